// The path-traced error check (engine/reference/error_check.h) against light
// maps whose error is known exactly: the furnace (Le 1, rho 0.5: L_lm = 2 at
// every texel, ANALYTIC_REFERENCES 1.1) with a chosen error added. No GL.
//
// Tolerances: the check reports its own standard error (meanSquareError); a
// test asks for the truth within 4 of them, and for the standard error to be
// small enough that the test could fail (under a quarter of the squared error
// it measures, at 256 paths per texel and estimate: measured 0.04-0.12 of it).
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "layout/layout.h"
#include "reference/error_check.h"
#include "reference/reference_baker.h"
#include "scene/scene.h"

namespace bb {
namespace {

struct Furnace {
    Scene scene;
    Layout layout;
    LightmapPages truth;  // 2 on every covered texel, the reference's coverage
};

Furnace furnace() {
    auto scene = loadScene(std::string(BUNDLEBAKE_SOURCE_DIR) + "/assets/furnace/furnace.gltf");
    EXPECT_TRUE(scene) << scene.error();
    LayoutOptions lo;
    lo.mode = UvLayout::Asset;
    lo.resolution = 32;
    auto layout = computeLayout(*scene, lo);
    EXPECT_TRUE(layout) << layout.error();
    Furnace f{std::move(scene.value()), std::move(layout.value()), {}};
    auto coverage = ReferenceBaker::create(f.scene, f.layout, ReferenceOptions{});
    EXPECT_TRUE(coverage) << coverage.error();
    f.truth = (*coverage)->readLightmaps();  // no samples yet: only the covered masks are of use
    for (auto& page : f.truth.pages)
        for (auto& v : page.pixels) v = glm::vec3(2.0f);
    return f;
}

ErrorCheck check(const Furnace& f, const LightmapPages& maps, ErrorCheckOptions o = {}) {
    o.spp = 256;
    o.reference.threads = 2;
    o.stitchSeams = false;  // the furnace's maps are not stitched here
    auto result = checkError(f.scene, f.layout, maps, o);
    EXPECT_TRUE(result) << result.error();
    return result ? *result : ErrorCheck{};
}

// Covered texels alternately 3 % high and 3 % low: rel_rmse 0.03, no bias.
TEST(ErrorCheck, MeasuresAKnownNoisePattern) {
    Furnace f = furnace();
    LightmapPages maps = f.truth;
    int k = 0;
    for (size_t i = 0; i < maps.covered[0].size(); ++i)
        if (maps.covered[0][i]) maps.pages[0].pixels[i] *= (k++ % 2 == 0 ? 1.03f : 0.97f);
    ASSERT_GT(k, 500);
    const ErrorCheck c = check(f, maps);
    const double truth = 0.03 * 0.03;
    EXPECT_LT(c.meanSquareError, truth / 4) << "too few paths for the test to tell";
    EXPECT_NEAR(c.meanSquare, truth, 4 * c.meanSquareError);
    EXPECT_TRUE(c.conclusive());
    EXPECT_EQ(c.texels, k);
}

// A subset of the texels (a large map's): the same estimate, over fewer texels.
TEST(ErrorCheck, ASubsetOfTheTexelsMeasuresTheSame) {
    Furnace f = furnace();
    LightmapPages maps = f.truth;
    int k = 0;
    for (size_t i = 0; i < maps.covered[0].size(); ++i)
        if (maps.covered[0][i]) maps.pages[0].pixels[i] *= (k++ % 2 == 0 ? 1.03f : 0.97f);
    ErrorCheckOptions o;
    o.maxTexels = k / 2;
    const ErrorCheck c = check(f, maps, o);
    EXPECT_EQ(c.coveredTexels, k);
    EXPECT_NEAR(double(c.texels), k / 2.0, 4.0 * std::sqrt(k / 4.0)) << "a binomial draw of half the texels";
    const double truth = 0.03 * 0.03;
    EXPECT_LT(c.meanSquareError, truth / 4) << "too few paths for the test to tell";
    EXPECT_NEAR(c.meanSquare, truth, 4 * c.meanSquareError);
}

// Every texel 2 % high: the error is all bias, which the bake's own noise
// estimate (the two halves of the directions) cannot see; the check does.
TEST(ErrorCheck, MeasuresABias) {
    Furnace f = furnace();
    LightmapPages maps = f.truth;
    for (auto& v : maps.pages[0].pixels) v *= 1.02f;
    const ErrorCheck c = check(f, maps);
    const double truth = 0.02 * 0.02;
    EXPECT_LT(c.meanSquareError, truth / 4) << "too few paths for the test to tell";
    EXPECT_NEAR(c.meanSquare, truth, 4 * c.meanSquareError);
    EXPECT_NEAR(c.relRmse, 0.02, 0.005);
    EXPECT_TRUE(c.conclusive());
}

// The exact maps: the estimate is 0 within its error, and says it cannot
// tell an error that small (the reference's noise is all it sees).
TEST(ErrorCheck, ExactMapsReadZeroAndInconclusive) {
    Furnace f = furnace();
    const ErrorCheck c = check(f, f.truth);
    EXPECT_NEAR(c.meanSquare, 0.0, 4 * c.meanSquareError);
    EXPECT_FALSE(c.conclusive());
    EXPECT_GE(c.upperBound, c.relRmse);
}

// The budget: where the pilot says 256 paths could not resolve twice the
// expected error (0.01 %: far under the reference's noise over ~800 texels),
// the fallback's; where they could (5 %), all of them; where they could not
// resolve it but 4096 could resolve twice it, about as many as resolve it
// (the standard error falls as 1 / the paths: twice 256's to resolve an
// error whose square is 1.5 of 256 paths' standard error).
TEST(ErrorCheck, FallsBackWhereTheExpectedErrorCannotBeResolved) {
    Furnace f = furnace();
    ErrorCheckOptions o;
    o.fallbackSpp = 16;
    o.maxSpp = 4096;
    o.expectedError = 1e-4;
    EXPECT_EQ(check(f, f.truth, o).spp, 16);
    o.expectedError = 0.05;
    EXPECT_EQ(check(f, f.truth, o).spp, 256);
    o.expectedError = std::sqrt(1.5 * check(f, f.truth).meanSquareError);
    const int spp = check(f, f.truth, o).spp;
    EXPECT_GT(spp, 256 * 3 / 2);
    EXPECT_LT(spp, 256 * 3);
}

}  // namespace
}  // namespace bb
