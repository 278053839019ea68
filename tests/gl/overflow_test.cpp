// No fragment is lost when the node buffer is too small: a bake with a
// memory budget that holds about a fifth of one direction's fragments must
// overflow (detected from the atomic counter), split and redraw its tiles,
// and end with exactly the fragments of an unconstrained bake and the same
// light maps, bit for bit (no random number and no interpolated value
// depends on the tile that drew it).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "support/bake_helper.h"

namespace bb {
namespace {

TEST(BundleOverflow, SmallNodeBufferSplitsAndRedrawsWithoutLosingFragments) {
    BB_REQUIRE_GL();
    BakeOptions roomy;
    roomy.directions = 16;
    BakeOptions tight = roomy;
    // head image: 64 x 64 x 4 B = 16 KiB (the smallest tile); nodes: 1200 x 12 B.
    // One direction of the 64-texel furnace has about 5000 fragments.
    tight.bundleMemory = 64 * 64 * 4 + 1200 * 12;
    tight.predictTiles = false;  // no pre-splitting: only the atomic counter can save the fragments

    auto a = test::makeBake("assets/furnace/furnace.gltf", test::assetLayout(64), roomy);
    ASSERT_TRUE(a) << a.error;
    test::bakeToEnd(*a.baker);
    const BakeStats sa = a.baker->stats();
    auto mapsA = a.baker->readLightmaps();
    auto accumulatorsA = a.baker->readAccumulators();

    auto b = test::makeBake("assets/furnace/furnace.gltf", test::assetLayout(64), tight);
    ASSERT_TRUE(b) << b.error;
    test::bakeToEnd(*b.baker);
    const BakeStats sb = b.baker->stats();
    auto mapsB = b.baker->readLightmaps();
    auto accumulatorsB = b.baker->readAccumulators();

    EXPECT_EQ(sa.overflows, 0);
    EXPECT_LE(sb.nodeCapacity, 1200);
    EXPECT_GT(sb.overflows, 0) << "the tight budget never overflowed: the test no longer tests overflow";
    EXPECT_GT(sb.tilesDrawn, sa.tilesDrawn);
    EXPECT_LE(sb.peakNodesPerTile, sb.nodeCapacity);
    // the same pixel grid, cut differently: every fragment drawn exactly once
    EXPECT_EQ(sb.fragments, sa.fragments);
    // every texel received the same samples: the raw accumulators (mean RGB and
    // the weight W, read from the GPU) agree bit for bit, texel by texel (the
    // stats' updatedTexels is covered texels x directions in both bakes, so it
    // cannot tell)
    ASSERT_EQ(accumulatorsA.size(), accumulatorsB.size());
    size_t differingAccumulators = 0, weighted = 0;
    for (size_t p = 0; p < accumulatorsA.size(); ++p) {
        ASSERT_EQ(accumulatorsA[p].size(), accumulatorsB[p].size());
        for (size_t i = 0; i < accumulatorsA[p].size(); ++i) {
            differingAccumulators += std::memcmp(&accumulatorsA[p][i], &accumulatorsB[p][i], sizeof(glm::vec4)) != 0;
            weighted += accumulatorsA[p][i].w > 0;
        }
    }
    EXPECT_EQ(differingAccumulators, 0u) << "texels whose accumulated samples differ after the overflow redraws";
    EXPECT_GT(weighted, 1000u) << "the 64^2 furnace page should have most texels sampled";

    // the same light maps, bit for bit
    ASSERT_EQ(mapsA.pages.size(), mapsB.pages.size());
    double worst = 0;
    for (size_t p = 0; p < mapsA.pages.size(); ++p)
        for (size_t i = 0; i < mapsA.pages[p].pixels.size(); ++i)
            if (mapsA.covered[p][i])
                worst = std::max(worst, double(std::abs(mapsA.pages[p].pixels[i].g - mapsB.pages[p].pixels[i].g)) /
                                            std::max(1e-3, double(mapsA.pages[p].pixels[i].g)));
    std::printf("[overflow] capacity %lld nodes, %lld overflows, %lld vs %lld tiles, worst texel difference %.3f%%\n",
                (long long)sb.nodeCapacity, (long long)sb.overflows, (long long)sb.tilesDrawn,
                (long long)sa.tilesDrawn, 100 * worst);
    EXPECT_EQ(worst, 0.0);
}

}  // namespace
}  // namespace bb
