#version 430
// Visibility of an emitter sample or a point/spot light: distance from the
// sample point, one cube face.
#include "lib/bake_vertex.glsl"
uniform mat4 clipFromWorld;
out vec3 vPosition;
out vec2 vUv0;
flat out uint vMaterial;
flat out uint vFlags;
flat out uint vTriangle;
void main() {
    vPosition = inPosition.xyz;
    vUv0 = inUv0;
    vTriangle = uint(gl_VertexID) / 3u;
    uvec4 tri = bakeTriangle(vTriangle);
    vMaterial = tri.x;
    vFlags = tri.w;
    gl_Position = clipFromWorld * vec4(inPosition.xyz, 1.0);
}
