#version 430
// Scene view (engine/render/scene_renderer.h): the bake mesh's world-space
// vertices through the camera. Drawn with an index buffer sorted by
// material, so gl_VertexID is the BakeMesh vertex: triangle = gl_VertexID / 3.
#include "lib/bake_vertex.glsl"

uniform mat4 clipFromWorld;

out vec3 vWorld;
out vec2 vUv0;
out vec2 vLightmapUv;
flat out uint vTriangle;
flat out uint vPage;

void main() {
    gl_Position = clipFromWorld * inPosition;
    vWorld = inPosition.xyz;
    vUv0 = inUv0;
    vLightmapUv = inLightmapUv;
    vTriangle = uint(gl_VertexID) / 3u;
    vPage = bakeTriangle(vTriangle).y;
}
