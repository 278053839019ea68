// Whole bakes with an analytic answer at every texel: the white furnace
// (ANALYTIC_REFERENCES 1.1) and a uniform sky over an open plane.
//
// Furnace (assets/furnace): a closed cube and a floating inner cube, one
// material everywhere, Le = 1: L_lm = Le / (1 - rho) at every texel
// (2 for rho 0.5, 10 for rho 0.9), occluded or not. Asset layout, 64 x 64.
// There is no sampling noise here (every direction sees the same radiance),
// so what spreads the texels is rounding: RGBE node radiance and the fp16
// accumulators with stochastic rounding (unbiased; the accumulators hold a
// running mean, so this noise does not grow with the number of directions;
// see rounding_bake_test.cpp).
//
// Expected mean: the analytic answer, within 1%. The baker's history ramp
// and radiance-map refresh schedule leave a start-up bias that
// furnaceExpectation() computes (the iteration's exact expectation): rho 0.5
// at 256 directions -0.06%; rho 0.9 at 256 directions -0.8% (-0.9% with the
// fp16 albedo 0.8999 the meta pass stores), too close to 1%, hence 1024
// directions for rho 0.9 (-0.1%, -0.2% with the fp16 albedo).
//
// Per-texel tolerances, measured over seeds 1..20 (OSMesa; EGL gives the same
// bytes, see cli_determinism_test.cpp), all channels, with the engine as of
// 1122b3d and again with the working tree of 16:35 (update.frag's 2-pixel
// reach):
//   rho 0.5, 256 dirs:  mean 1.9980..1.9987, texels 1.9434..2.0271 (worst -2.8%) -> +-4%
//   rho 0.9, 1024 dirs: mean 9.9684..9.9780, texels 9.7056..10.2256 (worst -2.9%) -> +-4%
#include <gtest/gtest.h>

#include <cstdio>

#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

struct FurnaceCase {
    const char* file;
    double rho;
    int directions;
    double texelTolerance;  // relative, every covered texel and channel
    BakeOptions::Tiling tiling = BakeOptions::Tiling::Adaptive;
    double meanTolerance = 0.01;  // relative
    float albedo = -1.0f;         // >= 0: every material's albedo replaced (rho 0.99 from the rho 0.9 file)
    int supersample = 1;          // BakeOptions::supersample
    // The history ramp's plateau (noise.cpp chooseHistoryPlateau): at half the
    // directions where the bounces need it (rho 0.99), earlier elsewhere
    bool rampOverHalf = false;
};

void runFurnace(const FurnaceCase& fc) {
    BB_REQUIRE_GL();
    const double answer = 1.0 / (1.0 - fc.rho);
    BakeOptions options;
    options.directions = fc.directions;
    options.seed = 1;
    options.tiling = fc.tiling;
    options.supersample = fc.supersample;
    SceneBake bake = fc.albedo >= 0.0f ? makeBake(fc.file, assetLayout(64), options,
                                                  [&](Scene& scene) {
                                                      for (Material& m : scene.materials) m.albedo = glm::vec3(fc.albedo);
                                                  })
                                       : makeBake(fc.file, assetLayout(64), options);
    ASSERT_TRUE(bake) << bake.error;
    const double seconds = bakeToEnd(*bake.baker);
    LightmapPages maps = bake.baker->readLightmaps();
    ASSERT_EQ(maps.pages.size(), 1u);
    Summary s = summarizeCovered(maps);
    const double expectation =
        furnaceExpectation(1.0, fc.rho, fc.directions, defaultHistoryPower(fc.rho), bake.baker->stats().historyPlateau);
    std::printf("[furnace] %s, %d directions, %.2f s: %s (answer %.4f, iteration expectation %.4f)\n", fc.file,
                fc.directions, seconds, describe(s, 64).c_str(), answer, expectation);

    const int plateau = bake.baker->stats().historyPlateau;
    if (fc.rampOverHalf)
        EXPECT_EQ(plateau, fc.directions / 2) << "rho " << fc.rho << " needs the ramp over half the directions";
    else
        EXPECT_LT(plateau, fc.directions / 2) << "rho " << fc.rho << ": the lag is gone before half the directions";
    ASSERT_GT(s.count, 3u * 2000u) << "the furnace covers 58% of the 64 x 64 atlas: 2478 texels";
    EXPECT_NEAR(s.mean, answer, fc.meanTolerance * answer)
        << "furnace mean over covered texels is not within " << fc.meanTolerance * 100
        << "% of Le / (1 - rho) = " << answer << " after "
        << fc.directions << " directions; " << describe(s, 64);
    EXPECT_GE(s.min, answer * (1.0 - fc.texelTolerance))
        << "a furnace texel is more than " << fc.texelTolerance * 100 << "% below " << answer << ": "
        << describe(s, 64);
    EXPECT_LE(s.max, answer * (1.0 + fc.texelTolerance))
        << "a furnace texel is more than " << fc.texelTolerance * 100 << "% above " << answer << ": "
        << describe(s, 64);
    EXPECT_EQ(bake.baker->stats().overflows, 0);
}

TEST(FurnaceBake, Rho05Gives2Everywhere) { runFurnace({"assets/furnace/furnace.gltf", 0.5, 256, 0.04}); }

// rho 0.9 at 1024 directions: mean within 0.3 % (issue 11; seed 1 reads
// 9.9932, -0.07 %, the ramp ending at 128; 9.981 while it ran over half the
// directions)
TEST(FurnaceBake, Rho09Gives10Everywhere) {
    runFurnace({"assets/furnace/furnace_rho09.gltf", 0.9, 1024, 0.04, BakeOptions::Tiling::Adaptive, 0.003});
}

// rho 0.99 (answer 100) needs ~700 bounces: the refresh follows every
// direction until rho^b < 1e-3 (baker.cpp). Issue 11: within 2 % at 1024
// directions; seed 1 reads 98.51 (-1.5 %; the ramp's own expectation is
// 99.34), texels 98.25..98.73. It read 97.61 while the history ramp's rescale
// could round a sampled texel's weight to 0 (rescale.comp): a texel that
// then missed a round was read as black for a bounce.
TEST(FurnaceBake, Rho099Gives100Everywhere) {
    runFurnace({"assets/furnace/furnace_rho09.gltf", 0.99, 1024, 0.04, BakeOptions::Tiling::Adaptive, 0.02, 0.99f, 1, true});
}

// ... and at 4096 directions, where the lag is gone, within 0.03 %: at rho
// 0.99 each 1e-6 of samples that read black costs the map 0.01 %, and it
// shows what the bundle lists lose. It read -0.086 % while a ray just
// outside the inner box's outline met its far side's back before its near
// side: the raster covers the snapped triangles, and their planes, read past
// the outline where they cross, had swapped their order. append.frag now
// reads them on the triangle's edge, where the two share a depth, and a tie
// goes to the side the ray sees (update.frag preferred). Black reads: 4.3e-6
// of the samples before, 2.1e-6 with the reads on the edge, 0.36e-6 with
// both. Seed 1 reads 99.9136 (-0.086 %) before both, 99.9977 (-0.002 %)
// since (at 1024 directions, above, 98.41 before).
TEST(FurnaceBake, Rho099At4096DirectionsLosesNoSamples) {
    runFurnace({"assets/furnace/furnace_rho09.gltf", 0.99, 4096, 0.04, BakeOptions::Tiling::Adaptive, 0.0003, 0.99f, 1, true});
}

// The Hermes et al. baseline (--tiling uniform) gives the same answers.
// Half-size texels reduced to the layout's (bake/supersample.h): the same
// answer, on the same texels (seed 1: -0.07 %, texels within 1.6 %)
TEST(FurnaceBake, SupersampledRho09Gives10Everywhere) {
    runFurnace({"assets/furnace/furnace_rho09.gltf", 0.9, 1024, 0.04, BakeOptions::Tiling::Adaptive, 0.003, -1.0f, 2});
}

TEST(FurnaceBake, UniformTilingRho05Gives2Everywhere) {
    runFurnace({"assets/furnace/furnace.gltf", 0.5, 256, 0.04, BakeOptions::Tiling::Uniform});
}
TEST(FurnaceBake, UniformTilingRho09Gives10Everywhere) {
    runFurnace({"assets/furnace/furnace_rho09.gltf", 0.9, 1024, 0.04, BakeOptions::Tiling::Uniform});
}

// Uniform sky S over an upward single-sided plane (assets/sky_plane), albedo
// 0.5: L_lm = S at every texel, whatever the iteration. Asset layout 64 x 64,
// 64 directions. No sampling noise either (the whole upper hemisphere is sky),
// only rounding: measured over seeds 1..10, 64 directions, the worst texel
// was 0.67% off (e.g. 1.20799 for S = 1.2), the mean within 0.01% (with fp16
// sums; with the running mean, seed 1: 0.07% worst).
// Tolerance: mean 1%, every texel 1% (1.5x the worst).
// (When the accumulators held fp16 sums, 256 directions already put the
// worst texel 1.25% off: that noise grew with the direction count. They now
// hold a running mean; see rounding_bake_test.cpp.)
void checkSkyPlane(BakeOptions::Tiling tiling) {
    BB_REQUIRE_GL();
    SkyPlaneBake bake = bakeSkyPlane(64, tiling);
    ASSERT_TRUE(bake.error.empty()) << bake.error;
    const glm::vec3 sky = bake.sky;
    const double seconds = bake.seconds;
    const auto& img = bake.maps.pages[0];
    const auto& cov = bake.maps.covered[0];
    for (int c = 0; c < 3; ++c) {
        Summary s;
        for (size_t i = 0; i < img.pixels.size(); ++i)
            if (cov[i]) s.add(img.pixels[i][c], i);
        s.finish();
        std::printf("[sky plane] channel %d (S = %.2f), 64 directions, %.2f s: %s\n", c, sky[c], seconds,
                    describe(s, 64).c_str());
        ASSERT_GT(s.count, 3500u) << "the plane covers 93% of the 64 x 64 atlas";
        EXPECT_NEAR(s.mean, sky[c], 0.01 * sky[c]) << "channel " << c << ": mean L_lm is not the sky radiance";
        EXPECT_GE(s.min, 0.99 * sky[c]) << "channel " << c << ": a texel is more than 1% below the sky: "
                                        << describe(s, 64);
        EXPECT_LE(s.max, 1.01 * sky[c]) << "channel " << c << ": a texel is more than 1% above the sky: "
                                        << describe(s, 64);
    }
}

TEST(SkyPlaneBake, UniformSkyGivesSkyEverywhere) { checkSkyPlane(BakeOptions::Tiling::Adaptive); }
TEST(SkyPlaneBake, UniformTilingGivesSkyEverywhere) { checkSkyPlane(BakeOptions::Tiling::Uniform); }

}  // namespace
}  // namespace bb::test

namespace bb::test {
namespace {

// Radiance far outside fp16's range (issue 13): the furnace with Le = 1e5
// (L_lm = 2e5, past the fp16 maximum 65504) and Le = 1e-5 (L_lm = 2e-5, fp16
// subnormals) reads its analytic value within the usual 1 % (mean) and 4 %
// (texels): the light-map state holds radiance / a power-of-two unit.
void runScaledFurnace(float le) {
    BB_REQUIRE_GL();
    auto scene = loadScene(sourcePath("assets/furnace/furnace.gltf"));
    ASSERT_TRUE(scene) << scene.error();
    for (Material& m : scene->materials) m.emission *= le;
    auto layout = computeLayout(*scene, assetLayout(64));
    ASSERT_TRUE(layout) << layout.error();
    BakeOptions options;
    options.directions = 256;
    auto baker = Baker::create(*scene, *layout, options);
    ASSERT_TRUE(baker) << baker.error();
    bakeToEnd(**baker);
    const double answer = 2.0 * le;
    Summary s = summarizeCovered((*baker)->readLightmaps());
    std::printf("[furnace Le %g] %s, radiance unit %g\n", le, describe(s, 64).c_str(), (*baker)->stats().radianceUnit);
    EXPECT_NEAR(s.mean, answer, 0.01 * answer) << describe(s, 64);
    EXPECT_GE(s.min, 0.96 * answer) << describe(s, 64);
    EXPECT_LE(s.max, 1.04 * answer) << describe(s, 64);
}

TEST(FurnaceBake, BeyondTheFp16RangeReadsTheAnalyticValue) { runScaledFurnace(1e5f); }
TEST(FurnaceBake, FarBelowOneReadsTheAnalyticValue) { runScaledFurnace(1e-5f); }

// The history ramp's power and the refresh schedule follow the scene's
// transport albedo (defaultHistoryPower, bake/transport_albedo.h), a textured
// material's albedo being its factor times its texture's mean: in a closed
// room of one material, a factor of 1 on a texture of mean 0.5 (texels 0.3
// and 0.7) is rho 0.5 (power 3), not 1 (the cap, 1024: only the last half of
// the directions would count).
TEST(HistoryRamp, TexturedAlbedoCountsAtItsTexturesMean) {
    BB_REQUIRE_GL();
    Scene scene;
    Texture grey;
    grey.name = "grey";
    grey.width = 2;
    grey.height = 1;
    grey.texels = {glm::vec4(0.3f, 0.3f, 0.3f, 1.0f), glm::vec4(0.7f, 0.7f, 0.7f, 1.0f)};
    scene.textures.push_back(grey);
    const int textured = addMaterial(scene, glm::vec3(1.0f));
    scene.materials[size_t(textured)].albedoTexture = 0;
    addBox(scene, glm::vec3(0.0f), glm::vec3(1.0f), textured, false, "room");
    auto layout = packLayout(scene, 32, 4.0f);
    ASSERT_TRUE(layout) << layout.error();
    BakeOptions options;
    options.directions = 4;
    BakeStats stats;
    auto maps = bakeGpu(scene, *layout, options, nullptr, &stats);
    ASSERT_TRUE(maps) << maps.error();
    EXPECT_NEAR(stats.transportAlbedo, 0.5, 1e-3);
    EXPECT_EQ(stats.historyPower, defaultHistoryPower(0.5));
    EXPECT_EQ(defaultHistoryPower(0.5), 3.0);
}

}  // namespace
}  // namespace bb::test
