#version 430
// Bundle pass: orthographic projection of the scene along d into the tile.
#include "lib/bake_vertex.glsl"
#include "lib/bundle_frame.glsl"

out vec2 vLightmapUv;
out float vDepth;
flat out uint vPage;
flat out uint vFlags;
flat out vec3 vFaceNormal;
flat out uint vTriangle;

void main() {
    vec3 b = bundleFromWorld(inPosition.xyz);
    // clip space of the leaf's grid: the viewport (-tileOffset, leafPixels) and
    // a scissor to the tile select the tile, so every tile of a leaf rasterizes
    // the same window coordinates (an integer shift) and shares each edge's coverage
    vec2 ndc = gridFromRoot(rootFromBundle(b.xy)) / float(leafPixels) * 2.0 - 1.0;
    gl_Position = vec4(ndc, 0.0, 1.0);  // no depth clipping: every fragment along the line counts
    vLightmapUv = inLightmapUv;
    vDepth = b.z;
    uvec4 tri = triangles[gl_VertexID / 3];
    vPage = tri.y;
    vFlags = tri.w;
    vFaceNormal = inNormal.xyz;
    vTriangle = uint(gl_VertexID / 3);  // gl_PrimitiveID restarts with each draw of a multi-draw
}
