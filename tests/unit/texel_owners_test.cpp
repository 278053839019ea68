// Which triangle owns a texel where two could (layout/bake_mesh.h texelOwners,
// pageDrawOrder): the same in the bake's mesh, whose triangles the clusters
// reorder (tiler/tiler.h), as in the reference's, which keeps them as built.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "layout/bake_mesh.h"
#include "tiler/tiler.h"

namespace bb {
namespace {

// Two strips 0.125 texel wide in row 5 of a 16 x 16 page, mirror images
// about v = 5.55 (v 5.30..5.425 and 5.675..5.80), neither on the centre line:
// texels 2..5 hold an eighth of each, the strips' triangles ties, as a
// generated building's ledge top and the soffit above it were in its atlas.
BakeMesh mirroredStrips() {
    BakeMesh m;
    auto quad = [&](float v0, float v1, float z) {
        const glm::vec2 p00(2, v0), p10(6, v0), p11(6, v1), p01(2, v1);
        const std::array<glm::vec2, 3> tris[2] = {{p00, p10, p11}, {p00, p11, p01}};
        for (const auto& corners : tris) {
            for (const glm::vec2& c : corners) {
                BakeVertex v;
                v.position = glm::vec4(c, z, 1);
                v.normal = glm::vec4(0, 0, 1, 0);
                v.lightmapUv = c / 16.0f;
                m.vertices.push_back(v);
            }
            m.triangles.push_back({0, 0, 0, 0});
        }
    };
    quad(5.3f, 5.425f, 0.0f);
    quad(5.675f, 5.8f, 1.0f);
    m.pageFirstTriangle = {0, 4};
    m.builtIndex = {0, 1, 2, 3};
    return m;
}

// The mesh's triangles in the order `order` (new i = old order[i]), their
// builtIndex moved with them, as clusterMesh does.
BakeMesh reordered(const BakeMesh& m, const std::vector<uint32_t>& order) {
    BakeMesh out = m;
    for (size_t i = 0; i < order.size(); ++i) {
        out.triangles[i] = m.triangles[order[i]];
        for (int k = 0; k < 3; ++k) out.vertices[3 * i + size_t(k)] = m.vertices[3 * size_t(order[i]) + size_t(k)];
        out.builtIndex[i] = m.builtIndex[order[i]];
    }
    return out;
}

TEST(TexelOwners, TiesGoTheSameWayWhateverOrderTheMeshHolds) {
    const BakeMesh built = mirroredStrips();
    const BakeMesh clustered = reordered(built, {3, 2, 1, 0});
    const std::vector<int32_t> a = texelOwners(built, 0, 16), b = texelOwners(clustered, 0, 16);
    for (int x = 2; x < 6; ++x) {
        const size_t i = 5 * 16 + size_t(x);
        ASSERT_GE(a[i], 0) << "texel " << x << " holds a quarter of its square";
        ASSERT_GE(b[i], 0);
        EXPECT_EQ(built.builtIndex[size_t(a[i])], clustered.builtIndex[size_t(b[i])]) << "texel " << x;
    }
    // without builtIndex the reordered mesh's own order breaks the ties the other way: the test can fail
    BakeMesh unkeyed = clustered;
    unkeyed.builtIndex.clear();
    const std::vector<int32_t> c = texelOwners(unkeyed, 0, 16);
    int differ = 0;
    for (int x = 2; x < 6; ++x) differ += clustered.builtIndex[size_t(c[5 * 16 + size_t(x)])] != built.builtIndex[size_t(a[5 * 16 + size_t(x)])];
    EXPECT_GT(differ, 0) << "the strips' triangles tie";
}

// clusterMesh and setClusterImportance move each triangle's builtIndex with it.
TEST(TexelOwners, ClustersCarryTheBuiltIndex) {
    BakeMesh m;
    for (int k = 0; k < 40; ++k) {  // triangles scattered so that the median splits reorder them
        const float x = float((k * 17) % 40), y = float((k * 7) % 5);
        for (const glm::vec2 c : {glm::vec2(x, y), glm::vec2(x + 0.5f, y), glm::vec2(x, y + 0.5f)}) {
            BakeVertex v;
            v.position = glm::vec4(c, float(k), 1);
            v.normal = glm::vec4(0, 0, 1, 0);
            v.lightmapUv = c / 64.0f;
            m.vertices.push_back(v);
        }
        m.triangles.push_back({0, 0, 0, 0});
    }
    m.pageFirstTriangle = {0, 40};
    m.builtIndex.resize(40);
    for (uint32_t k = 0; k < 40; ++k) m.builtIndex[k] = k;
    std::vector<Cluster> clusters = clusterMesh(m, 8);
    std::vector<float> importance(40);
    for (size_t t = 0; t < 40; ++t) importance[t] = float((m.builtIndex[t] * 13) % 40) + (t % 3 == 0 ? 0.0f : 100.0f);
    setClusterImportance(m, clusters, importance);
    int moved = 0;
    for (uint32_t t = 0; t < 40; ++t) {
        EXPECT_EQ(m.vertices[3 * t].position.z, float(m.builtIndex[t])) << "triangle " << t;
        moved += m.builtIndex[t] != t;
    }
    EXPECT_GT(moved, 0) << "the clusters reordered the triangles";
}

}  // namespace
}  // namespace bb
