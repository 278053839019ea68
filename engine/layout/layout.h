// Light map layout: where each instance's TEXCOORD_1 lands in which page.
//
//   asset: TEXCOORD_1 is one shared atlas over one page of resolution^2 texels;
//          every instance maps with scale 1, offset 0.
//   pack:  every instance gets its own rectangle, sized from its world surface
//          area times the texel density (per-node override in glTF extras),
//          shelf-packed into square pages of `resolution` texels with
//          `padding` texels kept free around each rectangle. Meshes without
//          TEXCOORD_1 get generated light map UVs (as in generate).
//   generate: pack, with TEXCOORD_1 generated for every mesh (uv_generate.h):
//          charts cut at hard edges, flattened with low stretch, packed at the
//          layout's texel density on a texel grid with `padding` free texels
//          between charts; the mesh's rectangle is exactly that grid, so chart
//          rectangles land on texel boundaries of the page.
//
// GL-free. pageUv = uv1 * scale + offset, in [0,1]^2 of page `page`
// (u to the right, v up from texel row 0, as GL textures address them).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "core/status.h"
#include "layout/uv_generate.h"
#include "scene/scene.h"

namespace bb {

enum class UvLayout { Asset, Pack, Generate };

struct LayoutOptions {
    UvLayout mode = UvLayout::Pack;
    int resolution = 512;        // page width = height in texels (typ. 256..4096)
    float texelDensity = 0.0f;   // texels per scene unit; 0 = auto: fit the scene into about one page
    int padding = 2;             // free texels around every rectangle (pack), for dilation and bilinear filtering
    // asset: texel centres inside two TEXCOORD_1 triangles (overlapping charts,
    // which would share texels and race in the update pass) are counted and
    // reported with an example; true makes that an error.
    bool failOnOverlap = false;
    UvChartOptions charts;       // generated TEXCOORD_1: chart angles and sizes
};

struct InstanceRect {
    int page = 0;
    int x = 0, y = 0;            // texel origin of the rectangle (without padding)
    int width = 0, height = 0;   // in texels (without padding)
    glm::vec2 scale{1.0f};       // pageUv = uv1 * scale + offset
    glm::vec2 offset{0.0f};
    float texelDensity = 0.0f;   // the density actually used (texels per scene unit), after clamping
};

// Figures of the generated TEXCOORD_1 (zero when nothing was generated).
struct UvGenerationStats {
    size_t meshes = 0;             // meshes given generated TEXCOORD_1 (after the copies below)
    size_t copiedMeshes = 0;       // copies made for instances of another size or shape than the mesh's first
    size_t charts = 0;             // over those meshes (each counted once)
    size_t lscmCharts = 0;         // of them flattened by LSCM (the rest: planar projection)
    double worstStretch = 0.0;     // the largest chart L2 stretch (1 = isometric)
    double meanStretch = 0.0;      // area-weighted mean of the charts' L2 stretch
    size_t gridTexels = 0;         // texels in the generated instances' rectangles (over instances)
    size_t coveredTexels = 0;      // of them, texel centres inside a triangle
    size_t overlappingTexels = 0;  // of them, inside two triangles (0 unless something is wrong)
    size_t subTexelCharts = 0;     // charts smaller than one texel in area (they may cover no texel centre)
    double chartSeconds = 0.0;     // makeCharts, wall time
    double packSeconds = 0.0;      // density search, chart packing, writeUv1
};

struct Layout {
    UvLayout mode = UvLayout::Pack;
    int resolution = 0;
    int pageCount = 0;
    int padding = 0;
    float texelDensity = 0.0f;          // global density used (pack), texels per scene unit
    std::vector<InstanceRect> rects;    // one per Scene::instances entry
    size_t overlappingTexels = 0;       // asset: texel centres inside more than one triangle
    UvGenerationStats uv;               // generated TEXCOORD_1 (pack, generate)
    size_t texelCount() const { return size_t(pageCount) * resolution * resolution; }
};

// Errors: resolution out of [16, 16384], negative density, padding < 0,
// asset mode on a scene without TEXCOORD_1 everywhere (one line with a hint),
// overlapping asset charts with failOnOverlap.
// This overload never changes the scene: pack and generate refuse meshes
// without TEXCOORD_1 (use the one below), and meshes whose TEXCOORD_1 was
// generated before (Mesh::uv1Grid) keep their grid as their rectangle.
Expected<Layout> computeLayout(const Scene& scene, const LayoutOptions& options);

// The same, generating TEXCOORD_1 where the layout needs it (pack: meshes
// without it; generate: every mesh): rewrites those meshes' vertices (split
// along chart boundaries) and uv1, sets Mesh::uv1Grid, and gives instances of
// one mesh that differ in size or shape (not just in rotation or position),
// or in texel density override, their own copy of the mesh (Instance::mesh
// changes). Same scene and options, same bytes. Costs about 1-2 s per million
// generated triangles. Extra error: a mesh with so many charts that they do
// not fit one page with their padding (raise the resolution).
Expected<Layout> computeLayout(Scene& scene, const LayoutOptions& options);

// Texel centres of the pages inside the instances' TEXCOORD_1 triangles
// (mapped by their rectangles; asset: each mesh once), and those inside two
// or more: overlapping charts. A centre on (or within 1e-4 texel of) an edge
// counts for neither side: nearly collinear vertices round by that much.
struct TexelCoverage {
    size_t covered = 0;
    size_t overlapping = 0;
    int page = 0, x = 0, y = 0;     // the first overlapping texel
    std::string first, second;      // its two instances' names
};
TexelCoverage measureCoverage(const Scene& scene, const Layout& layout);

}  // namespace bb
