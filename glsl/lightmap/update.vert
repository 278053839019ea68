#version 430
// Update pass: raster in light map space (one fragment per covered texel
// centre) carrying the texel's world position and normal.
#include "shared/bundle_layout.h"
#include "lib/bake_vertex.glsl"
#include "lib/triangle_side.glsl"

out vec3 vPosition;
out vec3 vNormal;
flat out uint vFlags;
flat out uint vPage;
flat out vec3 vSide;  // the triangle's side (lib/triangle_side.glsl)

void main() {
    gl_Position = vec4(inLightmapUv * 2.0 - 1.0, 0.0, 1.0);
    vPosition = inPosition.xyz;
    vNormal = inNormal.xyz;
    uvec4 tri = bakeTriangle(uint(gl_VertexID) / 3u);
    vFlags = tri.w;
    vSide = triangleSide(uint(gl_VertexID) / 3u);
    vPage = tri.y;  // one draw covers every page
}
