// Reproducibility through the CLI (BUNDLEBAKE_CLI): the same scene, options
// and seed give the same lightmap_0.exr bytes; another seed gives other
// bytes; and EGL and OSMesa (both Mesa llvmpipe here) give the same bytes.
//
// Scene: the Cornell box (assets/cornell_box, asset layout 64 x 64), 64
// directions: a real mix of emission, colour bleeding and shadows, so any
// difference in directions, rounding random numbers or rasterization shows.
// ~0.5 s of baking per run.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "headless/platform.h"
#include "io/image_io.h"
#include "support/cli_helper.h"
#include "support/gl_fixture.h"

namespace bb::test {
namespace {

std::vector<std::string> bakeArgs(const std::string& out, const std::string& backend, int seed) {
    return {"bake", sourcePath("assets/cornell_box/cornell_box.gltf"), "-o", out, "--backend", backend, "--uv-layout",
            "asset", "--resolution", "64", "--directions", "64", "--seed", std::to_string(seed), "--no-progress",
            "--no-preview"};
}

// Max abs difference between two EXR files' pixels (-1 if unreadable or of different size).
double maxAbsDiff(const std::string& a, const std::string& b, size_t* differing) {
    auto ia = io::readImageRgb(a), ib = io::readImageRgb(b);
    if (!ia || !ib || ia->width != ib->width || ia->height != ib->height) return -1;
    double m = 0;
    *differing = 0;
    for (size_t i = 0; i < ia->pixels.size(); ++i) {
        double d = 0;
        for (int c = 0; c < 3; ++c) d = std::max(d, double(std::abs(ia->pixels[i][c] - ib->pixels[i][c])));
        *differing += d > 0;
        m = std::max(m, d);
    }
    return m;
}

bool backendAvailable(Backend backend, std::string* why) {
    // a child process would be cleaner, but a context made and dropped here is harmless
    auto ctx = createHeadlessContext(backend);
    if (!ctx) *why = ctx.error();
    return bool(ctx);
}

TEST(CliDeterminism, SameSeedSameBytesOtherSeedOtherBytes) {
    std::string why;
    ASSERT_TRUE(backendAvailable(defaultTestBackend(), &why)) << why;
    const std::string backend = backendName(defaultTestBackend());
    TempDir tmp("determinism");
    ASSERT_TRUE(tmp.ok());
    CliResult a = runCli(bakeArgs(tmp / "a", backend, 7), tmp);
    ASSERT_EQ(a.exitCode, 0) << a.err;
    CliResult b = runCli(bakeArgs(tmp / "b", backend, 7), tmp);
    ASSERT_EQ(b.exitCode, 0) << b.err;
    CliResult c = runCli(bakeArgs(tmp / "c", backend, 8), tmp);
    ASSERT_EQ(c.exitCode, 0) << c.err;
    const std::string ea = readFileBytes(tmp / "a/lightmap_0.exr"), eb = readFileBytes(tmp / "b/lightmap_0.exr"),
                      ec = readFileBytes(tmp / "c/lightmap_0.exr");
    ASSERT_GT(ea.size(), 1000u);
    size_t differing = 0;
    if (ea != eb) {
        double d = maxAbsDiff(tmp / "a/lightmap_0.exr", tmp / "b/lightmap_0.exr", &differing);
        ADD_FAILURE() << "two bakes with seed 7 (" << backend << ") wrote different lightmap_0.exr bytes: max abs diff "
                      << d << " over " << differing << " texels (0 means only the file bytes differ, e.g. metadata)";
    }
    EXPECT_NE(ea, ec) << "seeds 7 and 8 wrote identical lightmap_0.exr bytes: the seed has no effect";
    double d = maxAbsDiff(tmp / "a/lightmap_0.exr", tmp / "c/lightmap_0.exr", &differing);
    std::printf("[determinism] %s: seed 7 twice %s; seed 7 vs 8: max abs diff %.4g over %zu texels\n", backend.c_str(),
                ea == eb ? "identical" : "DIFFERENT", d, differing);
    EXPECT_GT(differing, 100u) << "another seed should change the noise of most covered texels";
}

// Both backends are Mesa's llvmpipe (same driver, same JIT, same thread
// count rules), so bitwise equality is expected; the bake's own random numbers
// are hash-based and do not depend on scheduling. Only in builds with OSMesa
// (the default; -DBUNDLEBAKE_WITH_OSMESA=OFF leaves nothing to compare).
#ifdef BUNDLEBAKE_WITH_OSMESA
TEST(CliDeterminism, EglAndOsMesaGiveSameBytes) {
    std::string why;
    ASSERT_TRUE(backendAvailable(Backend::Egl, &why)) << "EGL: " << why;
    ASSERT_TRUE(backendAvailable(Backend::OsMesa, &why)) << "OSMesa: " << why;
    TempDir tmp("backends");
    ASSERT_TRUE(tmp.ok());
    CliResult egl = runCli(bakeArgs(tmp / "egl", "egl", 5), tmp);
    ASSERT_EQ(egl.exitCode, 0) << egl.err;
    CliResult osmesa = runCli(bakeArgs(tmp / "osmesa", "osmesa", 5), tmp);
    ASSERT_EQ(osmesa.exitCode, 0) << osmesa.err;
    const std::string a = readFileBytes(tmp / "egl/lightmap_0.exr"), b = readFileBytes(tmp / "osmesa/lightmap_0.exr");
    ASSERT_GT(a.size(), 1000u);
    size_t differing = 0;
    const double d = maxAbsDiff(tmp / "egl/lightmap_0.exr", tmp / "osmesa/lightmap_0.exr", &differing);
    std::printf("[backends] egl vs osmesa: %s; max abs diff %.4g over %zu texels\n", a == b ? "identical bytes" : "bytes differ",
                d, differing);
    EXPECT_TRUE(a == b) << "EGL and OSMesa wrote different lightmap_0.exr bytes for seed 5: max abs diff " << d
                            << " over " << differing << " texels";
}
#endif

}  // namespace
}  // namespace bb::test
