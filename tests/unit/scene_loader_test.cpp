// glTF scene loader (engine/scene): the four shared scenes with figures measured
// independently from their JSON and buffers, a hand-built glTF that covers the
// conversion rules one by one, and reject tests for every error path.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "core/log.h"
#include "io/stb_codec.h"
#include "scene/scene.h"

namespace bb {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr int BYTE = 5120;
constexpr int UNSIGNED_BYTE = 5121;
constexpr int UNSIGNED_SHORT = 5123;
constexpr int FLOAT = 5126;
constexpr int MODE_LINES = 1;
constexpr int MODE_TRIANGLE_STRIP = 5;
constexpr int MODE_TRIANGLE_FAN = 6;

// --- helpers ---------------------------------------------------------------

// A shared scene, as copied into assets/shared/ with its licence (the tests
// must pass from the project's own clone).
std::string sceneFile(const std::string& relative) {
    const fs::path root(BUNDLEBAKE_SOURCE_DIR);
    for (const fs::path& dir : {root / "assets" / "shared"}) {
        fs::path p = dir / relative;
        if (fs::exists(p)) return p.string();
    }
    return {};
}

// A fresh directory under the system temp dir, removed with its contents.
class TempDir {
public:
    TempDir() {
        const auto* info = testing::UnitTest::GetInstance()->current_test_info();
        path_ = fs::temp_directory_path() /
                ("bundlebake_scene_" + std::string(info->test_suite_name()) + "_" + info->name() + "_" +
                 std::to_string(std::hash<std::string>{}(std::to_string(reinterpret_cast<uintptr_t>(this)))));
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    std::string file(const std::string& name) const { return (path_ / name).string(); }

private:
    fs::path path_;
};

void writeBytes(const std::string& path, const void* data, size_t size) {
    std::ofstream out(path, std::ios::binary);
    out.write(static_cast<const char*>(data), std::streamsize(size));
    ASSERT_TRUE(out.good()) << path;
}

void writeText(const std::string& path, const std::string& text) { writeBytes(path, text.data(), text.size()); }

std::vector<unsigned char> readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string base64(const std::vector<unsigned char>& bytes) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < bytes.size(); i += 3) {
        uint32_t v = uint32_t(bytes[i]) << 16;
        if (i + 1 < bytes.size()) v |= uint32_t(bytes[i + 1]) << 8;
        if (i + 2 < bytes.size()) v |= bytes[i + 2];
        out += table[(v >> 18) & 63];
        out += table[(v >> 12) & 63];
        out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? table[v & 63] : '=';
    }
    return out;
}

// Builds a .gltf whose one buffer is a base64 data URI. Every bufferView is
// 4-byte aligned; the test fills everything but buffers/bufferViews/accessors.
class GltfBuilder {
public:
    GltfBuilder() { doc["asset"] = {{"version", "2.0"}, {"generator", "bundlebake scene_loader_test"}}; }

    int bufferView(const void* data, size_t size, size_t byteStride = 0) {
        while (bytes_.size() % 4 != 0) bytes_.push_back(0);
        json view = {{"buffer", 0}, {"byteOffset", bytes_.size()}, {"byteLength", size}};
        if (byteStride != 0) view["byteStride"] = byteStride;
        const auto* p = static_cast<const unsigned char*>(data);
        bytes_.insert(bytes_.end(), p, p + size);
        doc["bufferViews"].push_back(view);
        return int(doc["bufferViews"].size()) - 1;
    }
    template <class T>
    int bufferView(const std::vector<T>& v, size_t byteStride = 0) {
        return bufferView(v.data(), v.size() * sizeof(T), byteStride);
    }
    int accessor(json a) {
        doc["accessors"].push_back(std::move(a));
        return int(doc["accessors"].size()) - 1;
    }
    // A tightly packed accessor over a new bufferView.
    template <class T>
    int accessor(const std::vector<T>& v, int componentType, const std::string& type, size_t count,
                 bool normalized = false) {
        json a = {{"bufferView", bufferView(v)}, {"componentType", componentType}, {"type", type}, {"count", count}};
        if (normalized) a["normalized"] = true;
        return accessor(a);
    }
    int positions(const std::vector<float>& xyz) { return accessor(xyz, FLOAT, "VEC3", xyz.size() / 3); }

    std::string write(const std::string& path) {
        json d = doc;
        if (!bytes_.empty())
            d["buffers"] = json::array(
            {{{"byteLength", bytes_.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes_)}}});
        writeText(path, d.dump(1));
        return path;
    }

    json doc;

private:
    std::vector<unsigned char> bytes_;
};

// One mesh with one primitive on one root node.
json onePrimitiveScene(GltfBuilder& b, const std::string& meshName, json primitive) {
    b.doc["meshes"] = json::array({{{"name", meshName}, {"primitives", json::array({primitive})}}});
    b.doc["nodes"] = json::array({{{"name", meshName + "Node"}, {"mesh", 0}}});
    b.doc["scenes"] = json::array({{{"nodes", json::array({0})}}});
    b.doc["scene"] = 0;
    return b.doc;
}

void writePng(const std::string& path, int w, int h, int channels, const std::vector<unsigned char>& pixels) {
    ASSERT_EQ(pixels.size(), size_t(w) * size_t(h) * size_t(channels));
    auto png = encodePng(pixels.data(), w, h, channels);
    ASSERT_TRUE(png) << png.error();
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(png->data()), std::streamsize(png->size()));
}

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

const Instance* instanceNamed(const Scene& s, const std::string& name) {
    for (const Instance& i : s.instances)
        if (i.name == name) return &i;
    return nullptr;
}

const Material* materialNamed(const Scene& s, const std::string& name) {
    for (const Material& m : s.materials)
        if (m.name == name) return &m;
    return nullptr;
}

double totalArea(const Scene& s) {
    double a = 0.0;
    for (size_t i = 0; i < s.instances.size(); ++i) a += s.instanceArea(i);
    return a;
}

size_t primitiveCount(const Scene& s) {
    size_t n = 0;
    for (const Instance& i : s.instances) n += s.meshes[size_t(i.mesh)].primitives.size();
    return n;
}

#define EXPECT_VEC3_NEAR(actual, ex, ey, ez, tol)         \
    do {                                                  \
        const glm::vec3 v_ = (actual);                    \
        EXPECT_NEAR(v_.x, (ex), (tol)) << #actual " .x";  \
        EXPECT_NEAR(v_.y, (ey), (tol)) << #actual " .y";  \
        EXPECT_NEAR(v_.z, (ez), (tol)) << #actual " .z";  \
    } while (0)

// An error path: fails, one line, names the file, contains every key word.
void expectOneLineError(const Expected<Scene>& result, const std::string& path,
                        const std::vector<std::string>& keyWords) {
    ASSERT_FALSE(result) << "expected an error for " << path;
    const std::string& m = result.error();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(m.find('\r'), std::string::npos) << m;
    EXPECT_NE(m.find(path), std::string::npos) << "message does not name the file: " << m;
    for (const std::string& k : keyWords) EXPECT_NE(m.find(k), std::string::npos) << "missing '" << k << "' in: " << m;
}

// --- the four shared scenes (figures checked against the files with Python) ---

TEST(SceneLoaderShared, CornellBox) {
    const std::string path = sceneFile("cornell_box/CornellBox.glb");
    ASSERT_FALSE(path.empty()) << "CornellBox.glb not found in assets/shared";
    Expected<Scene> loaded = loadScene(path);
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;

    EXPECT_EQ(s.triangleCount(), 36u);
    EXPECT_EQ(s.instances.size(), 4u);
    EXPECT_EQ(primitiveCount(s), 6u);
    EXPECT_TRUE(s.allHaveUv1());
    EXPECT_EQ(s.report.primitivesWithoutUv1, 0u);
    EXPECT_EQ(s.report.skippedDegenerateTriangles, 0u);
    EXPECT_EQ(s.report.skippedNonTrianglePrimitives, 0u);
    EXPECT_EQ(s.report.primitivesWithoutMaterial, 0u);
    EXPECT_EQ(s.materials.size(), 5u);
    EXPECT_EQ(s.textures.size(), 0u);
    EXPECT_EQ(s.lights.size(), 0u);
    EXPECT_EQ(s.cameras.size(), 0u);

    // the light: 2 triangles, emissiveFactor 1 x KHR_materials_emissive_strength 100
    EXPECT_EQ(s.emitterTriangleCount(), 2u);
    const Material* light = materialNamed(s, "Emitter_Light_temp");
    ASSERT_NE(light, nullptr);
    EXPECT_VEC3_NEAR(light->emission, 100.0f, 100.0f, 100.0f, 1e-4f);
    EXPECT_VEC3_NEAR(light->albedo, 0.8f, 0.8f, 0.8f, 1e-6f);
    EXPECT_TRUE(light->doubleSided);
    const Material* red = materialNamed(s, "cbox.red.002");
    ASSERT_NE(red, nullptr);
    EXPECT_VEC3_NEAR(red->albedo, 0.5f, 0.0f, 0.0f, 1e-6f);

    // 130 x 105 light quad; millimetres
    const Instance* lightNode = instanceNamed(s, "Light");
    ASSERT_NE(lightNode, nullptr);
    EXPECT_NEAR(s.instanceArea(size_t(lightNode - s.instances.data())), 130.0 * 105.0, 0.01);
    EXPECT_NEAR(totalArea(s), 1985566.33, 0.1);
    EXPECT_VEC3_NEAR(s.bounds.min, -556.0f, 0.0f, -559.2f, 1e-3f);
    EXPECT_VEC3_NEAR(s.bounds.max, 0.0f, 548.8f, 0.0f, 1e-3f);
}

TEST(SceneLoaderShared, LivingRoomSkipsZeroAreaTriangles) {
    const std::string path = sceneFile("living_room/living_room.glb");
    ASSERT_FALSE(path.empty()) << "living_room.glb not found in assets/shared";
    Expected<Scene> loaded = loadScene(path);
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;

    // 5,088 triangles in the file, 3,537 of them with coincident positions
    EXPECT_EQ(s.report.skippedDegenerateTriangles, 3537u);
    EXPECT_EQ(s.triangleCount(), 5088u - 3537u);
    EXPECT_EQ(s.instances.size(), 2u);
    EXPECT_EQ(primitiveCount(s), 7u);
    EXPECT_EQ(s.materials.size(), 7u);
    EXPECT_FALSE(s.allHaveUv1());
    EXPECT_EQ(s.report.primitivesWithoutUv1, 7u);
    EXPECT_EQ(s.report.primitivesWithoutMaterial, 0u);
    EXPECT_EQ(s.emitterTriangleCount(), 0u);
    EXPECT_EQ(s.lights.size(), 0u);
    EXPECT_EQ(s.cameras.size(), 0u);
    const Material* grass = materialNamed(s, "grass");
    ASSERT_NE(grass, nullptr);
    EXPECT_VEC3_NEAR(grass->albedo, 0.12558205f, 0.18571436f, 0.08531257f, 1e-6f);
    EXPECT_NEAR(totalArea(s), 696.183, 0.01);
    EXPECT_VEC3_NEAR(s.bounds.min, -5.0f, -1.5f, -2.5f, 1e-4f);
    EXPECT_VEC3_NEAR(s.bounds.max, 5.0f, 4.0f, 12.0f, 1e-4f);

    // asking for light map UVs fails with a hint
    LoadOptions strict;
    strict.requireUv1 = true;
    expectOneLineError(loadScene(path, strict), path, {"TEXCOORD_1", "Cube"});
}

TEST(SceneLoaderShared, MixedLightingSunAndTextures) {
    const std::string path = sceneFile("mixed_lighting/MixedLightingExample.gltf");
    ASSERT_FALSE(path.empty()) << "MixedLightingExample.gltf not found in assets/shared";
    Expected<Scene> loaded = loadScene(path);
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;

    EXPECT_EQ(s.triangleCount(), 40898u);
    EXPECT_EQ(s.instances.size(), 6u);
    EXPECT_EQ(primitiveCount(s), 6u);
    EXPECT_TRUE(s.allHaveUv1());
    EXPECT_EQ(s.report.skippedDegenerateTriangles, 0u);
    // 8 materials in the file; the 2 that only KHR_materials_variants names are not used
    EXPECT_EQ(s.materials.size(), 6u);
    EXPECT_EQ(s.cameras.size(), 0u);

    // the sun: travels along (-0.392, -0.775, -0.495), 2049 lux, white
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].name, "Sun");
    EXPECT_VEC3_NEAR(s.lights[0].direction, -0.392f, -0.775f, -0.495f, 1e-3f);
    EXPECT_NEAR(glm::length(s.lights[0].direction), 1.0f, 1e-6f);
    EXPECT_VEC3_NEAR(s.lights[0].irradiance, 2049.0f, 2049.0f, 2049.0f, 1e-3f);

    // textures: fabric and label base colours, and the wood's base colour with
    // (1 - metallic) from its metallicRoughness texture multiplied in
    ASSERT_EQ(s.textures.size(), 3u);
    const Material* fabric = materialNamed(s, "fabric Mystere Mango Velvet");
    const Material* label = materialNamed(s, "label");
    const Material* wood = materialNamed(s, "wood Brown");
    const Material* metal = materialNamed(s, "metal");
    ASSERT_TRUE(fabric && label && wood && metal);
    ASSERT_GE(fabric->albedoTexture, 0);
    ASSERT_GE(label->albedoTexture, 0);
    ASSERT_GE(wood->albedoTexture, 0);
    EXPECT_EQ(s.textures[size_t(fabric->albedoTexture)].width, 512);
    EXPECT_EQ(s.textures[size_t(label->albedoTexture)].width, 1024);
    EXPECT_EQ(s.textures[size_t(label->albedoTexture)].height, 512);
    // the wood has metallicFactor 1 (default) but its texture's B channel is about 0:
    // it must not bake black
    glm::dvec3 mean(0.0);
    for (const glm::vec4& t : s.textures[size_t(wood->albedoTexture)].texels) mean += glm::dvec3(t);
    mean /= double(s.textures[size_t(wood->albedoTexture)].texels.size());
    EXPECT_GT(mean.x, 0.1);
    EXPECT_LT(mean.x, 0.3);
    // plain metal (metallicFactor 1, no texture) has no diffuse albedo
    EXPECT_VEC3_NEAR(metal->albedo, 0.0f, 0.0f, 0.0f, 0.0f);
    for (const Texture& t : s.textures) {
        ASSERT_EQ(t.texels.size(), size_t(t.width) * size_t(t.height));
        for (const glm::vec4& v : t.texels) {
            ASSERT_TRUE(v.x >= 0.0f && v.x <= 1.0f && v.y >= 0.0f && v.y <= 1.0f && v.z >= 0.0f && v.z <= 1.0f);
        }
    }
    EXPECT_NEAR(totalArea(s), 11.6558, 1e-3);
    EXPECT_VEC3_NEAR(s.bounds.min, -1.553547f, -0.00007f, -1.553547f, 1e-5f);
    EXPECT_VEC3_NEAR(s.bounds.max, 1.553547f, 0.686177f, 1.553547f, 1e-5f);
}

TEST(SceneLoaderShared, Zdm2UsesDefaultMaterial) {
    const std::string path = sceneFile("zdm2/zdm2.glb");
    ASSERT_FALSE(path.empty()) << "zdm2.glb not found in assets/shared";
    LoadOptions options;
    options.defaultAlbedo = glm::vec3(0.5f);
    const int warningsBefore = warningCount();
    testing::internal::CaptureStderr();
    Expected<Scene> loaded = loadScene(path, options);
    const std::string log = testing::internal::GetCapturedStderr();
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;

    // 58,772 triangles in the file; 1,134 have exactly zero area (collinear or coincident)
    EXPECT_EQ(s.triangleCount(), 57638u);
    EXPECT_EQ(s.report.skippedDegenerateTriangles, 1134u);
    EXPECT_EQ(s.triangleCount() + s.report.skippedDegenerateTriangles, 58772u);
    EXPECT_EQ(s.instances.size(), 1u);

    // no materials at all: one bundlebake default, and one warning that says why
    ASSERT_EQ(s.materials.size(), 1u);
    EXPECT_TRUE(s.materials[0].isDefault);
    EXPECT_VEC3_NEAR(s.materials[0].albedo, 0.5f, 0.5f, 0.5f, 0.0f);
    EXPECT_EQ(s.report.primitivesWithoutMaterial, 1u);
    EXPECT_GE(warningCount() - warningsBefore, 1);
    EXPECT_NE(log.find("no material"), std::string::npos) << log;
    EXPECT_NE(log.find("metallic"), std::string::npos) << log;

    EXPECT_FALSE(s.allHaveUv1());
    EXPECT_EQ(s.report.primitivesWithoutUv1, 1u);
    EXPECT_EQ(s.textures.size(), 0u);
    EXPECT_EQ(s.lights.size(), 0u);
    EXPECT_EQ(s.cameras.size(), 0u);
    EXPECT_NEAR(totalArea(s), 29349.37, 0.1);
    EXPECT_VEC3_NEAR(s.bounds.min, -33.87949f, -11.96834f, -29.29027f, 1e-3f);
    EXPECT_VEC3_NEAR(s.bounds.max, 43.32052f, 23.98378f, 30.30972f, 1e-3f);
    for (const Primitive& p : s.meshes[0].primitives)
        for (const glm::vec3& n : p.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);

    LoadOptions strict;
    strict.requireUv1 = true;
    expectOneLineError(loadScene(path, strict), path, {"TEXCOORD_1", "zdm2"});
}

// --- a hand-built glTF, rule by rule ----------------------------------------

// Root (translate 10,0,0)
//   Child (rotate 90 deg about Z, scale 2, mesh Quad, extras.texelDensity 32)
//     Grandchild (matrix: translate 0,0,5; mesh Tri)
//   Sun (directional light, rotated -90 deg about X)
//   Bulb (point light)
// Camera (perspective, at 0,1,5)
// NoMat (translate -1,-1,-1, mesh NoMat)
// Unused (not in the scene, mesh Tri)
std::string writeTinyScene(const TempDir& dir) {
    GltfBuilder b;
    const float h = std::sqrt(0.5f);
    // Tri: non-indexed, no normals
    const int triPos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    // Quad: positions and unnormalized normals interleaved (byteStride 24),
    // vertex 4 used only by a zero-area triangle
    std::vector<float> interleaved;
    const float quadPos[5][3] = {{0, 0, 0}, {2, 0, 0}, {2, 2, 0}, {0, 2, 0}, {1, 1, 0}};
    for (const auto& p : quadPos) interleaved.insert(interleaved.end(), {p[0], p[1], p[2], 0.0f, 0.0f, 2.0f});
    const int quadView = b.bufferView(interleaved, 24);
    const int quadPosAcc = b.accessor({{"bufferView", quadView}, {"componentType", FLOAT}, {"type", "VEC3"}, {"count", 5}});
    const int quadNrmAcc = b.accessor(
        {{"bufferView", quadView}, {"byteOffset", 12}, {"componentType", FLOAT}, {"type", "VEC3"}, {"count", 5}});
    // TEXCOORD_1 as normalized unsigned shorts
    const int quadUv1 = b.accessor(std::vector<uint16_t>{0, 0, 65535, 0, 65535, 65535, 0, 65535, 32768, 32768},
                                   UNSIGNED_SHORT, "VEC2", 5, true);
    // two triangles, one with a repeated index, one with zero area
    const int quadIdx = b.accessor(std::vector<uint16_t>{0, 1, 2, 0, 2, 3, 0, 0, 1, 0, 2, 4}, UNSIGNED_SHORT,
                                   "SCALAR", 12);
    // NoMat: a sparse accessor without bufferView (zeros) overriding vertices 1 and 2
    const int sparseIdx = b.bufferView(std::vector<uint8_t>{1, 2});
    const int sparseVal = b.bufferView(std::vector<float>{3, 0, 0, 0, 4, 0});
    const int noMatPos = b.accessor({{"componentType", FLOAT},
                                     {"type", "VEC3"},
                                     {"count", 3},
                                     {"sparse",
                                      {{"count", 2},
                                       {"indices", {{"bufferView", sparseIdx}, {"componentType", UNSIGNED_BYTE}}},
                                       {"values", {{"bufferView", sparseVal}}}}}});
    const int noMatIdx = b.accessor(std::vector<uint8_t>{0, 1, 2}, UNSIGNED_BYTE, "SCALAR", 3);

    b.doc["materials"] = json::array(
        {{{"name", "Half"}, {"pbrMetallicRoughness", {{"baseColorFactor", {0.8, 0.6, 0.4, 1.0}}, {"metallicFactor", 0.5}}}},
         {{"name", "Glow"},
          {"doubleSided", true},
          {"emissiveFactor", {1.0, 0.5, 0.25}},
          {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}},
          {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}}});
    b.doc["meshes"] = json::array(
        {{{"name", "Tri"},
          {"primitives",
           {{{"attributes", {{"POSITION", triPos}}}, {"material", 0}},
            {{"attributes", {{"POSITION", triPos}}}, {"material", 0}, {"mode", MODE_LINES}}}}},
         {{"name", "Quad"},
          {"primitives",
           {{{"attributes", {{"POSITION", quadPosAcc}, {"NORMAL", quadNrmAcc}, {"TEXCOORD_1", quadUv1}}},
             {"indices", quadIdx},
             {"material", 1}}}}},
         {{"name", "NoMat"}, {"primitives", {{{"attributes", {{"POSITION", noMatPos}}}, {"indices", noMatIdx}}}}}});
    b.doc["nodes"] = json::array(
        {{{"name", "Root"}, {"translation", {10, 0, 0}}, {"children", {1, 3, 7}}},
         {{"name", "Child"},
          {"rotation", {0, 0, h, h}},
          {"scale", {2, 2, 2}},
          {"mesh", 1},
          {"children", json::array({2})},
          {"extras", {{"texelDensity", 32}}}},
         {{"name", "Grandchild"}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 5, 1}}, {"mesh", 0}},
         {{"name", "Sun"}, {"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
         {{"name", "CameraNode"}, {"camera", 0}, {"translation", {0, 1, 5}}},
         {{"name", "NoMat"}, {"mesh", 2}, {"translation", {-1, -1, -1}}},
         {{"name", "Unused"}, {"mesh", 0}},
         {{"name", "Bulb"}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}}});
    b.doc["cameras"] = json::array(
        {{{"name", "Cam"},
          {"type", "perspective"},
          {"perspective", {{"yfov", 0.7}, {"znear", 0.1}, {"zfar", 100.0}, {"aspectRatio", 1.5}}}}});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_emissive_strength"};
    b.doc["extensions"] = {
        {"KHR_lights_punctual",
         {{"lights",
           {{{"name", "Sun"}, {"type", "directional"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 8.0}},
            {{"name", "Bulb"}, {"type", "point"}, {"intensity", 100.0}}}}}}};
    b.doc["scenes"] = json::array({{{"nodes", {0, 4, 5}}}});
    b.doc["scene"] = 0;
    return b.write(dir.file("tiny.gltf"));
}

TEST(SceneLoader, TinySceneFollowsEveryRule) {
    TempDir dir;
    const std::string path = writeTinyScene(dir);
    LoadOptions options;
    options.defaultAlbedo = glm::vec3(0.25f, 0.5f, 0.75f);
    testing::internal::CaptureStderr();
    Expected<Scene> loaded = loadScene(path, options);
    const std::string log = testing::internal::GetCapturedStderr();
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;
    EXPECT_EQ(s.path, path);

    // instances: the three mesh nodes of the default scene, not "Unused"
    ASSERT_EQ(s.instances.size(), 3u);
    const Instance* child = instanceNamed(s, "Child");
    const Instance* grandchild = instanceNamed(s, "Grandchild");
    const Instance* noMat = instanceNamed(s, "NoMat");
    ASSERT_TRUE(child && grandchild && noMat);
    EXPECT_EQ(instanceNamed(s, "Unused"), nullptr);

    // transforms composed down the hierarchy: T(10,0,0) Rz(90) S(2) [T(0,0,5)]
    EXPECT_VEC3_NEAR(glm::vec3(child->worldFromObject * glm::vec4(2, 2, 0, 1)), 6.0f, 4.0f, 0.0f, 1e-5f);
    EXPECT_VEC3_NEAR(glm::vec3(grandchild->worldFromObject * glm::vec4(1, 0, 0, 1)), 10.0f, 2.0f, 10.0f, 1e-5f);
    EXPECT_VEC3_NEAR(glm::vec3(noMat->worldFromObject * glm::vec4(0, 4, 0, 1)), -1.0f, 3.0f, -1.0f, 1e-6f);
    EXPECT_EQ(child->node, 1);
    EXPECT_EQ(grandchild->node, 2);
    // extras.texelDensity, inherited by the subtree
    EXPECT_EQ(child->texelDensity, 32.0f);
    EXPECT_EQ(grandchild->texelDensity, 32.0f);
    EXPECT_EQ(noMat->texelDensity, 0.0f);

    // Tri: non-indexed, flat normals computed, the LINES primitive skipped
    const Mesh& tri = s.meshes[size_t(grandchild->mesh)];
    EXPECT_EQ(tri.name, "Tri");
    ASSERT_EQ(tri.primitives.size(), 1u);
    const Primitive& triP = tri.primitives[0];
    EXPECT_EQ(triP.indices, (std::vector<uint32_t>{0, 1, 2}));
    ASSERT_EQ(triP.normals.size(), 3u);
    for (const glm::vec3& n : triP.normals) EXPECT_VEC3_NEAR(n, 0.0f, 0.0f, 1.0f, 1e-6f);
    EXPECT_TRUE(triP.uv1.empty());

    // Quad: interleaved attributes, normals normalized, two degenerate triangles
    // removed and the vertex only they used dropped
    const Mesh& quad = s.meshes[size_t(child->mesh)];
    ASSERT_EQ(quad.primitives.size(), 1u);
    const Primitive& quadP = quad.primitives[0];
    EXPECT_EQ(quadP.triangleCount(), 2u);
    EXPECT_EQ(quadP.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
    ASSERT_EQ(quadP.positions.size(), 4u);
    EXPECT_VEC3_NEAR(quadP.positions[2], 2.0f, 2.0f, 0.0f, 0.0f);
    for (const glm::vec3& n : quadP.normals) EXPECT_VEC3_NEAR(n, 0.0f, 0.0f, 1.0f, 1e-6f);
    ASSERT_EQ(quadP.uv1.size(), 4u);
    EXPECT_EQ(quadP.uv1[0], glm::vec2(0.0f, 0.0f));
    EXPECT_EQ(quadP.uv1[2], glm::vec2(1.0f, 1.0f));  // normalized 65535
    EXPECT_EQ(quadP.uv1[3], glm::vec2(0.0f, 1.0f));

    // NoMat: sparse positions over zeros
    const Primitive& noMatP = s.meshes[size_t(noMat->mesh)].primitives[0];
    ASSERT_EQ(noMatP.positions.size(), 3u);
    EXPECT_VEC3_NEAR(noMatP.positions[0], 0.0f, 0.0f, 0.0f, 0.0f);
    EXPECT_VEC3_NEAR(noMatP.positions[1], 3.0f, 0.0f, 0.0f, 0.0f);
    EXPECT_VEC3_NEAR(noMatP.positions[2], 0.0f, 4.0f, 0.0f, 0.0f);

    // materials: metallic 0.5 halves the albedo; emissive strength scales emission;
    // no material -> bundlebake default with the caller's albedo, and one warning
    ASSERT_EQ(s.materials.size(), 3u);
    const Material& half = s.materials[size_t(triP.material)];
    EXPECT_EQ(half.name, "Half");
    EXPECT_VEC3_NEAR(half.albedo, 0.4f, 0.3f, 0.2f, 1e-6f);
    EXPECT_VEC3_NEAR(half.emission, 0.0f, 0.0f, 0.0f, 0.0f);
    EXPECT_FALSE(half.doubleSided);
    EXPECT_FALSE(half.isDefault);
    const Material& glow = s.materials[size_t(quadP.material)];
    EXPECT_EQ(glow.name, "Glow");
    EXPECT_VEC3_NEAR(glow.albedo, 1.0f, 1.0f, 1.0f, 1e-6f);
    EXPECT_VEC3_NEAR(glow.emission, 4.0f, 2.0f, 1.0f, 1e-6f);
    EXPECT_TRUE(glow.doubleSided);
    const Material& fallback = s.materials[size_t(noMatP.material)];
    EXPECT_TRUE(fallback.isDefault);
    EXPECT_VEC3_NEAR(fallback.albedo, 0.25f, 0.5f, 0.75f, 0.0f);
    EXPECT_NE(log.find("1 primitive(s) have no material"), std::string::npos) << log;

    // counts
    EXPECT_EQ(s.triangleCount(), 4u);
    EXPECT_EQ(s.emitterTriangleCount(), 2u);
    EXPECT_FALSE(s.allHaveUv1());
    EXPECT_EQ(s.report.skippedNonTrianglePrimitives, 1u);
    EXPECT_EQ(s.report.skippedDegenerateTriangles, 2u);
    EXPECT_EQ(s.report.primitivesWithoutMaterial, 1u);
    EXPECT_EQ(s.report.primitivesWithoutUv1, 2u);
    EXPECT_NE(log.find("skipped 1 point/line primitive"), std::string::npos) << log;
    EXPECT_NE(log.find("skipped 2 degenerate triangle"), std::string::npos) << log;

    // world-space areas: 2x2 quad scaled by 2, unit right triangle scaled by 2, 3-4-5 triangle
    EXPECT_NEAR(s.instanceArea(size_t(child - s.instances.data())), 16.0, 1e-5);
    EXPECT_NEAR(s.instanceArea(size_t(grandchild - s.instances.data())), 2.0, 1e-5);
    EXPECT_NEAR(s.instanceArea(size_t(noMat - s.instances.data())), 6.0, 1e-6);
    EXPECT_VEC3_NEAR(s.bounds.min, -1.0f, -1.0f, -1.0f, 1e-5f);
    EXPECT_VEC3_NEAR(s.bounds.max, 10.0f, 4.0f, 10.0f, 1e-5f);

    // lights: the sun travels along world -Y; the point light sits at its node's world origin
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].name, "Sun");
    EXPECT_VEC3_NEAR(s.lights[0].direction, 0.0f, -1.0f, 0.0f, 1e-6f);
    EXPECT_VEC3_NEAR(s.lights[0].irradiance, 8.0f, 4.0f, 2.0f, 1e-6f);
    ASSERT_EQ(s.punctualLights.size(), 1u);
    EXPECT_EQ(s.punctualLights[0].name, "Bulb");
    EXPECT_EQ(s.punctualLights[0].type, PunctualLight::Type::Point);
    EXPECT_VEC3_NEAR(glm::vec3(s.punctualLights[0].position), 10.0f, 0.0f, 0.0f, 0.0f);
    EXPECT_VEC3_NEAR(s.punctualLights[0].intensity, 100.0f, 100.0f, 100.0f, 0.0f);
    EXPECT_EQ(s.punctualLights[0].range, 0.0f);  // undefined: infinite
    EXPECT_EQ(log.find("light(s) of an unknown type"), std::string::npos) << log;

    // camera
    ASSERT_EQ(s.cameras.size(), 1u);
    const Camera& cam = s.cameras[0];
    EXPECT_EQ(cam.name, "Cam");
    EXPECT_TRUE(cam.perspective);
    EXPECT_FLOAT_EQ(cam.yfov, 0.7f);
    EXPECT_FLOAT_EQ(cam.aspect, 1.5f);
    EXPECT_FLOAT_EQ(cam.znear, 0.1f);
    EXPECT_FLOAT_EQ(cam.zfar, 100.0f);
    EXPECT_VEC3_NEAR(glm::vec3(cam.worldFromCamera[3]), 0.0f, 1.0f, 5.0f, 0.0f);
}

TEST(SceneLoader, GlbOfTheSameSceneLoadsTheSame) {
    // the same document as a .glb with a BIN chunk instead of a data URI
    TempDir dir;
    const std::string gltfPath = writeTinyScene(dir);
    json doc = json::parse(readBytes(gltfPath));
    std::string uri = doc["buffers"][0]["uri"];
    // decode the data URI back to bytes
    std::string b64 = uri.substr(uri.find(',') + 1);
    std::vector<unsigned char> bin;
    uint32_t acc = 0;
    int bits = 0;
    for (char c : b64) {
        const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        const char* at = std::strchr(table, c);
        if (c == '=' || !at) break;
        acc = (acc << 6) | uint32_t(at - table);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            bin.push_back(static_cast<unsigned char>((acc >> bits) & 0xff));
        }
    }
    doc["buffers"][0].erase("uri");
    std::string text = doc.dump();
    while (text.size() % 4 != 0) text += ' ';
    while (bin.size() % 4 != 0) bin.push_back(0);
    std::vector<unsigned char> glb;
    auto put32 = [&](uint32_t v) { for (int i = 0; i < 4; ++i) glb.push_back(static_cast<unsigned char>(v >> (8 * i))); };
    put32(0x46546C67);  // "glTF"
    put32(2);
    put32(uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    put32(uint32_t(text.size()));
    put32(0x4E4F534A);  // JSON
    glb.insert(glb.end(), text.begin(), text.end());
    put32(uint32_t(bin.size()));
    put32(0x004E4942);  // BIN
    glb.insert(glb.end(), bin.begin(), bin.end());
    const std::string glbPath = dir.file("tiny.glb");
    writeBytes(glbPath, glb.data(), glb.size());

    Expected<Scene> fromGltf = loadScene(gltfPath);
    Expected<Scene> fromGlb = loadScene(glbPath);
    ASSERT_TRUE(fromGltf) << fromGltf.error();
    ASSERT_TRUE(fromGlb) << fromGlb.error();
    EXPECT_EQ(fromGlb->triangleCount(), 4u);
    EXPECT_EQ(fromGlb->instances.size(), fromGltf->instances.size());
    EXPECT_EQ(fromGlb->report.skippedDegenerateTriangles, 2u);
    EXPECT_VEC3_NEAR(fromGlb->bounds.max, 10.0f, 4.0f, 10.0f, 1e-5f);
}

TEST(SceneLoader, StripsAndFansBecomeTriangleLists) {
    // unit square as a strip and as a fan, both counter-clockwise seen from +Z:
    // every flat normal must be +Z (the odd strip triangle's winding is flipped back)
    TempDir dir;
    GltfBuilder b;
    const int strip = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
    const int fan = b.positions({0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});
    b.doc["meshes"] = json::array(
        {{{"name", "Strips"},
          {"primitives",
           {{{"attributes", {{"POSITION", strip}}}, {"mode", MODE_TRIANGLE_STRIP}},
            {{"attributes", {{"POSITION", fan}}}, {"mode", MODE_TRIANGLE_FAN}}}}}});
    b.doc["nodes"] = json::array({{{"mesh", 0}}});  // no scenes: every root node
    const std::string path = b.write(dir.file("strips.gltf"));
    Expected<Scene> loaded = loadScene(path);
    ASSERT_TRUE(loaded) << loaded.error();
    ASSERT_EQ(loaded->instances.size(), 1u);
    EXPECT_EQ(loaded->instances[0].name, "node 0");
    EXPECT_EQ(loaded->triangleCount(), 4u);
    for (const Primitive& p : loaded->meshes[0].primitives) {
        EXPECT_EQ(p.triangleCount(), 2u);
        for (const glm::vec3& n : p.normals) EXPECT_VEC3_NEAR(n, 0.0f, 0.0f, 1.0f, 1e-6f);
    }
    EXPECT_NEAR(loaded->instanceArea(0), 2.0, 1e-6);
}

TEST(SceneLoader, TexturesDecodeToLinearAndBrokenOnesAreRefused) {
    TempDir dir;
    // 2x1 base colour: sRGB 128 grey and white; 2x1 metallicRoughness: metallic (B) 1 and 0
    writePng(dir.file("base.png"), 2, 1, 3, {128, 128, 128, 255, 255, 255});
    writePng(dir.file("mr.png"), 2, 1, 3, {0, 128, 255, 0, 128, 0});
    writeText(dir.file("broken.png"), "this is not a PNG file");
    GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int uv = b.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, FLOAT, "VEC2", 3);
    // TEXCOORD_1 as normalized signed bytes (127 -> 1)
    const int uv1 = b.accessor(std::vector<int8_t>{0, 0, 127, 0, 0, 127}, BYTE, "VEC2", 3, true);
    writePng(dir.file("glow.png"), 1, 1, 3, {255, 255, 255});
    b.doc["images"] = json::array({{{"uri", "base.png"}}, {{"uri", "mr.png"}}, {{"uri", "glow.png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}, {{"source", 1}}, {{"source", 2}}});
    b.doc["materials"] = json::array(
        {{{"name", "Textured"},
          {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}, {"metallicFactor", 0.0}}},
          {"emissiveFactor", {1.0, 1.0, 1.0}},
          {"emissiveTexture", {{"index", 2}}}},
         {{"name", "Metal"},
          {"pbrMetallicRoughness",
           {{"baseColorTexture", {{"index", 0}}}, {"metallicRoughnessTexture", {{"index", 1}}}}}}});
    b.doc["meshes"] = json::array(
        {{{"name", "A"},
          {"primitives", {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}, {"TEXCOORD_1", uv1}}}, {"material", 0}}}}},
         {{"name", "B"},
          {"primitives", {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}, {"TEXCOORD_1", uv1}}}, {"material", 1}}}}}});
    b.doc["nodes"] = json::array({{{"mesh", 0}}, {{"mesh", 1}}});
    b.doc["scenes"] = json::array({{{"nodes", {0, 1}}}});
    const std::string path = b.write(dir.file("textured.gltf"));

    testing::internal::CaptureStderr();
    Expected<Scene> loaded = loadScene(path);
    const std::string log = testing::internal::GetCapturedStderr();
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;
    EXPECT_TRUE(s.allHaveUv1());
    EXPECT_EQ(s.meshes[0].primitives[0].uv1[1], glm::vec2(1.0f, 0.0f));

    const Material* textured = materialNamed(s, "Textured");
    const Material* metal = materialNamed(s, "Metal");
    ASSERT_TRUE(textured && metal);
    // base colour decoded from sRGB to linear
    ASSERT_GE(textured->albedoTexture, 0);
    const Texture& base = s.textures[size_t(textured->albedoTexture)];
    ASSERT_EQ(base.width, 2);
    ASSERT_EQ(base.height, 1);
    EXPECT_NEAR(base.texels[0].r, srgbToLinear(128.0f / 255.0f), 1e-6f);
    EXPECT_NEAR(base.texels[0].r, 0.2158605f, 1e-6f);
    EXPECT_NEAR(base.texels[1].g, 1.0f, 1e-6f);
    EXPECT_EQ(base.texels[0].a, 1.0f);
    EXPECT_GE(textured->emissionTexture, 0);
    EXPECT_VEC3_NEAR(textured->emission, 1.0f, 1.0f, 1.0f, 0.0f);
    // metallic from the texture's B channel: texel 0 fully metallic (black), texel 1 dielectric
    ASSERT_GE(metal->albedoTexture, 0);
    EXPECT_NE(metal->albedoTexture, textured->albedoTexture);
    EXPECT_VEC3_NEAR(metal->albedo, 1.0f, 1.0f, 1.0f, 0.0f);
    const Texture& derived = s.textures[size_t(metal->albedoTexture)];
    ASSERT_EQ(derived.texels.size(), 2u);
    EXPECT_NEAR(derived.texels[0].r, 0.0f, 1e-6f);
    EXPECT_NEAR(derived.texels[1].r, 1.0f, 1e-6f);
    EXPECT_EQ(s.textures.size(), 3u);

    // a used image that is not an image, or is missing: one error naming the
    // material, the slot and the image (a bake without it would be wrong)
    b.doc["images"][2] = {{"uri", "broken.png"}};
    const std::string broken = b.write(dir.file("broken.gltf"));
    expectOneLineError(loadScene(broken), broken, {"'Textured' emissiveTexture", "broken.png", "could not be decoded"});
    b.doc["images"][2] = {{"uri", "missing.png"}};
    const std::string missing = b.write(dir.file("missing.gltf"));
    testing::internal::CaptureStderr();
    const Expected<Scene> missingLoaded = loadScene(missing);
    testing::internal::GetCapturedStderr();
    expectOneLineError(missingLoaded, missing, {"missing.png", "could not be read"});
    // unused, it is never read: no error
    b.doc["materials"][0].erase("emissiveTexture");
    const std::string unused = b.write(dir.file("unused.gltf"));
    testing::internal::CaptureStderr();
    EXPECT_TRUE(loadScene(unused));
    testing::internal::GetCapturedStderr();
}

TEST(SceneLoader, TextureTransformIsAppliedToUv0) {
    TempDir dir;
    writePng(dir.file("base.png"), 1, 1, 3, {255, 255, 255});
    GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    const int uv = b.accessor(std::vector<float>{0, 0, 1, 0, 0, 1}, FLOAT, "VEC2", 3);
    b.doc["images"] = json::array({{{"uri", "base.png"}}});
    b.doc["textures"] = json::array({{{"source", 0}}});
    // the extension's own example: offset (0,1), rotation 90 deg, scale 0.5 -> the
    // lower left quadrant, rotated: uv (0,0) -> (0,1), (1,0) -> (0,0.5), (0,1) -> (0.5,1)
    json transform = {{"offset", {0.0, 1.0}}, {"rotation", 1.57079632679}, {"scale", {0.5, 0.5}}};
    json textureInfo = {{"index", 0}, {"extensions", {{"KHR_texture_transform", transform}}}};
    json pbr = {{"metallicFactor", 0.0}, {"baseColorTexture", textureInfo}};
    b.doc["materials"] = json::array({json{{"pbrMetallicRoughness", pbr}}});
    onePrimitiveScene(b, "Transformed", {{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"material", 0}});
    const std::string path = b.write(dir.file("transform.gltf"));
    Expected<Scene> loaded = loadScene(path);
    ASSERT_TRUE(loaded) << loaded.error();
    const std::vector<glm::vec2>& uv0 = loaded->meshes[0].primitives[0].uv0;
    ASSERT_EQ(uv0.size(), 3u);
    EXPECT_NEAR(uv0[0].x, 0.0f, 1e-6f);
    EXPECT_NEAR(uv0[0].y, 1.0f, 1e-6f);
    EXPECT_NEAR(uv0[1].x, 0.0f, 1e-6f);
    EXPECT_NEAR(uv0[1].y, 0.5f, 1e-6f);
    EXPECT_NEAR(uv0[2].x, 0.5f, 1e-6f);
    EXPECT_NEAR(uv0[2].y, 1.0f, 1e-6f);
}

TEST(SceneMembers, InstancedCountsAndWorldAreas) {
    // one unit quad (area 1) instanced twice, once scaled by 3; one emissive material
    Scene s;
    s.materials.resize(2);
    s.materials[1].emission = glm::vec3(0.0f, 0.0f, 2.0f);
    Primitive quad;
    quad.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    quad.normals.assign(4, glm::vec3(0, 0, 1));
    quad.indices = {0, 1, 2, 0, 2, 3};
    quad.material = 1;
    Primitive tri = quad;
    tri.indices = {0, 1, 2};
    tri.material = 0;
    tri.uv1.assign(4, glm::vec2(0.0f));
    s.meshes.push_back(Mesh{"m", {quad, tri}});
    Instance a;
    a.mesh = 0;
    Instance b = a;
    b.worldFromObject = glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(5, 0, 0)), glm::vec3(3.0f));
    s.instances = {a, b};
    EXPECT_EQ(s.triangleCount(), 6u);
    EXPECT_EQ(s.emitterTriangleCount(), 4u);
    EXPECT_FALSE(s.allHaveUv1());
    EXPECT_NEAR(s.instanceArea(0), 1.5, 1e-12);
    EXPECT_NEAR(s.instanceArea(1), 13.5, 1e-5);
    s.meshes[0].primitives[0].uv1.assign(4, glm::vec2(0.0f));
    EXPECT_TRUE(s.allHaveUv1());
}

// --- reject tests: one line each, naming the file ----------------------------

TEST(SceneLoaderReject, MissingFile) {
    TempDir dir;
    const std::string path = dir.file("does_not_exist.gltf");
    expectOneLineError(loadScene(path), path, {"not found"});
}

TEST(SceneLoaderReject, Directory) {
    TempDir dir;
    const std::string path = dir.file("");
    expectOneLineError(loadScene(path), path, {"directory"});
}

TEST(SceneLoaderReject, TruncatedJson) {
    TempDir dir;
    const std::string path = writeTinyScene(dir);
    std::string text(reinterpret_cast<const char*>(readBytes(path).data()), 400);
    const std::string truncated = dir.file("truncated.gltf");
    writeText(truncated, text);
    expectOneLineError(loadScene(truncated), truncated, {"not a valid glTF file", "parse error"});

    const std::string garbage = dir.file("garbage.gltf");
    writeText(garbage, "this is not json at all\n{{{\n");
    expectOneLineError(loadScene(garbage), garbage, {"not a valid glTF file"});

    const std::string empty = dir.file("empty.gltf");
    writeText(empty, "");
    expectOneLineError(loadScene(empty), empty, {"not a valid glTF file"});
}

TEST(SceneLoaderReject, TruncatedGlb) {
    const std::string cornell = sceneFile("cornell_box/CornellBox.glb");
    ASSERT_FALSE(cornell.empty());
    const std::vector<unsigned char> bytes = readBytes(cornell);
    ASSERT_EQ(bytes.size(), 10212u);
    TempDir dir;
    for (size_t size : {size_t(12), size_t(100), bytes.size() / 2, bytes.size() - 4}) {
        const std::string path = dir.file("truncated_" + std::to_string(size) + ".glb");
        writeBytes(path, bytes.data(), size);
        expectOneLineError(loadScene(path), path, {"not a valid glTF binary"});
        EXPECT_NE(loadScene(path).error().find("truncated"), std::string::npos);  // header length > file size
    }
}

TEST(SceneLoaderReject, CorruptGlbChunk) {
    const std::string cornell = sceneFile("cornell_box/CornellBox.glb");
    ASSERT_FALSE(cornell.empty());
    std::vector<unsigned char> bytes = readBytes(cornell);
    ASSERT_GE(bytes.size(), 20u);
    const uint32_t hugeJsonChunk = 0x00ffffffu;  // the JSON chunk claims more than the file holds
    std::memcpy(bytes.data() + 12, &hugeJsonChunk, 4);
    TempDir dir;
    const std::string path = dir.file("corrupt.glb");
    writeBytes(path, bytes.data(), bytes.size());
    expectOneLineError(loadScene(path), path, {"not a valid glTF binary", "Invalid glTF binary"});
}

TEST(SceneLoaderReject, MissingExternalBuffer) {
    TempDir dir;
    GltfBuilder b;
    b.doc["buffers"] = json::array({{{"byteLength", 36}, {"uri", "missing.bin"}}});
    b.doc["bufferViews"] = json::array({{{"buffer", 0}, {"byteLength", 36}}});
    b.doc["accessors"] = json::array({{{"bufferView", 0}, {"componentType", FLOAT}, {"type", "VEC3"}, {"count", 3}}});
    onePrimitiveScene(b, "Tri", {{"attributes", {{"POSITION", 0}}}});
    const std::string path = dir.file("external.gltf");
    writeText(path, b.doc.dump());  // b.write() would replace the buffers
    expectOneLineError(loadScene(path), path, {"not a valid glTF file", "missing.bin"});
}

TEST(SceneLoaderReject, NanPositionNamesTheMesh) {
    TempDir dir;
    GltfBuilder b;
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const int pos = b.positions({0, 0, 0, 1, nan, 0, 0, 1, 0});
    onePrimitiveScene(b, "Broken", {{"attributes", {{"POSITION", pos}}}});
    const std::string path = b.write(dir.file("nan.gltf"));
    expectOneLineError(loadScene(path), path, {"mesh 'Broken'", "NaN"});

    GltfBuilder inf;
    const int infPos = inf.positions({0, 0, 0, 1, 0, 0, 0, std::numeric_limits<float>::infinity(), 0});
    onePrimitiveScene(inf, "Infinite", {{"attributes", {{"POSITION", infPos}}}});
    const std::string infPath = inf.write(dir.file("inf.gltf"));
    expectOneLineError(loadScene(infPath), infPath, {"mesh 'Infinite'", "infinite"});
}

TEST(SceneLoaderReject, RequireUv1WithoutTexcoord1) {
    TempDir dir;
    GltfBuilder b;
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    onePrimitiveScene(b, "NoLightmapUvs", {{"attributes", {{"POSITION", pos}}}});
    const std::string path = b.write(dir.file("nouv1.gltf"));
    // loads without the requirement...
    Expected<Scene> relaxed = loadScene(path);
    ASSERT_TRUE(relaxed) << relaxed.error();
    EXPECT_EQ(relaxed->report.primitivesWithoutUv1, 1u);
    // ...and fails with a hint with it
    LoadOptions strict;
    strict.requireUv1 = true;
    expectOneLineError(loadScene(path, strict), path, {"TEXCOORD_1", "NoLightmapUvs", "DCC tool"});
}

TEST(SceneLoaderReject, NothingToBake) {
    TempDir dir;
    // only a LINES primitive
    GltfBuilder lines;
    const int pos = lines.positions({0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0});
    onePrimitiveScene(lines, "Wire", {{"attributes", {{"POSITION", pos}}}, {"mode", MODE_LINES}});
    const std::string linesPath = lines.write(dir.file("lines.gltf"));
    expectOneLineError(loadScene(linesPath), linesPath, {"no triangles", "1 point/line primitive"});

    // only degenerate triangles
    GltfBuilder flat;
    const int flatPos = flat.positions({0, 0, 0, 1, 0, 0, 2, 0, 0});
    onePrimitiveScene(flat, "Sliver", {{"attributes", {{"POSITION", flatPos}}}});
    const std::string flatPath = flat.write(dir.file("degenerate.gltf"));
    expectOneLineError(loadScene(flatPath), flatPath, {"no triangles", "1 degenerate triangle"});

    // no nodes at all
    GltfBuilder none;
    const std::string nonePath = none.write(dir.file("empty_scene.gltf"));
    expectOneLineError(loadScene(nonePath), nonePath, {"no triangles"});
}

TEST(SceneLoaderReject, MalformedReferencesAndRanges) {
    TempDir dir;
    {
        // an index past the vertex count
        GltfBuilder b;
        const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
        const int idx = b.accessor(std::vector<uint16_t>{0, 1, 7, 0}, UNSIGNED_SHORT, "SCALAR", 3);
        onePrimitiveScene(b, "BadIndex", {{"attributes", {{"POSITION", pos}}}, {"indices", idx}});
        const std::string path = b.write(dir.file("bad_index.gltf"));
        expectOneLineError(loadScene(path), path, {"mesh 'BadIndex'", "index 7 is out of range"});
    }
    {
        // an accessor that reads past its bufferView
        GltfBuilder b;
        const int view = b.bufferView(std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
        const int pos = b.accessor({{"bufferView", view}, {"componentType", FLOAT}, {"type", "VEC3"}, {"count", 4}});
        onePrimitiveScene(b, "Overrun", {{"attributes", {{"POSITION", pos}}}});
        const std::string path = b.write(dir.file("overrun.gltf"));
        expectOneLineError(loadScene(path), path, {"mesh 'Overrun'", "POSITION", "reads past the end"});
    }
    {
        // a missing material
        GltfBuilder b;
        const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
        onePrimitiveScene(b, "Orphan", {{"attributes", {{"POSITION", pos}}}, {"material", 3}});
        const std::string path = b.write(dir.file("missing_material.gltf"));
        expectOneLineError(loadScene(path), path, {"missing material 3"});
    }
    {
        // a cycle in the node hierarchy
        GltfBuilder b;
        const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
        onePrimitiveScene(b, "Loop", {{"attributes", {{"POSITION", pos}}}});
        b.doc["nodes"] = json::array({{{"name", "A"}, {"mesh", 0}, {"children", json::array({1})}}, {{"name", "B"}, {"children", json::array({0})}}});
        const std::string path = b.write(dir.file("cycle.gltf"));
        expectOneLineError(loadScene(path), path, {"not a tree"});
    }
    {
        // Draco-compressed geometry cannot be read
        GltfBuilder b;
        const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
        onePrimitiveScene(b, "Draco", {{"attributes", {{"POSITION", pos}}}});
        b.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
        b.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
        const std::string path = b.write(dir.file("draco.gltf"));
        expectOneLineError(loadScene(path), path, {"KHR_draco_mesh_compression"});
    }
}


// Only glTF 2.0: asset.version 1.0 (and any other major), a minVersion above
// 2.0 and a .glb container version 1 are refused in one line that says so.
TEST(SceneLoaderReject, OtherGltfVersions) {
    TempDir dir;
    auto write = [&](const std::string& name, const json& asset) {
        GltfBuilder b;
        const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
        onePrimitiveScene(b, "Tri", {{"attributes", {{"POSITION", pos}}}});
        b.doc["asset"] = asset;
        return b.write(dir.file(name));
    };
    for (const char* version : {"1.0", "3.0", "0.9", "1.1"}) {
        SCOPED_TRACE(version);
        const std::string path = write(std::string("v") + version + ".gltf", {{"version", version}});
        expectOneLineError(loadScene(path), path, {std::string("glTF ") + version + " is not supported", "2.0 only"});
    }
    const std::string notNumber = write("vx.gltf", {{"version", "two"}});
    expectOneLineError(loadScene(notNumber), notNumber, {"asset.version 'two'"});
    const std::string minVersion = write("min21.gltf", {{"version", "2.0"}, {"minVersion", "2.1"}});
    expectOneLineError(loadScene(minVersion), minVersion, {"requires glTF 2.1", "minVersion"});
    EXPECT_TRUE(loadScene(write("v21.gltf", {{"version", "2.1"}, {"minVersion", "2.0"}}))) << "2.1 without a higher minVersion is 2.0-compatible";

    // a glTF 1.0 document (meshes and scenes as objects): the version, not tinygltf's schema error
    const std::string gltf1 = dir.file("gltf1.gltf");
    writeText(gltf1, R"({"asset": {"version": "1.0"}, "scene": "s", "scenes": {"s": {"nodes": ["n"]}},
                        "nodes": {"n": {"meshes": ["m"]}}, "meshes": {"m": {"primitives": []}}})");
    expectOneLineError(loadScene(gltf1), gltf1, {"glTF 1.0 is not supported"});

    // KHR_binary_glTF (glTF 1.0's .glb): container version 1
    std::vector<unsigned char> glb = {'g', 'l', 'T', 'F', 1, 0, 0, 0, 20, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
    const std::string glb1 = dir.file("v1.glb");
    writeBytes(glb1, glb.data(), glb.size());
    expectOneLineError(loadScene(glb1), glb1, {"container version 1", "2.0 only"});
}

}  // namespace
}  // namespace bb

namespace bb {
namespace {

// KHR_lights_punctual point and spot lights and alphaMode MASK (issue 12):
// a spot on a node rotated 90 degrees about X (its -Z points down the world
// -Y) translated to (1, 3, 2), range 5, cone angles 0.2 / 0.6; a spot with an
// inner angle above its outer one (clamped to it) and an outer one above
// pi/2 (clamped); cut-out, blended and opaque materials.
TEST(SceneLoader, PunctualLightsAndCutouts) {
    TempDir dir;
    GltfBuilder b;
    const float h = std::sqrt(0.5f);
    const int pos = b.positions({0, 0, 0, 1, 0, 0, 0, 1, 0});
    b.doc["materials"] = json::array(
        {{{"name", "Leaf"}, {"alphaMode", "MASK"}, {"alphaCutoff", 0.3},
          {"pbrMetallicRoughness", {{"baseColorFactor", {1.0, 1.0, 1.0, 0.8}}, {"metallicFactor", 0.0}}}},
         {{"name", "Glass"}, {"alphaMode", "BLEND"}, {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}},
         {{"name", "Fence"}, {"alphaMode", "MASK"}, {"pbrMetallicRoughness", {{"metallicFactor", 0.0}}}}});
    b.doc["meshes"] = json::array({{{"name", "Tris"},
                                    {"primitives",
                                     {{{"attributes", {{"POSITION", pos}}}, {"material", 0}},
                                      {{"attributes", {{"POSITION", pos}}}, {"material", 1}},
                                      {{"attributes", {{"POSITION", pos}}}, {"material", 2}}}}}});
    b.doc["nodes"] = json::array(
        {{{"name", "Mesh"}, {"mesh", 0}},
         {{"name", "Spot"}, {"translation", {1, 3, 2}}, {"rotation", {-h, 0, 0, h}},
          {"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}},
         {{"name", "Odd"}, {"extensions", {{"KHR_lights_punctual", {{"light", 1}}}}}}});
    b.doc["extensionsUsed"] = {"KHR_lights_punctual"};
    b.doc["extensions"] = {
        {"KHR_lights_punctual",
         {{"lights",
           {{{"name", "Lamp"}, {"type", "spot"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 40.0}, {"range", 5.0},
             {"spot", {{"innerConeAngle", 0.2}, {"outerConeAngle", 0.6}}}},
            {{"type", "spot"}, {"spot", {{"innerConeAngle", 1.0}, {"outerConeAngle", 0.9}}}}}}}}};
    b.doc["scenes"] = json::array({{{"nodes", {0, 1, 2}}}});
    b.doc["scene"] = 0;
    const std::string path = b.write(dir.file("lights.gltf"));
    testing::internal::CaptureStderr();
    Expected<Scene> loaded = loadScene(path);
    const std::string log = testing::internal::GetCapturedStderr();
    ASSERT_TRUE(loaded) << loaded.error();
    const Scene& s = *loaded;

    ASSERT_EQ(s.punctualLights.size(), 2u);
    const PunctualLight& lamp = s.punctualLights[0];
    EXPECT_EQ(lamp.name, "Lamp");
    EXPECT_EQ(lamp.type, PunctualLight::Type::Spot);
    EXPECT_VEC3_NEAR(glm::vec3(lamp.position), 1.0f, 3.0f, 2.0f, 1e-12f);
    EXPECT_VEC3_NEAR(lamp.direction, 0.0f, -1.0f, 0.0f, 1e-6f);
    EXPECT_VEC3_NEAR(lamp.intensity, 40.0f, 20.0f, 10.0f, 1e-6f);
    EXPECT_EQ(lamp.range, 5.0f);
    EXPECT_FLOAT_EQ(lamp.innerConeAngle, 0.2f);
    EXPECT_FLOAT_EQ(lamp.outerConeAngle, 0.6f);
    const PunctualLight& odd = s.punctualLights[1];
    EXPECT_EQ(odd.name, "Odd");
    EXPECT_VEC3_NEAR(odd.direction, 0.0f, 0.0f, -1.0f, 1e-6f);  // the node's -Z
    EXPECT_VEC3_NEAR(odd.intensity, 1.0f, 1.0f, 1.0f, 0.0f);    // glTF's defaults
    EXPECT_EQ(odd.range, 0.0f);
    EXPECT_FLOAT_EQ(odd.outerConeAngle, 0.9f);
    EXPECT_FLOAT_EQ(odd.innerConeAngle, 0.9f);  // clamped to the outer angle

    ASSERT_EQ(s.materials.size(), 3u);
    EXPECT_TRUE(s.materials[0].alphaMask);
    EXPECT_FLOAT_EQ(s.materials[0].alphaCutoff, 0.3f);
    EXPECT_FLOAT_EQ(s.materials[0].alpha, 0.8f);
    EXPECT_FALSE(s.materials[1].alphaMask);  // BLEND bakes opaque
    EXPECT_TRUE(s.materials[2].alphaMask);
    EXPECT_FLOAT_EQ(s.materials[2].alphaCutoff, 0.5f);  // glTF's default cutoff
    EXPECT_FLOAT_EQ(s.materials[2].alpha, 1.0f);
    EXPECT_EQ(log.find("unknown type"), std::string::npos) << log;
}

}  // namespace
}  // namespace bb
