// SCRATCH (to be deleted): exploration of noise and timings.
#include <gtest/gtest.h>
#include <cstdlib>
#include "support/bake_helper.h"
namespace bb::test {
static int envInt(const char* n, int d) { const char* v = std::getenv(n); return v ? std::atoi(v) : d; }
static float envF(const char* n, float d) { const char* v = std::getenv(n); return v ? std::atof(v) : d; }
static std::string envS(const char* n, const char* d) { const char* v = std::getenv(n); return v ? v : d; }
TEST(Scratch, DISABLED_Explore) {
    auto ctx = createHeadlessContext(defaultTestBackend());
    ASSERT_TRUE(ctx) << ctx.error();
    std::string scene = envS("SC", "assets/furnace/furnace.gltf");
    int res = envInt("RES", 64), dirs = envInt("DIRS", 256), seeds = envInt("SEEDS", 3);
    for (int s = 1; s <= seeds; ++s) {
        BakeOptions bo; bo.directions = dirs; bo.seed = s;
        bo.historyPower = envF("HP", -1);
        bo.rounding = envInt("NEAREST", 0) ? Rounding::Nearest : Rounding::Stochastic;
        bo.sky = glm::vec3(envF("SKYR", 0), envF("SKYG", 0), envF("SKYB", 0));
        auto b = makeBake(scene, assetLayout(res), bo);
        ASSERT_TRUE(b) << b.error;
        double t = bakeToEnd(*b.baker);
        auto maps = b.baker->readLightmaps();
        for (int c = 0; c < 3; ++c) {
            Summary su; const auto& img = maps.pages[0];
            for (size_t i = 0; i < img.pixels.size(); ++i) if (maps.covered[0][i]) su.add(img.pixels[i][c], i);
            su.finish();
            printf("seed %d ch %d time %.2fs: %s\n", s, c, t, describe(su, res).c_str());
        }
        auto acc = b.baker->readAccumulators();
        double wmax = 0; for (auto& a : acc[0]) wmax = std::max<double>(wmax, a.w);
        printf("  Wmax %.1f\n", wmax);
    }
}
}
