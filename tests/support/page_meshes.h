// Hand-made BakeMeshes drawn directly in page space, for the CPU coverage,
// footprint and supersampling tests: positions are the page corners (z on
// top), normals +z, light-map UVs the corners over the page's size.
#pragma once

#include <array>

#include "layout/bake_mesh.h"

namespace bb {

// Appends a triangle with corners in texels of a `pageTexels` page; `borders`
// is its chart-border bits (bit k: the edge opposite corner k), as
// buildBakeMesh sets them. builtIndex follows when the mesh keeps one.
inline void addPageTriangle(BakeMesh& m, const std::array<glm::vec2, 3>& corners, float pageTexels, float z = 0.0f,
                            uint32_t borders = 0) {
    for (const glm::vec2& c : corners) {
        BakeVertex v;
        v.position = glm::vec4(c, z, 1);
        v.normal = glm::vec4(0, 0, 1, 0);
        v.lightmapUv = c / pageTexels;
        m.vertices.push_back(v);
    }
    if (!m.builtIndex.empty() || m.triangles.empty()) m.builtIndex.push_back(uint32_t(m.triangles.size()));
    m.triangles.push_back({0, 0, 0, borders * TRIANGLE_CHART_BORDER0});
}

// Appends the rectangle lo..hi as two triangles split along lo-hi, its four
// sides chart borders.
inline void addPageQuad(BakeMesh& m, glm::vec2 lo, glm::vec2 hi, float pageTexels, float z = 0.0f) {
    const glm::vec2 p10(hi.x, lo.y), p01(lo.x, hi.y);
    addPageTriangle(m, {lo, p10, hi}, pageTexels, z, 1u | 4u);
    addPageTriangle(m, {lo, hi, p01}, pageTexels, z, 1u | 2u);
}

}  // namespace bb
