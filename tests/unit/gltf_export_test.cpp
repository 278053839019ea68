// The glTF export (engine/export/gltf_export.h), GL-free: RGBM round trip
// error, and a two-instance scene exported and read back (shared geometry,
// one TEXCOORD_1 per rectangle, pages from the EXR and from the PNG).
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "export/gltf_export.h"
#include "layout/layout.h"
#include "scene/scene.h"
#include "../support/scratch_dirs.h"

namespace bb {
namespace {

// RGBM error bound (gltf_export.h): the largest channel x (as a fraction of
// the page peak) is off by at most 0.5/255 * a / x relatively, a = ceil(255 x)
// / 255: at most 1/255 (0.39 %) for x >= 1/255, 0.77 % at x = 1e-3 and 7.7 %
// at 1e-4 (a = 1/255 there); 0 stays 0.
TEST(Rgbm, RoundTripErrorAcrossFourDecades) {
    std::vector<glm::vec3> pixels;
    for (int i = 0; i <= 4000; ++i) {
        const float v = std::pow(10.0f, -4.0f + float(i) / 1000.0f) * 123.0f;  // 1e-4 .. 1 of 123
        pixels.push_back(glm::vec3(v, v * 0.5f, v * 0.25f));
    }
    pixels.push_back(glm::vec3(0.0f));
    const float scale = rgbmScale(pixels);
    EXPECT_NEAR(scale * RGBM_RANGE, 123.0f, 1e-3f);
    const std::vector<uint8_t> rgba = encodeRgbm(pixels, scale);
    double worstHigh = 0, worst3 = 0, worst4 = 0;
    for (size_t i = 0; i + 1 < pixels.size(); ++i) {
        const glm::vec3 d = decodeRgbm(&rgba[4 * i], scale);
        const double rel = std::abs(double(d.r) - pixels[i].r) / pixels[i].r;
        if (pixels[i].r >= 123.0f / 255.0f) worstHigh = std::max(worstHigh, rel);
        if (pixels[i].r >= 123.0f * 1e-3f) worst3 = std::max(worst3, rel);
        worst4 = std::max(worst4, rel);
    }
    EXPECT_LE(worstHigh, 1.0 / 255.0 + 1e-6) << "1/255 .. 1 of the peak";
    EXPECT_LE(worst3, 0.0078) << "1e-3 .. 1 of the peak";
    EXPECT_LE(worst4, 0.078) << "1e-4 .. 1 of the peak";
    EXPECT_EQ(decodeRgbm(&rgba[4 * (pixels.size() - 1)], scale), glm::vec3(0.0f));
}

// A quad mesh (no TEXCOORD_1) used by two nodes: the pack layout gives each
// its own rectangle, so the export writes two meshes over one geometry.
std::string writeTwoQuadScene(const std::filesystem::path& dir) {
    std::filesystem::create_directories(dir);
    const float positions[12] = {0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1};
    const float normals[12] = {0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1, 0};
    const uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
    std::ofstream bin(dir / "quad.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(positions), 48);
    bin.write(reinterpret_cast<const char*>(normals), 48);
    bin.write(reinterpret_cast<const char*>(indices), 12);
    bin.close();
    nlohmann::json g = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0, 1}}}}},
        {"nodes", {{{"name", "a"}, {"mesh", 0}}, {{"name", "b"}, {"mesh", 0}, {"translation", {3, 0, 0}}}}},
        {"materials", {{{"name", "grey"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.5, 0.5, 1}}, {"metallicFactor", 0}}}}}},
        {"meshes", {{{"name", "quad"}, {"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}, {"material", 0}}}}}}},
        {"buffers", {{{"uri", "quad.bin"}, {"byteLength", 108}}}},
        {"bufferViews",
         {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}},
          {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 48}},
          {{"buffer", 0}, {"byteOffset", 96}, {"byteLength", 12}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {0, 0, -1}}, {"max", {1, 0, 0}}},
          {{"bufferView", 1}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}},
          {{"bufferView", 2}, {"componentType", 5123}, {"count", 6}, {"type", "SCALAR"}}}},
    };
    std::ofstream(dir / "two_quads.gltf") << g.dump(1);
    return (dir / "two_quads.gltf").string();
}

nlohmann::json glbJson(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    uint32_t length = 0;
    std::memcpy(&length, bytes.data() + 12, 4);
    return nlohmann::json::parse(bytes.begin() + 20, bytes.begin() + 20 + length);
}

TEST(GltfExport, InstancesInTwoRectanglesShareGeometryAndReadBack) {
    const std::filesystem::path dir =
        test::removeAtExit(::testing::TempDir() + "/export_unit_" + std::to_string(::getpid()));
    const std::string source = writeTwoQuadScene(dir);
    auto scene = loadScene(source);
    ASSERT_TRUE(scene) << scene.error();
    LayoutOptions lo;
    lo.resolution = 32;
    auto layout = computeLayout(*scene, lo);
    ASSERT_TRUE(layout) << layout.error();
    ASSERT_EQ(scene->instances.size(), 2u);
    ASSERT_EQ(scene->instances[0].mesh, scene->instances[1].mesh);
    ASSERT_NE(layout->rects[0].offset, layout->rects[1].offset);

    // a page with a gradient of magnitudes (L_lm 0.01 .. 50)
    LightmapPages maps;
    maps.resolution = 32;
    io::ImageRgb page;
    page.width = page.height = 32;
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) page.pixels.push_back(glm::vec3(0.01f + 50.0f * x / 31.0f, 1.0f + y, 0.5f));
    maps.pages.push_back(page);
    maps.covered.push_back(std::vector<uint8_t>(page.pixels.size(), 1));

    const std::string out = (dir / "baked.glb").string();
    auto report = exportBakedGltf(source, *scene, *layout, maps, out);
    ASSERT_TRUE(report) << report.error();
    EXPECT_EQ(report->meshes, 2u);
    EXPECT_EQ(report->sharedGeometry, 1u);
    ASSERT_EQ(report->exrFiles.size(), 1u);
    EXPECT_TRUE(std::filesystem::exists(dir / "baked.lightmap_0.exr"));

    const nlohmann::json j = glbJson(out);
    ASSERT_EQ(j["meshes"].size(), 2u);
    const auto& p0 = j["meshes"][0]["primitives"][0]["attributes"];
    const auto& p1 = j["meshes"][1]["primitives"][0]["attributes"];
    EXPECT_EQ(p0["POSITION"], p1["POSITION"]);
    EXPECT_NE(p0["TEXCOORD_1"], p1["TEXCOORD_1"]);
    EXPECT_EQ(j["nodes"][1]["extras"]["bundlebake_lightmap"]["page"], 0);
    EXPECT_EQ(j["extras"]["bundlebake_lightmaps"]["encoding"], "RGBM");

    // read back: TEXCOORD_1 is the page UV the bake used
    auto back = loadScene(out);
    ASSERT_TRUE(back) << back.error();
    ASSERT_EQ(back->instances.size(), 2u);
    for (size_t i = 0; i < 2; ++i) {
        const Primitive& a = scene->meshes[size_t(scene->instances[i].mesh)].primitives[0];
        const Primitive& b = back->meshes[size_t(back->instances[i].mesh)].primitives[0];
        ASSERT_EQ(a.uv1.size(), b.uv1.size());
        for (size_t v = 0; v < a.uv1.size(); ++v)
            EXPECT_EQ(b.uv1[v], a.uv1[v] * layout->rects[i].scale + layout->rects[i].offset) << "instance " << i;
    }
    auto fromExr = readExportedLightmaps(out, *back);
    ASSERT_TRUE(fromExr) << fromExr.error();
    EXPECT_EQ(fromExr->source, "exr");
    ASSERT_EQ(fromExr->maps.pages.size(), 1u);
    for (size_t i = 0; i < page.pixels.size(); ++i)
        EXPECT_NEAR(fromExr->maps.pages[0].pixels[i].r, page.pixels[i].r, 1e-3f * page.pixels[i].r);  // half floats
    std::filesystem::remove(dir / "baked.lightmap_0.exr");
    auto fromPng = readExportedLightmaps(out, *back);
    ASSERT_TRUE(fromPng) << fromPng.error();
    EXPECT_EQ(fromPng->source, "rgbm png");
    for (size_t i = 0; i < page.pixels.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float want = page.pixels[i][c];
            const float peakChannel = std::max(std::max(page.pixels[i].r, page.pixels[i].g), page.pixels[i].b);
            // the largest channel to 0.4 % (above 1e-3 of the peak), the others to 1/255 of it
            EXPECT_NEAR(fromPng->maps.pages[0].pixels[i][c], want, 0.004f * peakChannel + 1e-6f) << i << " " << c;
        }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace bb
