// Bakes with generated light map UVs (--uv-layout generate): the thin-wall
// scene (assets/two_rooms: room A lit by a ceiling panel, room B sealed
// behind a 2 cm slab, see tests/golden/thin_wall_bake_test.cpp) with its
// TEXCOORD_1 replaced by generated charts stays dark in room B: charts 2
// texels apart, dilation and the update pass mix nothing across them.
//
// 50 texels per metre: the slab is one texel thick, as in the thin-wall test.
// Tolerance: max L_lm over room B < 1e-3 x room A's mean (exact answer 0).
// 64 directions (the thin-wall test's 128 halved to keep this test in
// seconds; a leak through a chart border is systematic, not noise).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "support/bake_helper.h"

namespace bb::test {
namespace {

TEST(GeneratedUvBake, SealedRoomStaysDarkWithGeneratedCharts) {
    BB_REQUIRE_GL();
    LayoutOptions layout = packLayout(720);
    layout.mode = UvLayout::Generate;
    layout.texelDensity = 50.0f;
    BakeOptions options;
    options.directions = 64;
    options.seed = 1;
    SceneBake bake = makeBake("assets/two_rooms/two_rooms.gltf", layout, options);
    ASSERT_TRUE(bake) << bake.error;
    const UvGenerationStats& uv = bake.layout.uv;
    ASSERT_GE(uv.meshes, 1u);
    ASSERT_GT(uv.charts, 0u);
    const TexelCoverage cov = measureCoverage(bake.scene, bake.layout);
    EXPECT_EQ(cov.overlapping, 0u);
    const double seconds = bakeToEnd(*bake.baker);
    LightmapPages maps = bake.baker->readLightmaps();
    const BakeMesh& mesh = bake.baker->mesh();
    const int res = maps.resolution;

    Summary roomA, roomB;
    for (int page = 0; page < int(maps.pages.size()); ++page) {
        const std::vector<int> owner = texelTriangles(mesh, res, page);
        const auto& img = maps.pages[size_t(page)];
        const auto& covered = maps.covered[size_t(page)];
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            if (!covered[i]) continue;
            const int t = owner[i] >= 0 ? owner[i] : nearestTriangle(mesh, res, i, page);
            ASSERT_GE(t, 0);
            const double value = std::max({img.pixels[i].r, img.pixels[i].g, img.pixels[i].b});
            if (triangleCentroid(mesh, t).x > 0.0f) roomB.add(value, i);
            else roomA.add(img.pixels[i].g, i);
        }
    }
    roomA.finish();
    roomB.finish();
    std::printf("[generated uv thin wall] %zu charts (%zu LSCM), %d page(s) of %d, %.2f s bake; room A: %s; room B: %s\n",
                uv.charts, uv.lscmCharts, bake.layout.pageCount, res, seconds, describe(roomA, res).c_str(),
                describe(roomB, res).c_str());
    // both rooms are there: 24 m^2 each at 2500 texels per m^2 (less the diagonals' centres)
    ASSERT_GT(roomA.count, 50000u);
    ASSERT_GT(roomB.count, 50000u);
    ASSERT_GT(roomA.mean, 0.1) << "room A is not lit: " << describe(roomA, res);
    EXPECT_LT(roomB.max, 1e-3 * roomA.mean) << "light leaks into the sealed room B: " << describe(roomB, res);
}

}  // namespace
}  // namespace bb::test
