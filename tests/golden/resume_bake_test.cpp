// Checkpoints and --resume (issue 13): a bake stopped after some directions
// and resumed from its checkpoint ends on the bytes (and statistics) of an
// uninterrupted bake; a checkpoint is refused by a bake of another scene or
// other options that change the bytes, and accepted with another memory
// budget (which changes how tiles are cut, never the bytes).
// Scene: assets/cornell_box (its light is an explicit emitter) under a sky,
// 24 directions, stopped after 9: the refresh schedule, the history ramp and
// explicit direct light all cross the cut.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <functional>

#include <unistd.h>

#include "support/bake_helper.h"

namespace bb::test {
namespace {

BakeOptions baseOptions() {
    BakeOptions o;
    o.directions = 24;
    o.seed = 3;
    o.sky = glm::vec3(0.3f, 0.4f, 0.5f);
    return o;
}

const char* kScene = "assets/cornell_box/cornell_box.gltf";

std::string checkpointPath() {
    return (std::filesystem::temp_directory_path() / ("bundlebake_resume_" + std::to_string(::getpid()) + ".bin")).string();
}

// Bakes 9 directions and writes a checkpoint; the Baker is then gone (as a killed process's).
void writeCheckpoint(const std::string& path) {
    SceneBake b = makeBake(kScene, assetLayout(64), baseOptions());
    ASSERT_TRUE(b) << b.error;
    while (b.baker->progress().directionsDone < 9) b.baker->step(0.0);
    ASSERT_EQ(b.baker->progress().directionsDone, 9);
    ASSERT_TRUE(b.baker->saveCheckpoint(path));
}

TEST(ResumeBake, ResumedBakeEndsOnTheUninterruptedBytesAndStatistics) {
    BB_REQUIRE_GL();
    const std::string path = checkpointPath();
    writeCheckpoint(path);

    SceneBake whole = makeBake(kScene, assetLayout(64), baseOptions());
    ASSERT_TRUE(whole) << whole.error;
    bakeToEnd(*whole.baker);
    const LightmapPages expected = whole.baker->readLightmaps();

    // resumed, with another bundle memory: the tiles differ, the bytes must not
    BakeOptions other = baseOptions();
    other.bundleMemory = 64 * 64 * 4 + 4000 * 12;
    SceneBake resumed = makeBake(kScene, assetLayout(64), other);
    ASSERT_TRUE(resumed) << resumed.error;
    ASSERT_TRUE(resumed.baker->loadCheckpoint(path));
    EXPECT_EQ(resumed.baker->progress().directionsDone, 9);
    bakeToEnd(*resumed.baker);
    const LightmapPages got = resumed.baker->readLightmaps();
    ASSERT_EQ(got.pages.size(), expected.pages.size());
    size_t differing = 0;
    for (size_t p = 0; p < got.pages.size(); ++p)
        for (size_t i = 0; i < got.pages[p].pixels.size(); ++i) differing += got.pages[p].pixels[i] != expected.pages[p].pixels[i];
    EXPECT_EQ(differing, 0u) << "texels differ between the resumed and the uninterrupted bake";
    // statistics carried over: the same totals as the uninterrupted bake
    const BakeStats& a = whole.baker->stats();
    const BakeStats& b = resumed.baker->stats();
    EXPECT_EQ(b.fragments, a.fragments);
    EXPECT_EQ(b.updatedTexels, a.updatedTexels);
    EXPECT_EQ(b.leavesPerDirection, a.leavesPerDirection);
    EXPECT_EQ(b.tilesPerDirection.size(), a.tilesPerDirection.size());
    EXPECT_GT(b.tilesDrawn, a.tilesDrawn) << "the smaller bundle memory cuts more tiles after the resume";
    std::filesystem::remove(path);
}

TEST(ResumeBake, CheckpointOfOtherOptionsOrSceneIsRefused) {
    BB_REQUIRE_GL();
    const std::string path = checkpointPath();
    writeCheckpoint(path);
    struct Change {
        const char* what;
        std::function<void(BakeOptions&)> options;
        std::function<void(Scene&)> scene;
    };
    const Change changes[] = {
        {"sky", [](BakeOptions& o) { o.sky.g = 0.41f; }, nullptr},
        {"seed", [](BakeOptions& o) { o.seed = 4; }, nullptr},
        {"directions", [](BakeOptions& o) { o.directions = 32; }, nullptr},
        {"direct light mode", [](BakeOptions& o) { o.directLight = BakeOptions::DirectLight::Bundles; }, nullptr},
        {"emitter samples", [](BakeOptions& o) { o.emitterSamples = 64; }, nullptr},
        {"emitter shadow size", [](BakeOptions& o) { o.emitterShadowSize = 128; }, nullptr},
        {"tiling", [](BakeOptions& o) { o.tiling = BakeOptions::Tiling::Uniform; }, nullptr},
        {"sun jitter", [](BakeOptions& o) { o.sunJitter = 3; }, nullptr},
        {"rounding", [](BakeOptions& o) { o.rounding = Rounding::Nearest; }, nullptr},
        {"an albedo", nullptr, [](Scene& s) { s.materials[0].albedo.r *= 0.99f; }},
        {"an emission", nullptr, [](Scene& s) {
             for (Material& m : s.materials)
                 if (m.emission != glm::vec3(0.0f)) m.emission *= 1.01f;
         }},
        {"a sun", nullptr, [](Scene& s) { s.lights.push_back(DirectionalLight{"sun", {0, -1, 0}, {1, 1, 1}}); }},
    };
    for (const Change& c : changes) {
        SCOPED_TRACE(c.what);
        BakeOptions o = baseOptions();
        if (c.options) c.options(o);
        auto scene = loadScene(sourcePath(kScene));
        ASSERT_TRUE(scene) << scene.error();
        if (c.scene) c.scene(*scene);
        auto layout = computeLayout(*scene, assetLayout(64));
        ASSERT_TRUE(layout) << layout.error();
        auto baker = Baker::create(*scene, *layout, o);
        ASSERT_TRUE(baker) << baker.error();
        Status s = (*baker)->loadCheckpoint(path);
        EXPECT_FALSE(s) << "a checkpoint was accepted after changing " << c.what;
        if (!s) EXPECT_NE(s.message().find("another scene or other bake options"), std::string::npos) << s.message();
        EXPECT_EQ((*baker)->progress().directionsDone, 0);
    }
    std::filesystem::remove(path);
}

}  // namespace
}  // namespace bb::test
