// `bundlebake info` describes every shipped scene, including the ones no
// layout can be made for yet (no TEXCOORD_1): exit 0, and the figures the
// loader tests hold (triangles kept, skipped, lights) appear in its output.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>

namespace {

struct CliRun {
    int status = -1;
    std::string out;
};

CliRun runCli(const std::string& args) {
    CliRun r;
    std::string cmd = std::string(BUNDLEBAKE_CLI) + " " + args + " 2>/dev/null";
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return r;
    std::array<char, 4096> buf{};
    while (size_t n = fread(buf.data(), 1, buf.size(), p)) r.out.append(buf.data(), n);
    r.status = pclose(p);
    return r;
}

struct Expect {
    const char* file;
    const char* triangles;
    const char* skipped;
    const char* lights;
    const char* layout;
};

TEST(CliInfo, DescribesEveryShippedScene) {
    const Expect cases[] = {
        {"assets/shared/cornell_box/CornellBox.glb", "triangles    36 ", "skipped      0 degenerate", "lights       0 ", "layout       pack, 1 page"},
        {"assets/shared/living_room/living_room.glb", "triangles    1551 ", "skipped      3537 degenerate", "lights       0 ", "layout       pack, 1 page"},
        {"assets/shared/mixed_lighting/MixedLightingExample.gltf", "triangles    40898 ", "skipped      0 degenerate", "lights       1 directional", "layout       pack, 1 page"},
        {"assets/shared/zdm2/zdm2.glb", "triangles    57638 ", "skipped      1134 degenerate", "lights       0 ", "layout       pack, 1 page"},
        {"assets/cornell_box/cornell_box.gltf", "triangles    32 ", "skipped      0 degenerate", "lights       0 ", "layout       pack, 1 page"},
        {"assets/furnace/furnace.gltf", "triangles    24 ", "skipped      0 degenerate", "lights       0 ", "layout       pack, 1 page"},
    };
    for (const Expect& e : cases) {
        CliRun r = runCli("info " + std::string(BUNDLEBAKE_SOURCE_DIR) + "/" + e.file);
        EXPECT_EQ(r.status, 0) << e.file;
        for (const char* needle : {e.triangles, e.skipped, e.lights, e.layout})
            EXPECT_NE(r.out.find(needle), std::string::npos) << e.file << ": no '" << needle << "' in\n" << r.out;
    }
}

TEST(CliInfo, MissingFileIsOneErrorLineAndNonZero) {
    std::string cmd = std::string(BUNDLEBAKE_CLI) + " info /nonexistent/scene.glb 2>&1 >/dev/null";
    FILE* p = popen(cmd.c_str(), "r");
    ASSERT_NE(p, nullptr);
    std::string err;
    std::array<char, 4096> buf{};
    while (size_t n = fread(buf.data(), 1, buf.size(), p)) err.append(buf.data(), n);
    int status = pclose(p);
    EXPECT_NE(status, 0);
    EXPECT_EQ(err.rfind("bundlebake: error:", 0), 0u) << err;
    EXPECT_EQ(std::count(err.begin(), err.end(), '\n'), 1) << err;
}

}  // namespace
