#version 430
// Explicit direct light from one emitter sample: raster in light map space.
#include "lib/bake_vertex.glsl"
out vec3 vPosition;
out vec3 vNormal;
void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    vPosition = inPosition.xyz;
    vNormal = inNormal.xyz;
}
