// Golden image of the scene renderer (engine/render/scene_renderer.h) on a
// fixed bake: the Cornell box (assets/cornell_box/cornell_box.gltf, asset
// layout, 128^2 texels), 128 directions, seed 1, every other option at its
// default, seen from its glTF camera 0 at 256x256, exposure 0.
//
// Compared in 8-bit sRGB-encoded values (what is seen) against
// assets/goldens/cornell_box_render.png:
//   RMSE over all channels <= GOLDEN_RMSE_TOLERANCE levels, and
//   max |difference| <= GOLDEN_MAX_TOLERANCE levels.
// Why these numbers: on Mesa 22.3 llvmpipe the render is bit-identical run to
// run and between EGL and OSMesa (RMSE 0), and the CLI path (EXR half floats)
// differs by at most 1 level (RMSE ~0.06); the tolerance leaves room for other
// Mesa/LLVM builds (+-1 level rounding everywhere, a few silhouette pixels),
// while one stop of exposure gives RMSE ~33 (ExposurePerturbationIsDetected).
// Any change to the bake's bytes (directions, resolve, rounding) moves the
// image beyond it: re-promote after reviewing the new picture.
// On failure the actual image and an amplified difference (x8) are written to
// golden_out/ under the working directory (ctest: <build>/tests/golden_out).
// Regenerate with scripts/promote-goldens.sh (BUNDLEBAKE_PROMOTE_GOLDENS=1).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "render/scene_renderer.h"
#include "support/bake_helper.h"

namespace bb::test {
namespace {

constexpr double GOLDEN_RMSE_TOLERANCE = 1.5;  // levels of 255
constexpr int GOLDEN_MAX_TOLERANCE = 48;       // levels of 255 (a few edge pixels may flip)
constexpr int IMAGE_SIZE = 256;
const char* GOLDEN = "assets/goldens/cornell_box_render.png";

struct ImageDiff {
    double rmse = 0;       // levels
    int maxError = 0;      // levels
    int maxX = 0, maxY = 0;
    size_t pixelsOver8 = 0;
    bool sizeMismatch = false;
    bool within() const {
        return !sizeMismatch && rmse <= GOLDEN_RMSE_TOLERANCE && maxError <= GOLDEN_MAX_TOLERANCE;
    }
    std::string describe() const {
        if (sizeMismatch) return "image sizes differ";
        char s[256];
        std::snprintf(s, sizeof s,
                      "RMSE %.3f levels (tolerance %.2f), max error %d levels at (%d, %d) (tolerance %d), %zu pixels "
                      "differ by more than 8",
                      rmse, GOLDEN_RMSE_TOLERANCE, maxError, maxX, maxY, GOLDEN_MAX_TOLERANCE, pixelsOver8);
        return s;
    }
};

ImageDiff compare(const Image8& actual, const Image8& expected) {
    ImageDiff d;
    if (actual.width != expected.width || actual.height != expected.height) {
        d.sizeMismatch = true;
        return d;
    }
    double sum = 0;
    for (int y = 0; y < actual.height; ++y)
        for (int x = 0; x < actual.width; ++x) {
            int pixelMax = 0;
            for (int c = 0; c < 3; ++c) {
                const int e = std::abs(int(actual.at(x, y, c)) - int(expected.at(x, y, c)));
                sum += double(e) * e;
                pixelMax = std::max(pixelMax, e);
            }
            if (pixelMax > 8) ++d.pixelsOver8;
            if (pixelMax > d.maxError) d.maxError = pixelMax, d.maxX = x, d.maxY = y;
        }
    d.rmse = std::sqrt(sum / (3.0 * actual.width * actual.height));
    return d;
}

Image8 diffImage(const Image8& a, const Image8& b) {
    Image8 d = a;
    for (size_t i = 0; i < d.rgb.size(); ++i) d.rgb[i] = uint8_t(std::min(255, 8 * std::abs(int(a.rgb[i]) - int(b.rgb[i]))));
    return d;
}

// The fixed bake and its renderer, made once per test binary.
struct GoldenScene {
    SceneBake bake;
    std::unique_ptr<SceneRenderer> renderer;
    std::string error;
    double bakeSeconds = 0;
};

GoldenScene& goldenScene() {
    static GoldenScene g = [] {
        GoldenScene s;
        BakeOptions options;
        options.directions = 128;
        options.seed = 1;
        s.bake = makeBake("assets/cornell_box/cornell_box.gltf", assetLayout(128), options);
        if (!s.bake) {
            s.error = s.bake.error;
            return s;
        }
        s.bakeSeconds = bakeToEnd(*s.bake.baker);
        auto renderer = SceneRenderer::create(s.bake.scene, s.bake.baker->mesh(), s.bake.layout.resolution);
        if (!renderer) {
            s.error = renderer.error();
            return s;
        }
        s.renderer = std::move(renderer.value());
        s.bake.baker->resolveLightmaps();
        s.renderer->useLightmapTexture(s.bake.baker->lightmapTextureId());
        return s;
    }();
    return g;
}

Image8 renderCornell(float exposure) {
    GoldenScene& g = goldenScene();
    RenderSettings settings;
    settings.exposure = exposure;
    const Camera& camera = g.bake.scene.cameras.at(0);
    return g.renderer->renderImage(viewFromCamera(camera, 1.0f, g.bake.baker->mesh().bounds), settings, IMAGE_SIZE,
                                   IMAGE_SIZE);
}

bool promoting() {
    const char* env = std::getenv("BUNDLEBAKE_PROMOTE_GOLDENS");
    return env && std::string(env) == "1";
}

TEST(RenderGolden, CornellBoxMatchesGolden) {
    BB_REQUIRE_GL();
    GoldenScene& g = goldenScene();
    ASSERT_TRUE(g.error.empty()) << g.error;
    ASSERT_FALSE(g.bake.scene.cameras.empty());
    std::printf("fixed bake: 128 directions in %.1f s\n", g.bakeSeconds);
    const Image8 actual = renderCornell(0.0f);

    if (promoting()) {
        std::filesystem::create_directories(std::filesystem::path(sourcePath(GOLDEN)).parent_path());
        ASSERT_TRUE(writeImagePng(sourcePath(GOLDEN), actual)) << "cannot write " << sourcePath(GOLDEN);
        std::printf("promoted %s\n", sourcePath(GOLDEN).c_str());
        return;
    }
    auto expected = readImage8(sourcePath(GOLDEN));
    ASSERT_TRUE(expected) << expected.error() << " (make it with scripts/promote-goldens.sh)";
    const ImageDiff diff = compare(actual, *expected);
    std::printf("golden %s: %s\n", GOLDEN, diff.describe().c_str());
    if (!diff.within()) {
        std::filesystem::create_directories("golden_out");
        const std::string dir = std::filesystem::absolute("golden_out").string();
        writeImagePng(dir + "/cornell_box_render.actual.png", actual);
        if (!diff.sizeMismatch) writeImagePng(dir + "/cornell_box_render.diff.png", diffImage(actual, *expected));
        ADD_FAILURE() << "render differs from " << GOLDEN << ": " << diff.describe() << "; wrote " << dir
                      << "/cornell_box_render.{actual,diff}.png";
    }
}

// The tolerance has teeth: one stop of exposure must fail it.
TEST(RenderGolden, ExposurePerturbationIsDetected) {
    BB_REQUIRE_GL();
    if (promoting()) GTEST_SKIP() << "promoting goldens";
    GoldenScene& g = goldenScene();
    ASSERT_TRUE(g.error.empty()) << g.error;
    auto expected = readImage8(sourcePath(GOLDEN));
    ASSERT_TRUE(expected) << expected.error();
    const ImageDiff diff = compare(renderCornell(1.0f), *expected);
    std::printf("exposure +1: %s\n", diff.describe().c_str());
    EXPECT_FALSE(diff.within()) << "a render one stop brighter passes the golden tolerance: " << diff.describe();
}

// The same bake through the command line: `bundlebake bake` writes EXR pages
// (half floats), `bundlebake render` reads them back and draws with the same
// renderer: the disk path must match the live golden within the tolerance.
TEST(RenderGolden, CliBakeThenRenderMatchesGolden) {
    BB_REQUIRE_GL();
    if (promoting()) GTEST_SKIP() << "promoting goldens";
    const std::string dir = testing::TempDir() + "/bundlebake_render_golden";
    std::filesystem::remove_all(dir);
    const std::string scene = sourcePath("assets/cornell_box/cornell_box.gltf");
    const std::string backend = defaultTestBackend() == Backend::Egl ? "egl" : "osmesa";
    const std::string layout = " --uv-layout asset --resolution 128 --backend " + backend;
    const std::string bake = std::string(BUNDLEBAKE_CLI) + " -q bake '" + scene + "' -o '" + dir +
                             "/maps' --directions 128 --seed 1 --no-progress --no-preview" + layout;
    ASSERT_EQ(std::system(bake.c_str()), 0) << bake;
    const std::string png = dir + "/render.png";
    const std::string render = std::string(BUNDLEBAKE_CLI) + " -q render '" + scene + "' '" + dir + "/maps' -o '" + png +
                               "' --camera 0 --width 256 --exposure 0" + layout;
    ASSERT_EQ(std::system(render.c_str()), 0) << render;
    auto actual = readImage8(png);
    ASSERT_TRUE(actual) << actual.error();
    auto expected = readImage8(sourcePath(GOLDEN));
    ASSERT_TRUE(expected) << expected.error();
    const ImageDiff diff = compare(*actual, *expected);
    std::printf("bundlebake bake + render: %s\n", diff.describe().c_str());
    EXPECT_TRUE(diff.within()) << diff.describe() << " (image kept in " << dir << ")";
    if (diff.within()) std::filesystem::remove_all(dir);
}

// The Cornell box's light is in the picture and lit walls are coloured: a
// sanity check that does not depend on the stored golden.
TEST(RenderGolden, CornellBoxWallsShowColourBleeding) {
    BB_REQUIRE_GL();
    GoldenScene& g = goldenScene();
    ASSERT_TRUE(g.error.empty()) << g.error;
    const Image8 image = renderCornell(0.0f);
    // camera 0 looks down +Z: the red wall (x = 0.55) is on the image's left, green on the right
    auto mean = [&](int x0, int x1, int y0, int y1) {
        glm::dvec3 m(0.0);
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) m += glm::dvec3(image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2));
        return m / double((x1 - x0) * (y1 - y0));
    };
    const glm::dvec3 left = mean(8, 30, 100, 160), right = mean(226, 248, 100, 160), back = mean(100, 156, 60, 120);
    std::printf("left wall (%.0f, %.0f, %.0f), right wall (%.0f, %.0f, %.0f), back wall (%.0f, %.0f, %.0f)\n", left.r,
                left.g, left.b, right.r, right.g, right.b, back.r, back.g, back.b);
    EXPECT_GT(left.r, 2.0 * left.g) << "left wall should be red";
    EXPECT_GT(right.g, 1.3 * right.r) << "right wall should be green";
    EXPECT_GT(back.r + back.g + back.b, 150.0) << "back wall should be lit";
}

}  // namespace
}  // namespace bb::test
