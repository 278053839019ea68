#version 430
// Update pass: raster in light map space (one fragment per covered texel
// centre) carrying the texel's world position and normal.
#include "lib/bake_vertex.glsl"
#include "lib/rounding.glsl"
#include "lib/texel_footprint.glsl"

out vec3 vPosition;
out vec3 vNormal;
out vec3 vBary;
flat out uint vFlags;
flat out uint vPage;

void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    vPosition = inPosition.xyz;
    vNormal = inNormal.xyz;
    vBary = cornerBarycentric(gl_VertexID);
    uvec4 tri = bakeTriangle(uint(gl_VertexID) / 3u);
    vFlags = tri.w;
    vPage = tri.y;  // one draw covers every page
}
