// Adaptive tiling on generated cities (scripts/generate_city.py): the memory
// budget and culling change how a direction is cut and drawn, never the
// light maps (bitwise); the node prediction holds on three scene sizes.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <string>

#include "support/bake_helper.h"

namespace bb::test {
namespace {

LayoutOptions cityLayout() { return packLayout(512); }
BakeOptions cityOptions() { return skyOptions(8, 3); }

struct Baked {
    std::vector<std::vector<glm::vec4>> accumulators;
    BakeStats stats;
    std::string error;
};

Baked bakeScene(const std::string& path, const BakeOptions& options, const LayoutOptions& layout = cityLayout()) {
    Baked out;
    SceneBake bake = makeBake(path, layout, options);
    if (!bake) {
        out.error = bake.error;
        return out;
    }
    bakeToEnd(*bake.baker);
    out.accumulators = bake.baker->readAccumulators();
    out.stats = bake.baker->stats();
    return out;
}

size_t differingTexels(const Baked& a, const Baked& b) {
    size_t n = 0;
    for (size_t p = 0; p < a.accumulators.size(); ++p)
        for (size_t i = 0; i < a.accumulators[p].size(); ++i)
            n += std::memcmp(&a.accumulators[p][i], &b.accumulators[p][i], sizeof(glm::vec4)) != 0;
    return n;
}

// A tiny budget (head image 64^2, 3000 nodes) cuts every direction into many
// tiles, and with prediction off only overflow splits them; the leaves (and
// so the pixels) do not depend on the budget, and neither does any random
// number, so the accumulators are the same bits.
TEST(TilingBake, TinyBudgetGivesTheSameBits) {
    BB_REQUIRE_GL();
    const std::string city = generateTinyCity("budget", "--seed 5");
    ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed";
    const Baked roomy = bakeScene(city, cityOptions());
    ASSERT_TRUE(roomy.error.empty()) << roomy.error;
    BakeOptions tightOptions = cityOptions();
    tightOptions.bundleMemory = 64 * 64 * 4 + 3000 * 12;
    const Baked tight = bakeScene(city, tightOptions);
    ASSERT_TRUE(tight.error.empty()) << tight.error;
    tightOptions.predictTiles = false;
    const Baked splitOnly = bakeScene(city, tightOptions);
    ASSERT_TRUE(splitOnly.error.empty()) << splitOnly.error;

    std::printf("[tiling] tiles drawn %lld (roomy), %lld (tight, %lld overflows), %lld (overflow splits only, %lld "
                "overflows); fragments %lld / %lld / %lld\n",
                (long long)roomy.stats.tilesDrawn, (long long)tight.stats.tilesDrawn, (long long)tight.stats.overflows,
                (long long)splitOnly.stats.tilesDrawn, (long long)splitOnly.stats.overflows,
                (long long)roomy.stats.fragments, (long long)tight.stats.fragments,
                (long long)splitOnly.stats.fragments);
    EXPECT_GT(tight.stats.tilesDrawn, 4 * roomy.stats.tilesDrawn);
    EXPECT_GT(splitOnly.stats.overflows, 0) << "the tight buffer never overflowed: the test no longer tests overflow";
    EXPECT_LE(tight.stats.peakNodesPerTile, 3000);
    // every fragment drawn exactly once, however the directions were cut
    EXPECT_EQ(tight.stats.fragments, roomy.stats.fragments);
    EXPECT_EQ(splitOnly.stats.fragments, roomy.stats.fragments);
    EXPECT_EQ(differingTexels(roomy, tight), 0u);
    EXPECT_EQ(differingTexels(roomy, splitOnly), 0u);
    EXPECT_EQ(differingTexels(tight, splitOnly), 0u);
}

// Culling draws a fraction of the clusters per tile and changes no bit.
TEST(TilingBake, CullingChangesNothing) {
    BB_REQUIRE_GL();
    const std::string city = generateTinyCity("culling", "--seed 6");
    ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed";
    BakeOptions o = cityOptions();
    o.bundleMemory = 1 << 20;  // several tiles per direction, so there is something to cull
    const Baked on = bakeScene(city, o);
    ASSERT_TRUE(on.error.empty()) << on.error;
    o.cull = false;
    const Baked off = bakeScene(city, o);
    ASSERT_TRUE(off.error.empty()) << off.error;
    std::printf("[tiling] culling: %lld tiles; bundle pass drew %lld triangles with culling, %lld without\n",
                (long long)on.stats.tilesDrawn, (long long)on.stats.bundleTrianglesDrawn,
                (long long)off.stats.bundleTrianglesDrawn);
    ASSERT_EQ(on.stats.tilesDrawn, off.stats.tilesDrawn);
    EXPECT_GT(on.stats.tilesDrawn, on.stats.directionsDone);
    EXPECT_LT(on.stats.bundleTrianglesDrawn, off.stats.bundleTrianglesDrawn / 2);
    EXPECT_EQ(on.stats.fragments, off.stats.fragments);
    EXPECT_EQ(differingTexels(on, off), 0u);
}

// The viewer steps tile by tile (a frame need not hold a whole direction):
// the same tiles in the same order, so the same bits as whole directions.
TEST(TilingBake, SteppingByTileGivesTheSameBits) {
    BB_REQUIRE_GL();
    const std::string city = generateTinyCity("steps", "--seed 4");
    ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed";
    BakeOptions o = cityOptions();
    o.bundleMemory = 1 << 20;
    const Baked whole = bakeScene(city, o);
    ASSERT_TRUE(whole.error.empty()) << whole.error;

    SceneBake bake = makeBake(city, cityLayout(), o);
    ASSERT_TRUE(bake) << bake.error;
    int calls = 0, callsMidDirection = 0;
    for (BakeProgress p = bake.baker->progress(); !p.done(); ++calls) {
        p = bake.baker->stepTiles(0.0);
        callsMidDirection += p.midDirection;
    }
    Baked tiled;
    tiled.accumulators = bake.baker->readAccumulators();
    tiled.stats = bake.baker->stats();
    std::printf("[tiling] %d stepTiles calls for %lld tiles, %d of them ended mid-direction\n", calls,
                (long long)tiled.stats.tilesDrawn, callsMidDirection);
    EXPECT_EQ(int64_t(calls), tiled.stats.tilesDrawn);  // one tile per call
    EXPECT_GT(callsMidDirection, 0);
    EXPECT_EQ(tiled.stats.tilesDrawn, whole.stats.tilesDrawn);
    EXPECT_EQ(differingTexels(whole, tiled), 0u);
}

// Runs of whole leaves whose lists fit the buffers together are updated in
// one pass (bundle_tracer.h): each texel is drawn once a run instead of once
// for each tile its cluster meets. mixed_lighting's curved furniture cuts its
// directions into ~20 leaves. Roomy buffers hold a direction in one run; a
// head image of 128^2 cuts it into several; with runs off every tile is
// updated alone. The same bits every way, fewer triangles drawn.
TEST(TilingBake, LeafRunsUpdatedAtOnceGiveTheSameBits) {
    BB_REQUIRE_GL();
    const std::string scene = sourcePath("assets/shared/mixed_lighting/MixedLightingExample.gltf");
    BakeOptions o = skyOptions(6, 2);
    o.supersample = 2;  // as the CLI's auto: the texels the curvature refinement cuts the leaves for
    const Baked roomy = bakeScene(scene, o, packLayout(64));
    ASSERT_TRUE(roomy.error.empty()) << roomy.error;
    o.bundleMemory = (int64_t(1) << 20) - 1;  // a head image of 128^2 (a quarter of it at most), 81919 nodes
    const Baked small = bakeScene(scene, o, packLayout(64));
    ASSERT_TRUE(small.error.empty()) << small.error;
    o.bundleMemory = 0;
    o.leafRuns = false;
    const Baked alone = bakeScene(scene, o, packLayout(64));
    ASSERT_TRUE(alone.error.empty()) << alone.error;
    const auto& leaves = roomy.stats.leavesPerDirection;
    std::printf("[tiling] mixed_lighting, %d directions, %.1f leaves a direction: updates over leaf runs %lld / %lld "
                "/ %lld, update triangles drawn %lld / %lld / %lld (roomy / 128^2 heads / runs off)\n",
                roomy.stats.directionsDone,
                double(std::accumulate(leaves.begin(), leaves.end(), 0)) / double(std::max<size_t>(leaves.size(), 1)),
                (long long)roomy.stats.leafRunUpdates, (long long)small.stats.leafRunUpdates,
                (long long)alone.stats.leafRunUpdates, (long long)roomy.stats.updateTrianglesDrawn,
                (long long)small.stats.updateTrianglesDrawn, (long long)alone.stats.updateTrianglesDrawn);
    EXPECT_EQ(roomy.stats.leafRunUpdates, roomy.stats.directionsDone);  // one run a direction
    EXPECT_GT(small.stats.leafRunUpdates, roomy.stats.leafRunUpdates);
    EXPECT_EQ(alone.stats.leafRunUpdates, 0);
    EXPECT_LT(2 * roomy.stats.updateTrianglesDrawn, alone.stats.updateTrianglesDrawn);
    EXPECT_LT(small.stats.updateTrianglesDrawn, alone.stats.updateTrianglesDrawn);
    EXPECT_EQ(roomy.stats.fragments, alone.stats.fragments);
    EXPECT_EQ(small.stats.fragments, alone.stats.fragments);
    EXPECT_EQ(differingTexels(roomy, alone), 0u);
    EXPECT_EQ(differingTexels(small, alone), 0u);
}

// The projected-area prediction per tile on three generated sizes, cut into
// several tiles by a small budget: median within 20 %, p10 >= 0.5, p90 <= 2.5,
// under 1 % of tiles overflowing. Over-prediction only sizes a buffer larger
// than needed; p90 measured 1.00 / 2.13 / 1.77 on the three sizes (s2 was 1.74
// with the directions before the two-replicate set, bake/directions.h).
TEST(TilingBake, PredictionHoldsOnThreeSizes) {
    BB_REQUIRE_GL();
    struct Size {
        const char* name;
        const char* flags;
    } sizes[] = {{"s1", "--seed 7 --size-m 120 --buildings 40"},
                 {"s2", "--seed 8"},
                 {"s3", "--seed 9 --size-m 320 --buildings 300 --terrain-quads 12"}};
    for (const Size& s : sizes) {
        const std::string city = generateTinyCity(s.name, s.flags);
        ASSERT_FALSE(city.empty()) << "scripts/generate_city.py failed for " << s.flags;
        BakeOptions o = cityOptions();
        o.bundleMemory = 1 << 20;
        const Baked b = bakeScene(city, o);
        ASSERT_TRUE(b.error.empty()) << b.error;
        std::vector<double> r = b.stats.predictedOverActual;
        ASSERT_GT(r.size(), 8u);
        std::sort(r.begin(), r.end());
        auto pct = [&](double q) { return r[size_t(q * (r.size() - 1))]; };
        std::printf("[tiling] %s (%s): %lld triangles, %zu tiles, predicted/actual p10 %.3f median %.3f p90 %.3f, "
                    "%lld overflows\n",
                    s.name, s.flags, (long long)b.stats.triangles, r.size(), pct(0.1), pct(0.5), pct(0.9),
                    (long long)b.stats.overflows);
        EXPECT_NEAR(pct(0.5), 1.0, 0.2) << s.name;
        EXPECT_GE(pct(0.1), 0.5) << s.name;
        EXPECT_LE(pct(0.9), 2.5) << s.name;
        EXPECT_LT(double(b.stats.overflows), 0.01 * double(b.stats.tilesDrawn)) << s.name;
    }
}

}  // namespace
}  // namespace bb::test
