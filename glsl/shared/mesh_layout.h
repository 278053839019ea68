// Per-triangle flags of BakeTriangle (engine/layout/bake_mesh.h), shared with
// GLSL, and BakeVertex as shaders read the vertex buffer through an SSBO.
#ifndef BUNDLEBAKE_MESH_LAYOUT_H
#define BUNDLEBAKE_MESH_LAYOUT_H
#define TRIANGLE_DOUBLE_SIDED 1u
#define TRIANGLE_EMISSIVE 2u
// The triangle's side (lib/triangle_side.glsl) is the opposite of the normal
// the update pass takes from screen derivatives in light map space,
// cross(dFdx(P), dFdy(P)) = (p1 - p0) x (p2 - p0) / uv determinant: set where
// the winding disagrees with the shading normals XOR the uv triangle is clockwise.
#define TRIANGLE_DERIVATIVE_NORMAL_FLIPPED 4u
// The material is a cut-out (alphaMode MASK): passes test its alpha at the
// fragment (lib/alpha_mask.glsl); other triangles skip the lookup.
#define TRIANGLE_ALPHA_MASK 8u
// Edge k of the triangle (the one opposite vertex k) is a border of its light
// map chart: no other triangle of the page shares it (both end points) in page
// space. A texel's footprint ends there (lib/texel_footprint.glsl); across an
// edge the chart shares, it goes on in the neighbour. Bit k: TRIANGLE_CHART_BORDER0 << k.
#define TRIANGLE_CHART_BORDER0 16u
// Bits 16-30: the low 15 bits of the triangle's light map chart
// (findLightmapCharts), set by the baker for the bundle pass, which reads no
// texel another chart owns (glsl/bundle/append.frag, texelCharts).
#define TRIANGLE_CHART_SHIFT 16u
// texelCharts (r16ui per texel): its owner's chart's low 15 bits
// (TEXEL_CHART_MASK; uncovered: all of them set), and TEXEL_CURVED where its
// chart folds or curves within its square (engine/layout/bake_mesh.h
// curvedTexels): the update pass's light map raster leaves such texels to
// the curved texels' draw (lib/curved_footprint.glsl), as it does partial
// texels, whose centre no triangle holds (texelOwners).
#define TEXEL_CHART_MASK 0x7fffu
#define TEXEL_CURVED 0x8000u
// A curved texel's record (lib/curved_footprint.glsl): in its triangle count's
// top bit, a partial texel whose chart is flat over its square (CurvedTexel::flat):
// sampled along its owner's plane, as the raster's texels are.
#define CURVED_TEXEL_FLAT 0x80000000u
// ... and in the next bit, a flat one whose footprint the owner's border edges,
// the cells and one more edge do not hold (TexelFootprint::inexact): its points
// are kept where one of its triangles holds them (CurvedTexel::exact).
#define CURVED_TEXEL_EXACT 0x40000000u

// SSBO binding of BakeTriangle triangles[] (lib/bake_vertex.glsl), bound in
// chunks by MeshChunks (engine/layout/bake_mesh_gl.h)
#define MESH_BINDING_TRIANGLES 1

#ifndef __cplusplus
// BakeVertex as std430 sees it: 48 bytes, offsets 0, 16, 32, 40 (the C++
// struct static_asserts its size in engine/layout/bake_mesh.h).
struct BakeVertex {
    vec4 position;    // xyz world position, w = 1
    vec4 normal;      // xyz world unit normal, w = 0
    vec2 uv0;         // material texture coordinates
    vec2 lightmapUv;  // page-space light map coordinates
};
#endif
#endif
