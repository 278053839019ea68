#include "bake/curved_footprints.h"

#include <algorithm>
#include <cstring>
#include <map>

#include "core/check.h"
#include "glsl/shared/mesh_layout.h"

namespace bb {
namespace {

float bitsAsFloat(uint32_t bits) {
    float f;
    std::memcpy(&f, &bits, 4);
    return f;
}

CurvedTriangle curvedTriangle(const BakeMesh& mesh, uint32_t t, int res) {
    TexelAffine position, normal;
    CHECK(texelAffine(mesh, t, res, false, position));  // curvedTexels keeps triangles with area only
    CHECK(texelAffine(mesh, t, res, true, normal));
    const BakeVertex* v = &mesh.vertices[3 * size_t(t)];
    const glm::vec2 q1 = v[1].lightmapUv * float(res), q2 = v[2].lightmapUv * float(res);
    const uint32_t flags = mesh.triangles[t].flags;
    // the plane as the light map raster's derivatives give it (update.frag triangleSample)
    glm::dvec3 face = glm::cross(position.dx, position.dy);
    face = glm::length(face) > 0.0 ? glm::normalize(face) : glm::normalize(normal.at0);
    if (flags & TRIANGLE_DERIVATIVE_NORMAL_FLIPPED) face = -face;
    const double curvature = std::max(glm::length(normal.dx) / std::max(glm::length(position.dx), 1e-30),
                                      glm::length(normal.dy) / std::max(glm::length(position.dy), 1e-30));
    auto v4 = [](const glm::dvec3& a) { return glm::vec4(glm::vec3(a), 0.0f); };
    return {glm::vec4(glm::vec2(position.q0), q1),
            glm::vec4(q2, bitsAsFloat(flags), float(curvature)),
            v4(position.at0),
            v4(position.dx),
            v4(position.dy),
            v4(normal.at0),
            v4(normal.dx),
            v4(normal.dy),
            v4(face)};
}

}  // namespace

CurvedFootprints buildCurvedFootprints(const BakeMesh& mesh, const std::vector<Cluster>& clusters, int res,
                                       const std::vector<std::vector<CurvedTexel>>& pages) {
    // each texel's cluster: its owner's (clusters are runs of mesh order)
    std::vector<uint32_t> clusterStarts(clusters.size());
    for (size_t c = 0; c < clusters.size(); ++c) clusterStarts[c] = clusters[c].first;
    CHECK(std::is_sorted(clusterStarts.begin(), clusterStarts.end()));
    struct Entry {
        uint32_t cluster, page;
        const CurvedTexel* texel;
    };
    std::vector<Entry> entries;
    for (size_t p = 0; p < pages.size(); ++p)
        for (const CurvedTexel& texel : pages[p]) {
            const uint32_t owner = texel.triangles.front();
            const auto it = std::upper_bound(clusterStarts.begin(), clusterStarts.end(), owner);
            CHECK(it != clusterStarts.begin());
            entries.push_back({uint32_t(it - clusterStarts.begin() - 1), uint32_t(p), &texel});
        }
    std::stable_sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.cluster < b.cluster; });

    CurvedFootprints out;
    out.clusterFirst.assign(clusters.size() + 1, 0);
    std::map<uint32_t, uint32_t> record;  // mesh triangle -> its CurvedTriangle
    for (const Entry& e : entries) {
        ++out.clusterFirst[e.cluster + 1];
        const CurvedTexel& texel = *e.texel;
        const uint32_t x = texel.texel % uint32_t(res), y = texel.texel / uint32_t(res);
        const uint32_t firstRef = uint32_t(out.refs.size());
        for (uint32_t t : texel.triangles) {
            auto [it, added] = record.try_emplace(t, uint32_t(out.triangles.size()));
            if (added) out.triangles.push_back(curvedTriangle(mesh, t, res));
            out.refs.push_back(it->second);
        }
        out.texels.push_back(glm::uvec4(x | (y << 16), e.page, firstRef,
                                        uint32_t(texel.triangles.size()) | (texel.flat ? CURVED_TEXEL_FLAT : 0u) |
                                            (texel.exact ? CURVED_TEXEL_EXACT : 0u)));
    }
    for (size_t c = 0; c < clusters.size(); ++c) out.clusterFirst[c + 1] += out.clusterFirst[c];
    return out;
}

}  // namespace bb
