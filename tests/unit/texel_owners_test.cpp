// Which triangle owns a texel where two could (layout/bake_mesh.h texelOwners,
// pageDrawOrder): the same in the bake's mesh, whose triangles the clusters
// reorder (tiler/tiler.h), as in the reference's, which keeps them as built.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>

#include "layout/bake_mesh.h"
#include "support/page_meshes.h"
#include "tiler/tiler.h"

namespace bb {
namespace {

// Two strips 0.125 texel wide in row 5 of a 16 x 16 page, mirror images
// about v = 5.55 (v 5.30..5.425 and 5.675..5.80), neither on the centre line:
// texels 2..5 hold an eighth of each, the strips' triangles ties, as a
// generated building's ledge top and the soffit above it were in its atlas.
BakeMesh mirroredStrips() {
    BakeMesh m;
    addPageQuad(m, {2.0f, 5.3f}, {6.0f, 5.425f}, 16.0f, 0.0f);
    addPageQuad(m, {2.0f, 5.675f}, {6.0f, 5.8f}, 16.0f, 1.0f);
    m.pageFirstTriangle = {0, 4};
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
        const glm::vec2 c(float((k * 17) % 40), float((k * 7) % 5));
        addPageTriangle(m, {c, c + glm::vec2(0.5f, 0.0f), c + glm::vec2(0.0f, 0.5f)}, 64.0f, float(k));
    }
    m.pageFirstTriangle = {0, 40};
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

// Of half-size row `row` (a 16-wide page), x0..x1, how many have a half-size
// texel of `chart` within one along the row.
int ownedWithinOne(const std::vector<int32_t>& owner, const std::vector<uint32_t>& charts, uint32_t chart, int row,
                   int x0, int x1) {
    int n = 0;
    for (int x = x0; x <= x1; ++x) {
        bool near = false;
        for (int dx = -1; dx <= 1; ++dx) {
            const int32_t o = owner[size_t(row) * 16 + size_t(x + dx)];
            near |= o >= 0 && charts[size_t(o)] == chart;
        }
        n += near;
    }
    return n;
}

// Three charts across an 8 x 8 page (texel units), x 1..7: A below (y 1..3.2),
// a strip B 0.12 high (y 3.3..3.42, a soffit between two bands) and C above
// (y 3.5..6). Texel row 3 is C's (its centres on C's bottom edge); of its
// lower half-size row (y 3..3.5) A holds 0.4 and B 0.24 of each, and A's
// triangles the most, so B would own no half-size texel anywhere and its
// bundle fragments would read A's light.
BakeMesh threeBands() {
    BakeMesh m;
    addPageQuad(m, {1.0f, 1.0f}, {7.0f, 3.2f}, 8.0f);
    addPageQuad(m, {1.0f, 3.3f}, {7.0f, 3.42f}, 8.0f);
    addPageQuad(m, {1.0f, 3.5f}, {7.0f, 6.0f}, 8.0f);
    m.pageFirstTriangle = {0, 6};
    return m;
}

TEST(HalfTexelOwners, AStripThatLosesEveryHalfSizeTexelGetsOnesNoTexelNeeds) {
    const BakeMesh m = threeBands();
    const std::vector<uint32_t> charts = findLightmapCharts(m);
    const uint32_t a = charts[0], b = charts[2], c = charts[4];
    ASSERT_TRUE(a != b && b != c && a != c);
    const std::vector<int32_t> coarse = texelOwners(m, 0, 8);
    ASSERT_EQ(charts[size_t(coarse[3 * 8 + 3])], c) << "row 3 is C's";
    const std::vector<int32_t> plain = texelOwners(m, 0, 16, nullptr, kMinPartialTexelArea / 4.0);
    const std::vector<int32_t> fine = halfTexelOwners(m, charts, 0, 8);
    // the half-size texels of row 6 (y 3..3.5), x 2..13, with one of B's within one of them
    EXPECT_LE(ownedWithinOne(plain, charts, b, 6, 2, 13), 3)
        << "by the most area B owns at most an end's: the test can fail";
    EXPECT_EQ(ownedWithinOne(fine, charts, b, 6, 2, 13), 12);
    // A keeps the row below (its own texels' half-size texels), C its texels' upper half: no texel's value moves
    for (int x = 2; x <= 13; ++x) {
        EXPECT_EQ(charts[size_t(fine[5 * 16 + size_t(x)])], a) << x;
        EXPECT_EQ(charts[size_t(fine[7 * 16 + size_t(x)])], c) << x;
    }
}

// A strip B (y 3.78..3.9, x 1..7 of an 8 x 8 page) lying only in half-size
// row 7 (y 3.5..4), which texel row 3's chart C (y 3.2..3.6, its centres on
// C) needs: C holds a fifth of it (a sixteenth is enough), 0.6 of row 6 below.
// No half-size texel is free for B (D, y 3.92..6, owns rows 8 and up): B
// takes some of row 7 from C, which keeps row 6, three quarters of its part.
TEST(HalfTexelOwners, AStripWithNoFreeHalfSizeTexelTakesOnesItsTexelsChartCanSpare) {
    BakeMesh m;
    addPageQuad(m, {1.0f, 3.2f}, {7.0f, 3.6f}, 8.0f);
    addPageQuad(m, {1.0f, 3.78f}, {7.0f, 3.9f}, 8.0f);
    addPageQuad(m, {1.0f, 3.92f}, {7.0f, 6.0f}, 8.0f);
    m.pageFirstTriangle = {0, 6};
    const std::vector<uint32_t> charts = findLightmapCharts(m);
    const uint32_t c = charts[0], b = charts[2];
    ASSERT_NE(b, c);
    ASSERT_EQ(charts[size_t(texelOwners(m, 0, 8)[3 * 8 + 3])], c) << "row 3 is C's";
    const std::vector<int32_t> fine = halfTexelOwners(m, charts, 0, 8);
    for (int x = 3; x <= 12; ++x) EXPECT_EQ(charts[size_t(fine[6 * 16 + size_t(x)])], c) << "C keeps row 6, x " << x;
    EXPECT_EQ(ownedWithinOne(fine, charts, b, 7, 3, 12), 10)
        << "a half-size texel of B's within one of each of row 7's";
    for (int x = 2; x <= 13; ++x) {
        const int32_t o = fine[7 * 16 + size_t(x)];
        EXPECT_TRUE(o >= 0 && (charts[size_t(o)] == b || charts[size_t(o)] == c)) << x;
    }
}

}  // namespace
}  // namespace bb
