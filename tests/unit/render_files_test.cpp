// GL-free parts of engine/render: 8-bit PNG round trip, reading a bake's
// output directory back (and refusing one of another layout), cameras.
#include <gtest/gtest.h>

#include <filesystem>

#include "bake/bake_output.h"
#include "render/scene_renderer.h"

namespace bb {
namespace {

std::string tempDir(const std::string& name) {
    const std::string dir = testing::TempDir() + "/bundlebake_render_" + name;
    std::filesystem::remove_all(dir);
    return dir;
}

TEST(RenderFiles, Image8PngKeepsEveryByte) {
    Image8 image;
    image.width = 256;
    image.height = 2;
    image.rgb.resize(size_t(image.width) * image.height * 3);
    for (size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = uint8_t((i / 3 + i % 3 * 85) % 256);
    const std::string path = tempDir("png") + ".png";
    ASSERT_TRUE(writeImagePng(path, image));
    auto back = readImage8(path);
    ASSERT_TRUE(back) << back.error();
    EXPECT_EQ(back->width, 256);
    EXPECT_EQ(back->height, 2);
    EXPECT_EQ(back->rgb, image.rgb);
    std::filesystem::remove(path);
}


struct Baked {
    Scene scene;
    Layout layout;
    LightmapPages maps;
};

Baked fakeBake(int resolution) {
    Baked b;
    auto scene = loadScene(std::string(BUNDLEBAKE_SOURCE_DIR) + "/assets/furnace/furnace.gltf");
    EXPECT_TRUE(scene) << scene.error();
    b.scene = std::move(scene.value());
    LayoutOptions lo;
    lo.mode = UvLayout::Asset;
    lo.resolution = resolution;
    b.layout = computeLayout(b.scene, lo).value();
    b.maps.resolution = resolution;
    io::ImageRgb page;
    page.width = page.height = resolution;
    for (int y = 0; y < resolution; ++y)
        for (int x = 0; x < resolution; ++x) page.pixels.push_back(glm::vec3(0.25f * x, 0.5f, float(y)));
    b.maps.pages.push_back(page);
    b.maps.covered.push_back(std::vector<uint8_t>(page.pixels.size(), 1));
    b.maps.covered[0][0] = 0;
    return b;
}

TEST(RenderFiles, ReadsWhatTheBakeWrites) {
    Baked b = fakeBake(16);
    const std::string dir = tempDir("roundtrip");
    BakeOutputInfo info;
    info.writePreviews = false;
    ASSERT_TRUE(writeBakeOutputs(dir, b.scene, b.layout, b.maps, nlohmann::json::object(), info));
    auto maps = readBakedLightmaps(dir, b.layout);
    ASSERT_TRUE(maps) << maps.error();
    ASSERT_EQ(maps->pages.size(), 1u);
    EXPECT_EQ(maps->resolution, 16);
    for (size_t i = 0; i < b.maps.pages[0].pixels.size(); ++i)
        ASSERT_NEAR(maps->pages[0].pixels[i].x, b.maps.pages[0].pixels[i].x, 4e-3) << i;  // half float
    EXPECT_EQ(maps->covered[0][0], 0);
    EXPECT_EQ(maps->covered[0][1], 1);
    std::filesystem::remove_all(dir);
}

TEST(RenderFiles, RefusesLightMapsOfAnotherLayout) {
    Baked b = fakeBake(16);
    const std::string dir = tempDir("mismatch");
    BakeOutputInfo info;
    info.writePreviews = false;
    ASSERT_TRUE(writeBakeOutputs(dir, b.scene, b.layout, b.maps, nlohmann::json::object(), info));
    Baked other = fakeBake(32);
    auto maps = readBakedLightmaps(dir, other.layout);
    ASSERT_FALSE(maps);
    EXPECT_NE(maps.error().find("--resolution"), std::string::npos) << maps.error();
    auto missing = readBakedLightmaps(dir + "/nope", b.layout);
    ASSERT_FALSE(missing);
    EXPECT_NE(missing.error().find("manifest.json"), std::string::npos) << missing.error();
    std::filesystem::remove_all(dir);
}

TEST(RenderFiles, FramingCameraSeesTheWholeBounds) {
    Bounds bounds;
    bounds.extend(glm::vec3(-1, 0, -2));
    bounds.extend(glm::vec3(3, 1, 2));
    for (float aspect : {0.5f, 1.0f, 2.0f}) {
        Camera c = framingCamera(bounds, DEFAULT_FRAMING_DIRECTION, 0.8f, aspect);
        RenderView v = viewFromCamera(c, aspect, bounds);
        for (int k = 0; k < 8; ++k) {
            glm::vec3 corner((k & 1) ? bounds.max.x : bounds.min.x, (k & 2) ? bounds.max.y : bounds.min.y,
                             (k & 4) ? bounds.max.z : bounds.min.z);
            glm::vec4 clip = v.clipFromView * v.viewFromWorld * glm::vec4(corner, 1.0f);
            ASSERT_GT(clip.w, 0.0f);
            glm::vec3 ndc = glm::vec3(clip) / clip.w;
            EXPECT_LE(std::abs(ndc.x), 1.0f) << "aspect " << aspect << " corner " << k;
            EXPECT_LE(std::abs(ndc.y), 1.0f) << "aspect " << aspect << " corner " << k;
            EXPECT_LE(std::abs(ndc.z), 1.0f) << "aspect " << aspect << " corner " << k;
        }
    }
}

TEST(RenderFiles, ViewModeNamesRoundTrip) {
    for (int m = 0; m < VIEW_MODE_COUNT; ++m) EXPECT_EQ(int(parseViewMode(viewModeName(ViewMode(m))).value()), m);
    EXPECT_FALSE(parseViewMode("shiny"));
}

}  // namespace
}  // namespace bb
