// Curved texels on the GPU (glsl/lib/curved_footprint.glsl): where a chart
// folds or curves within a texel's square (layout/bake_mesh.h curvedTexels),
// the light passes draw the texel as a point and find each sample's
// footprint point on the triangle that holds it. GL-free.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "layout/bake_mesh.h"
#include "tiler/tiler.h"

namespace bb {

// lib/curved_footprint.glsl's CurvedTriangle (std430).
struct CurvedTriangle {
    glm::vec4 corners01;   // corners 0 and 1, page texels
    glm::vec4 corner2;     // corner 2; z: flags (uint bits), w: curvature (1 / scene units)
    glm::vec4 position;    // at corner 0
    glm::vec4 positionDx;  // per texel along x
    glm::vec4 positionDy;  // per texel along y
    glm::vec4 normal;      // shading normal at corner 0, and its steps per texel
    glm::vec4 normalDx;
    glm::vec4 normalDy;
    glm::vec4 faceNormal;  // unit, on the side the bundle pass gives its fragments
};
static_assert(sizeof(CurvedTriangle) == 144);

struct CurvedFootprints {
    std::vector<glm::uvec4> texels;          // one per curved texel (lib/curved_footprint.glsl), in cluster order
    std::vector<uint32_t> refs;              // per texel its triangles, owner first
    std::vector<CurvedTriangle> triangles;   // each once
    std::vector<uint32_t> clusterFirst;      // per cluster, its first curved texel (its owner's); then the count
    size_t count() const { return texels.size(); }
    int64_t bytes() const {
        return int64_t(texels.size() * sizeof(glm::uvec4) + refs.size() * 4 + triangles.size() * sizeof(CurvedTriangle));
    }
};

// pages[p]: page p's curvedTexels (res x res pages). Texels go with their
// owner triangle's cluster (the tile that draws it draws them). Deterministic.
CurvedFootprints buildCurvedFootprints(const BakeMesh& mesh, const std::vector<Cluster>& clusters, int res,
                                       const std::vector<std::vector<CurvedTexel>>& pages);

}  // namespace bb
