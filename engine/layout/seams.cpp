// Seam edges of the bake mesh (see seams.h).
#include "layout/seams.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <tuple>

#include "core/parallel.h"

namespace bb {
namespace {

uint32_t bits(float f) {
    uint32_t u;
    std::memcpy(&u, &f, sizeof u);
    return u;
}

// One triangle's edge between welded vertices lo < hi.
struct EdgeUse {
    uint32_t lo, hi;
    uint32_t triangle;
    uint8_t cornerLo, cornerHi;  // 0..2 within the triangle
};

glm::vec3 faceNormal(const BakeMesh& mesh, uint32_t t) {
    const glm::vec3 p0(mesh.vertices[3 * size_t(t)].position), p1(mesh.vertices[3 * size_t(t) + 1].position),
        p2(mesh.vertices[3 * size_t(t) + 2].position);
    const glm::vec3 n = glm::cross(p1 - p0, p2 - p0);
    const float len = glm::length(n);
    return len > 0.0f ? n / len : glm::vec3(0.0f);
}

// Whether a bilinear lookup at `texel` (page texels, GL_LINEAR) reads chart
// `chart`'s own light: of the four texels it taps, one at least is owned by
// the chart and none by another (`owner`: texelOwners of the page; unowned
// ones are padding, dilated from the chart's).
bool ownLookup(const std::vector<int32_t>& owner, const std::vector<uint32_t>& chartOf, int res, glm::vec2 texel,
               uint32_t chart) {
    const int x0 = int(std::floor(texel.x - 0.5f)), y0 = int(std::floor(texel.y - 0.5f));
    int owned = 0;
    for (int y = y0; y <= y0 + 1; ++y)
        for (int x = x0; x <= x0 + 1; ++x) {
            if (x < 0 || y < 0 || x >= res || y >= res) continue;
            const int32_t t = owner[size_t(y) * size_t(res) + size_t(x)];
            if (t < 0) continue;
            if (chartOf[size_t(t)] != chart) return false;
            ++owned;
        }
    return owned > 0;
}

}  // namespace

Seams findSeams(const BakeMesh& mesh, int resolution, const SeamOptions& options) {
    Seams out;
    const size_t nv = mesh.vertices.size();
    const size_t nt = mesh.triangles.size();
    if (nt == 0 || resolution < 1) return out;

    // weld: sort every vertex by (instance, position bits)
    struct Key {
        uint32_t instance, x, y, z, v;
    };
    std::vector<Key> keys(nv);
    for (size_t v = 0; v < nv; ++v) {
        const glm::vec4& p = mesh.vertices[v].position;
        keys[v] = {mesh.triangles[v / 3].instance, bits(p.x), bits(p.y), bits(p.z), uint32_t(v)};
    }
    std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
        return std::tie(a.instance, a.x, a.y, a.z, a.v) < std::tie(b.instance, b.x, b.y, b.z, b.v);
    });
    std::vector<uint32_t> weld(nv);
    uint32_t id = 0;
    for (size_t i = 0; i < nv; ++i) {
        if (i > 0 && std::tie(keys[i].instance, keys[i].x, keys[i].y, keys[i].z) !=
                         std::tie(keys[i - 1].instance, keys[i - 1].x, keys[i - 1].y, keys[i - 1].z))
            ++id;
        weld[keys[i].v] = id;
    }

    // edges: every triangle's three, grouped by welded ends
    std::vector<EdgeUse> uses;
    uses.reserve(3 * nt);
    for (size_t t = 0; t < nt; ++t)
        for (int k = 0; k < 3; ++k) {
            const int k2 = (k + 1) % 3;
            uint32_t a = weld[3 * t + size_t(k)], b = weld[3 * t + size_t(k2)];
            if (a == b) continue;  // degenerate after welding
            uint8_t ca = uint8_t(k), cb = uint8_t(k2);
            if (a > b) {
                std::swap(a, b);
                std::swap(ca, cb);
            }
            uses.push_back({a, b, uint32_t(t), ca, cb});
        }
    std::sort(uses.begin(), uses.end(), [](const EdgeUse& a, const EdgeUse& b) {
        return std::tie(a.lo, a.hi, a.triangle, a.cornerLo) < std::tie(b.lo, b.hi, b.triangle, b.cornerLo);
    });

    // seams in triangle order (deterministic, and neighbouring seams sample together)
    std::vector<std::pair<size_t, size_t>> seamUses;  // (first use, second use)
    const float res = float(resolution);
    const float sameTexels = 1e-3f;
    for (size_t i = 0; i < uses.size();) {
        size_t j = i + 1;
        while (j < uses.size() && uses[j].lo == uses[i].lo && uses[j].hi == uses[i].hi) ++j;
        const size_t count = j - i;
        if (count > 2) {
            ++out.nonManifoldEdges;
        } else if (count == 2) {
            const EdgeUse& a = uses[i];
            const EdgeUse& b = uses[i + 1];
            const BakeVertex& a0 = mesh.vertices[3 * size_t(a.triangle) + a.cornerLo];
            const BakeVertex& a1 = mesh.vertices[3 * size_t(a.triangle) + a.cornerHi];
            const BakeVertex& b0 = mesh.vertices[3 * size_t(b.triangle) + b.cornerLo];
            const BakeVertex& b1 = mesh.vertices[3 * size_t(b.triangle) + b.cornerHi];
            const bool samePage = mesh.triangles[a.triangle].page == mesh.triangles[b.triangle].page;
            const float d0 = glm::length(a0.lightmapUv - b0.lightmapUv) * res;
            const float d1 = glm::length(a1.lightmapUv - b1.lightmapUv) * res;
            if (!samePage || d0 > sameTexels || d1 > sameTexels) {
                const bool smooth = glm::dot(glm::vec3(a0.normal), glm::vec3(b0.normal)) >= options.cosNormalThreshold &&
                                    glm::dot(glm::vec3(a1.normal), glm::vec3(b1.normal)) >= options.cosNormalThreshold;
                const bool folded = glm::dot(faceNormal(mesh, a.triangle), faceNormal(mesh, b.triangle)) <
                                    options.cosFaceThreshold;
                if (smooth && !folded) seamUses.push_back({i, i + 1});
                else ++out.hardEdges;
            }
        }
        i = j;
    }
    std::sort(seamUses.begin(), seamUses.end(), [&](const auto& x, const auto& y) {
        return std::tie(uses[x.first].triangle, uses[x.first].cornerLo) <
               std::tie(uses[y.first].triangle, uses[y.first].cornerLo);
    });
    out.seamEdges = seamUses.size();

    // sample pairs: n per edge at the centres of n equal parts, where both
    // sides' charts own a texel of their lookups
    const std::vector<uint32_t> chartOf = findLightmapCharts(mesh);
    // the texels' owners of the pages the seams lie on, a page a core
    std::vector<std::vector<int32_t>> owners(mesh.pageFirstTriangle.size() - 1);
    std::vector<uint8_t> seamPage(owners.size(), 0);
    for (const auto& [first, second] : seamUses)
        seamPage[mesh.triangles[uses[first].triangle].page] = seamPage[mesh.triangles[uses[second].triangle].page] = 1;
    parallelFor(owners.size(), [&](size_t page) {
        if (seamPage[page]) owners[page] = texelOwners(mesh, int(page), resolution);
    });
    for (size_t seam = 0; seam < seamUses.size(); ++seam) {
        const EdgeUse& a = uses[seamUses[seam].first];
        const EdgeUse& b = uses[seamUses[seam].second];
        const glm::vec2 a0 = mesh.vertices[3 * size_t(a.triangle) + a.cornerLo].lightmapUv * res;
        const glm::vec2 a1 = mesh.vertices[3 * size_t(a.triangle) + a.cornerHi].lightmapUv * res;
        const glm::vec2 b0 = mesh.vertices[3 * size_t(b.triangle) + b.cornerLo].lightmapUv * res;
        const glm::vec2 b1 = mesh.vertices[3 * size_t(b.triangle) + b.cornerHi].lightmapUv * res;
        const float texels = std::max(glm::length(a1 - a0), glm::length(b1 - b0));
        const int n = std::max(2, int(std::ceil(texels * options.samplesPerTexel)));
        const uint32_t pageA = mesh.triangles[a.triangle].page, pageB = mesh.triangles[b.triangle].page;
        for (int s = 0; s < n; ++s) {
            const float t = (float(s) + 0.5f) / float(n);
            const glm::vec2 ta = a0 + (a1 - a0) * t, tb = b0 + (b1 - b0) * t;
            if (!ownLookup(owners[pageA], chartOf, resolution, ta, chartOf[a.triangle]) ||
                !ownLookup(owners[pageB], chartOf, resolution, tb, chartOf[b.triangle])) {
                ++out.narrowPairs;
                continue;
            }
            out.samples.push_back({uint32_t(seam), pageA, pageB, ta, tb});
        }
    }
    // the part of each texel on its chart, on the pages whose owners the seams needed
    out.texelArea.resize(owners.size());
    const size_t threads = threadsWithin(int64_t(resolution) * resolution * int64_t(sizeof(TexelFootprint) + sizeof(uint64_t)));
    parallelFor(owners.size(), [&](size_t page) {  // each page its own areas
        if (owners[page].empty()) return;
        const std::vector<TexelFootprint> footprints = texelFootprints(mesh, int(page), resolution, owners[page], chartOf);
        out.texelArea[page].resize(footprints.size());
        for (size_t i = 0; i < footprints.size(); ++i)
            out.texelArea[page][i] = owners[page][i] >= 0 ? footprints[i].area : uint8_t(0);
    }, threads);
    return out;
}

}  // namespace bb
