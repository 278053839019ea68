// The scene renderer (engine/render/scene_renderer.h) against the CPU: its
// display transform is io::writePngToneMapped's, pixel for pixel; the view
// modes show what they say; it leaves the GL state the Baker assumes.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <unistd.h>

#include <glm/gtc/matrix_transform.hpp>

#include "gl/gl.h"
#include "io/image_io.h"
#include "layout/bake_mesh.h"
#include "render/scene_renderer.h"
#include "support/bake_helper.h"
#include "support/gl_fixture.h"

namespace bb::test {
namespace {

// The furnace (one material everywhere: albedo 0.5, Le = 1) seen from inside,
// so every pixel shows albedo * L_lm + Le of a uniform light map.
struct Furnace {
    Scene scene;
    Layout layout;
    BakeMesh mesh;
    std::unique_ptr<SceneRenderer> renderer;
    Camera camera;
};

Furnace makeFurnace() {
    Furnace f;
    auto scene = loadScene(sourcePath("assets/furnace/furnace.gltf"));
    EXPECT_TRUE(scene) << scene.error();
    f.scene = std::move(scene.value());
    auto layout = computeLayout(f.scene, assetLayout(32));
    EXPECT_TRUE(layout) << layout.error();
    f.layout = std::move(layout.value());
    f.mesh = buildBakeMesh(f.scene, f.layout);
    auto renderer = SceneRenderer::create(f.scene, f.mesh, f.layout.resolution);
    EXPECT_TRUE(renderer) << renderer.error();
    if (renderer) f.renderer = std::move(renderer.value());
    // inside the box, looking at the z = -0.5 wall past the inner cube
    f.camera.worldFromCamera = glm::inverse(glm::lookAt(glm::vec3(0.1f, 0.5f, 0.35f), glm::vec3(-0.1f, 0.45f, -0.5f),
                                                        glm::vec3(0, 1, 0)));
    f.camera.yfov = 1.0f;
    f.camera.znear = 0.01f;
    return f;
}

LightmapPages uniformPages(int resolution, float value) {
    LightmapPages maps;
    maps.resolution = resolution;
    io::ImageRgb page;
    page.width = page.height = resolution;
    page.pixels.assign(size_t(resolution) * resolution, glm::vec3(value));
    maps.pages.push_back(page);
    maps.covered.push_back(std::vector<uint8_t>(page.pixels.size(), 1));
    return maps;
}

// The byte writePngToneMapped writes for `radiance` at `exposure`, read back.
int cpuToneMapped(float radiance, float exposure) {
    io::ImageRgb one;
    one.width = one.height = 1;
    one.pixels = {glm::vec3(radiance)};
    // one file per process: ctest runs these tests side by side, and one's
    // remove took the other's probe before it was read (a clean-clone run)
    const std::string path = testing::TempDir() + "/tonemap_probe_" + std::to_string(::getpid()) + ".png";
    EXPECT_TRUE(io::writePngToneMapped(path, one, exposure));
    auto back = readImage8(path);
    EXPECT_TRUE(back) << back.error();
    std::filesystem::remove(path);
    return back ? back->rgb[0] : -1;
}

// Every pixel of the image, channel 0, must be `expected` (+-1 for the GPU's float rounding).
void expectUniform(const Image8& image, int expected, const std::string& what) {
    int worst = 0, worstValue = expected;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x)
            for (int c = 0; c < 3; ++c) {
                const int v = image.at(x, y, c);
                if (std::abs(v - expected) > worst) worst = std::abs(v - expected), worstValue = v;
            }
    EXPECT_LE(worst, 1) << what << ": expected " << expected << " everywhere, found " << worstValue;
}

TEST(SceneRenderer, LitViewIsTheBakePreviewCurve) {
    BB_REQUIRE_GL();
    Furnace f = makeFurnace();
    ASSERT_TRUE(f.renderer);
    const RenderView view = viewFromCamera(f.camera, 1.0f, f.mesh.bounds);
    for (float lightmap : {0.0f, 0.3f, 1.0f, 2.0f, 40.0f}) {
        f.renderer->uploadLightmaps(uniformPages(f.layout.resolution, lightmap));
        for (float exposure : {-3.0f, 0.0f, 1.5f}) {
            RenderSettings settings;
            settings.exposure = exposure;
            const Image8 image = f.renderer->renderImage(view, settings, 24, 24);
            const float radiance = 0.5f * lightmap + 1.0f;  // albedo * L_lm + Le
            expectUniform(image, cpuToneMapped(radiance, exposure),
                          "L_lm " + std::to_string(lightmap) + ", exposure " + std::to_string(exposure));
        }
    }
}

TEST(SceneRenderer, ViewModesShowWhatTheySay) {
    BB_REQUIRE_GL();
    Furnace f = makeFurnace();
    ASSERT_TRUE(f.renderer);
    f.renderer->uploadLightmaps(uniformPages(f.layout.resolution, 0.8f));
    const RenderView view = viewFromCamera(f.camera, 1.0f, f.mesh.bounds);
    RenderSettings settings;
    settings.mode = ViewMode::Lightmap;
    expectUniform(f.renderer->renderImage(view, settings, 16, 16), cpuToneMapped(0.8f, 0.0f), "light map only");
    settings.mode = ViewMode::Albedo;  // sRGB(0.5) = 0.7354 -> 188
    expectUniform(f.renderer->renderImage(view, settings, 16, 16), 188, "albedo");
    // no importance: the mode falls back to lit
    EXPECT_FALSE(f.renderer->hasImportance());
    settings.mode = ViewMode::Importance;
    expectUniform(f.renderer->renderImage(view, settings, 16, 16), cpuToneMapped(1.4f, 0.0f), "importance (none)");
    EXPECT_FALSE(f.renderer->setImportance(std::vector<float>(3, 1.0f)));  // wrong size
    std::vector<float> importance(f.mesh.triangleCount(), 100.0f);
    ASSERT_TRUE(f.renderer->setImportance(importance));
    EXPECT_TRUE(f.renderer->hasImportance());
    const Image8 heat = f.renderer->renderImage(view, settings, 16, 16);
    EXPECT_NE(heat.at(8, 8, 0), f.renderer->renderImage(view, RenderSettings{}, 16, 16).at(8, 8, 0));
    // texel density: a checkerboard has two levels
    settings.mode = ViewMode::TexelDensity;
    const Image8 checker = f.renderer->renderImage(view, settings, 64, 64);
    int low = 255, high = 0;
    for (int y = 0; y < 64; ++y)
        for (int x = 0; x < 64; ++x) low = std::min<int>(low, checker.at(x, y, 0)), high = std::max<int>(high, checker.at(x, y, 0));
    EXPECT_GT(high - low, 60) << "checkerboard levels " << low << " and " << high;
}

TEST(SceneRenderer, LeavesTheStateTheBakerAssumes) {
    BB_REQUIRE_GL();
    Furnace f = makeFurnace();
    ASSERT_TRUE(f.renderer);
    f.renderer->renderImage(viewFromCamera(f.camera, 1.0f, f.mesh.bounds), RenderSettings{}, 8, 8);
    EXPECT_FALSE(glIsEnabled(GL_DEPTH_TEST));
    EXPECT_FALSE(glIsEnabled(GL_CULL_FACE));
    EXPECT_FALSE(glIsEnabled(GL_BLEND));
    GLint fbo = -1, program = -1, vao = -1;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &fbo);
    glGetIntegerv(GL_CURRENT_PROGRAM, &program);
    glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao);
    EXPECT_EQ(fbo, 0);
    EXPECT_EQ(program, 0);
    EXPECT_EQ(vao, 0);
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

// A live bake drawn through Baker::lightmapTextureId() shows what
// readLightmaps() returns (same resolve), and rendering between steps does
// not change the bake's bytes.
TEST(SceneRenderer, LiveBakeTextureMatchesReadBackAndBakeIsUndisturbed) {
    BB_REQUIRE_GL();
    BakeOptions options;
    options.directions = 8;
    auto reference = makeBake("assets/furnace/furnace.gltf", assetLayout(32), options);
    ASSERT_TRUE(reference) << reference.error;
    bakeToEnd(*reference.baker);
    const LightmapPages expected = reference.baker->readLightmaps();
    reference.baker.reset();

    auto live = makeBake("assets/furnace/furnace.gltf", assetLayout(32), options);
    ASSERT_TRUE(live) << live.error;
    auto renderer = SceneRenderer::create(live.scene, live.baker->mesh(), live.layout.resolution);
    ASSERT_TRUE(renderer) << renderer.error();
    Furnace f = makeFurnace();
    const RenderView view = viewFromCamera(f.camera, 1.0f, live.baker->mesh().bounds);
    RenderSettings settings;
    settings.tileOverlay = true;
    while (!live.baker->step(0.0).done()) {
        live.baker->resolveLightmaps();
        (*renderer)->useLightmapTexture(live.baker->lightmapTextureId());
        (*renderer)->setBundleGrid(live.baker->bundleGrid());
        (*renderer)->renderImage(view, settings, 32, 32);
    }
    const Baker::BundleGrid grid = live.baker->bundleGrid();
    EXPECT_GT(grid.tiles, 0);
    EXPECT_GE(grid.tileStep, 1);
    EXPECT_LE(grid.tileStep, grid.gridSize);
    const LightmapPages actual = live.baker->readLightmaps();
    ASSERT_EQ(actual.pages.size(), expected.pages.size());
    EXPECT_EQ(actual.pages[0].pixels, expected.pages[0].pixels) << "rendering between steps changed the bake";
    live.baker->resolveLightmaps();
    (*renderer)->useLightmapTexture(live.baker->lightmapTextureId());
    const LightmapPages shown = (*renderer)->readLightmaps();
    ASSERT_EQ(shown.pages.size(), 1u);
    EXPECT_EQ(shown.pages[0].pixels, expected.pages[0].pixels);
}

}  // namespace
}  // namespace bb::test
