#version 430
// Explicit direct light from one emitter sample or a point/spot light: raster
// in light map space.
#include "lib/bake_vertex.glsl"
#include "lib/rounding.glsl"
#include "lib/texel_footprint.glsl"
out vec3 vPosition;
out vec3 vNormal;
out vec3 vBary;
flat out uint vFlags;
void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    vPosition = inPosition.xyz;
    vNormal = inNormal.xyz;
    vBary = cornerBarycentric(gl_VertexID);
    vFlags = bakeTriangle(uint(gl_VertexID) / 3u).w;
}
