// Seam finding (layout/seams.h) on hand-made bake meshes, and seam stitching
// (bake/seam_stitch.h) on a synthetic page with a step across a seam.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "bake/seam_stitch.h"
#include "layout/seams.h"

namespace bb {
namespace {

// A unit quad in z = 0 as two triangles sharing the diagonal (0,0)-(1,1), on
// page 0; light map uv = position / 4 (+ offsetB on the second triangle).
BakeMesh quadMesh(glm::vec2 offsetB, glm::vec3 normalB = {0, 0, 1}, uint32_t instanceB = 0) {
    BakeMesh m;
    const glm::vec2 corners[2][3] = {{{0, 0}, {1, 0}, {1, 1}}, {{0, 0}, {1, 1}, {0, 1}}};
    for (int t = 0; t < 2; ++t) {
        for (int k = 0; k < 3; ++k) {
            BakeVertex v;
            v.position = glm::vec4(corners[t][k], 0, 1);
            v.normal = glm::vec4(t == 0 ? glm::vec3(0, 0, 1) : normalB, 0);
            v.lightmapUv = corners[t][k] * 0.25f + (t == 1 ? offsetB : glm::vec2(0));
            m.vertices.push_back(v);
        }
        m.triangles.push_back({0, 0, t == 1 ? instanceB : 0u, 0});
    }
    m.pageFirstTriangle = {0, 2};
    return m;
}

TEST(Seams, OneChartHasNoSeam) {
    const Seams s = findSeams(quadMesh({0, 0}), 16);
    EXPECT_EQ(s.seamEdges, 0u);
    EXPECT_EQ(s.hardEdges, 0u);
    EXPECT_TRUE(s.samples.empty());
}

TEST(Seams, SplitDiagonalIsOneSeamSampledAlongBothSides) {
    const Seams s = findSeams(quadMesh({0.5f, 0}), 16);
    ASSERT_EQ(s.seamEdges, 1u);
    EXPECT_EQ(s.hardEdges, 0u);
    // the diagonal is 16 x 0.25 x sqrt 2 = 5.66 texels: ceil(3 x 5.66) = 17
    // pairs, all kept: at its two ends (the triangles' acute corners) a side's
    // lookup taps texels its chart covers only in part, which it owns too
    // (texelOwners' partial texels; before they were, 4 pairs were dropped)
    ASSERT_EQ(s.samples.size() + s.narrowPairs, 17u);
    EXPECT_EQ(s.narrowPairs, 0u);
    for (const SeamSamplePair& p : s.samples) {
        // the same point of the edge on both sides: B is A moved by the offset (8 texels)
        EXPECT_NEAR(p.texelB.x - p.texelA.x, 8.0f, 1e-4f);
        EXPECT_NEAR(p.texelB.y - p.texelA.y, 0.0f, 1e-4f);
        EXPECT_NEAR(p.texelA.x, p.texelA.y, 1e-4f);  // on the diagonal
        EXPECT_GT(p.texelA.x, 0.0f);
        EXPECT_LT(p.texelA.x, 4.0f);
    }
    // the part of each texel's square on its chart, which the stitch weighs
    // texels by: the same for a bake's maps and the reference's
    ASSERT_EQ(s.texelArea.size(), 1u);
    ASSERT_EQ(s.texelArea[0].size(), 256u);
    const auto area = [&](int x, int y) { return double(s.texelArea[0][size_t(y) * 16 + size_t(x)]) / 255.0; };
    EXPECT_NEAR(area(3, 0), 1.0, 0.01) << "inside A";
    EXPECT_NEAR(area(8, 3), 1.0, 0.01) << "inside B";
    EXPECT_NEAR(area(1, 1), 0.5, 0.1) << "halved by the diagonal, the rest off every chart (counted on a grid)";
    EXPECT_EQ(area(6, 6), 0.0) << "off the charts";
}

// Two charts a quarter texel apart: each side's lookups tap texels the other
// owns, so no lookup reads its own chart's light and no pair is kept (a
// stitch would only pull the two charts' texels toward each other).
TEST(Seams, ChartsCloserThanATexelKeepNoPairs) {
    const Seams s = findSeams(quadMesh({1.0f / 64.0f, 0}), 16);
    ASSERT_EQ(s.seamEdges, 1u);
    EXPECT_TRUE(s.samples.empty());
    EXPECT_EQ(s.narrowPairs, 17u);
}

// A chart folded along the quad's diagonal (the corner (0, 1) lifted off the
// plane): the texels whose squares hold both triangles are curved (their
// owner's plane extended over the square leaves the other triangle); the flat
// quad, or one folded by less than the departure (2 % of a texel), has none.
TEST(CurvedTexels, AFoldWithinATexelIsCurved) {
    auto curved = [](float lift) {
        BakeMesh m = quadMesh({0, 0});
        m.vertices[5].position.z = lift;  // triangle 1's corner (0, 1)
        const std::vector<int32_t> owners = texelOwners(m, 0, 16);
        return curvedTexels(m, 0, 16, owners, findLightmapCharts(m));
    };
    EXPECT_TRUE(curved(0.0f).empty());
    EXPECT_TRUE(curved(0.001f).empty());  // departs by at most ~0.1 % of a texel (0.25 units)
    const std::vector<CurvedTexel> folded = curved(0.5f);
    std::printf("[curved] %zu texels along a fold\n", folded.size());
    // the diagonal's 4 texels (the 4 x 4 quad's) and those its squares' corners touch, less any
    // the owner's plane extended still holds
    EXPECT_GE(folded.size(), 4u);
    EXPECT_LE(folded.size(), 10u);
    for (const CurvedTexel& c : folded) {
        const int x = int(c.texel % 16), y = int(c.texel / 16);
        EXPECT_LE(std::abs(x - y), 1) << "texel (" << x << ", " << y << ") is off the fold";
        EXPECT_EQ(c.triangles.size(), 2u);
    }
}

// The same two charts' texels: a quarter texel apart, the texels along their
// diagonal hold parts of both; half a page apart, none does.
TEST(SharedTexels, CountsTexelsAnotherChartAlsoOverlaps) {
    auto shared = [](const BakeMesh& m) {
        return sharedTexels(m, 0, 16, texelOwners(m, 0, 16), findLightmapCharts(m));
    };
    const size_t close = shared(quadMesh({1.0f / 64.0f, 0}));
    std::printf("[shared] %zu\n", close);
    EXPECT_GE(close, 4u);   // at least the diagonal's texels (it crosses 4 texels each way)
    EXPECT_LE(close, 12u);  // and not the charts' inner texels
    EXPECT_EQ(shared(quadMesh({0.5f, 0})), 0u);
    EXPECT_EQ(shared(quadMesh({0, 0})), 0u);  // one chart: nothing shared
}

TEST(Seams, HardEdgeAndOtherInstanceAreNotSeams) {
    const Seams hard = findSeams(quadMesh({0.5f, 0}, glm::normalize(glm::vec3(0, 1, 1))), 16);
    EXPECT_EQ(hard.seamEdges, 0u);
    EXPECT_EQ(hard.hardEdges, 1u);
    const Seams apart = findSeams(quadMesh({0.5f, 0}, {0, 0, 1}, 1), 16);
    EXPECT_EQ(apart.seamEdges, 0u);
    EXPECT_EQ(apart.hardEdges, 0u);
}

// A 16 x 16 page, 1 left of x = 8 and 2 from it; a seam from (4, 2) to (4, 10)
// on side A and (12, 2) to (12, 10) on side B: a step of 1 across it.
TEST(SeamStitch, StepAcrossSeamIsStitchedAndTheRestKept) {
    LightmapPages maps;
    maps.resolution = 16;
    maps.pages.resize(1);
    maps.pages[0].width = maps.pages[0].height = 16;
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) maps.pages[0].pixels.push_back(glm::vec3(x < 8 ? 1.0f : 2.0f));
    maps.covered.assign(1, std::vector<uint8_t>(256, 1));
    Seams seams;
    seams.seamEdges = 1;
    for (int s = 0; s < 24; ++s) {
        const float y = 2.0f + 8.0f * (float(s) + 0.5f) / 24.0f;
        seams.samples.push_back({0, 0, 0, {4.0f, y}, {12.0f, y}});
    }
    const LightmapPages baked = maps;
    const SeamStitchStats st = stitchSeams(maps, seams);
    ASSERT_TRUE(st.solved);
    EXPECT_NEAR(st.rmsBefore, 1.0, 1e-9);
    EXPECT_NEAR(st.meanValue, 1.5, 1e-9);
    // every texel covered: keepWeight 0.1 x coveredKeepFactor 3, the step
    // shrinks by about 9x (measured 0.112; 0.053 when covered texels moved as freely as padding)
    EXPECT_LT(st.rmsAfter, 0.13 * st.rmsBefore) << st.toJson().dump();
    EXPECT_EQ(st.samplePairs, 24u);
    // columns 3, 4 and 11, 12 of rows 1..10 (the lookups' taps)
    EXPECT_EQ(st.texelsAdjusted, 2u * 2u * 10u);
    // symmetric: both sides meet half way
    EXPECT_NEAR(seamDifference(maps, seams).mean, 1.5, 0.01);
    size_t changed = 0;
    for (size_t i = 0; i < 256; ++i) changed += maps.pages[0].pixels[i] != baked.pages[0].pixels[i];
    EXPECT_LE(changed, st.texelsAdjusted);
    EXPECT_EQ(maps.pages[0].at(0, 0), baked.pages[0].at(0, 0));
    EXPECT_EQ(maps.pages[0].at(8, 5), baked.pages[0].at(8, 5));
    EXPECT_EQ(maps.pages[0].at(4, 12), baked.pages[0].at(4, 12));
    // same input, same bytes
    LightmapPages again = baked;
    stitchSeams(again, seams);
    EXPECT_EQ(again.pages[0].pixels, maps.pages[0].pixels);
}

}  // namespace
}  // namespace bb
