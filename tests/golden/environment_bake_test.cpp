// `--env` on the GPU (BakeOptions::environment, glsl/lightmap/update.frag
// environment()): an equirectangular radiance map, against an analytic answer
// and against the CPU reference baker (engine/reference), which is the ruler.
//
// Convention (update.frag, the reference, README): u = 0.5 + atan2(d.z, d.x) /
// 2pi, v = acos(d.y) / pi, image row 0 = v 0 = straight up (+Y).
//
// 1. Linear environment, convex body. Each channel is linear in the
//    direction along its own axis: L(w) = (a + b w.x, a + b w.y, a + b w.z),
//    a = 1, b = 0.9. A single-sided face of normal n that sees only the
//    environment (the outward faces of a convex box never see each other)
//    reads, exactly, L_lm = (1/pi) int_H(n) L(w) (w.n) dw = a + (2/3) b n
//    (int_H (w.k)(w.n) dw = (2pi/3) k.n), in every texel, for any albedo.
//    The box is rotated by a generic rotation, so every face has a different
//    value in every channel: a lookup mirrored in u (z -> -z), shifted by half
//    a turn (x, z -> -x, -z), swapping x and z, or upside down (y -> -y) moves
//    some face by up to (4/3) b = 1.2, i.e. 60-100 % of its value, and turns
//    the sign of (L_lm - a) against the sign of n: checked face by face.
// 2. The open box (assets/open_box, black, occluding) under a non-uniform
//    environment (a bright lobe on one side plus a gradient): the GPU bake
//    against the reference, relative RMSE over the texels both cover, and the
//    wall facing the lobe brighter than the opposite one, as in the reference.
//
// Tolerances are stated at each check, with the measured values beside them.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <glm/gtc/matrix_transform.hpp>

#include "io/image_io.h"
#include "support/bake_helper.h"
#include "support/cli_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

constexpr double PI = 3.14159265358979323846;

// The direction at the centre of pixel (x, y) of a w x h equirectangular map.
glm::dvec3 envDirection(int x, int y, int w, int h) {
    const double u = (x + 0.5) / w, v = (y + 0.5) / h;
    const double phi = (u - 0.5) * 2.0 * PI, theta = v * PI;
    return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

template <class F>
io::ImageRgb makeEnvironment(int w, int h, F&& radiance) {
    io::ImageRgb env;
    env.width = w;
    env.height = h;
    env.pixels.resize(size_t(w) * h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) env.at(x, y) = glm::vec3(radiance(envDirection(x, y, w, h)));
    return env;
}

constexpr double A = 1.0, B = 0.9;

// 128 x 64: bilinear interpolation of the linear field between pixel centres
// (2.8 degrees apart) is off by < 0.1 % (the field's curvature in (u, v) is
// that of sin/cos over 2.8 degrees); the GPU's v repeat blends the poles
// within half a row (0.0006 of a face's cosine weight): < 0.1 % as well.
io::ImageRgb linearEnvironment() {
    return makeEnvironment(128, 64, [](glm::dvec3 d) { return glm::dvec3(A) + B * d; });
}

// A 1 m box rotated by a generic rotation, outward faces, albedo 0.5 (which
// does not matter: the faces never see each other), at the origin.
Scene rotatedBox() {
    Scene scene;
    const int m = addMaterial(scene, glm::vec3(0.5f));
    const glm::mat3 axes = glm::mat3(glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(glm::vec3(1.0f, 2.0f, 3.0f))));
    addBox(scene, glm::vec3(0.0f), glm::vec3(0.5f), m, true, "box", axes);
    return scene;
}

// Per face: mean L_lm and the worst texel's relative error against a + (2/3) b n.
struct FaceResult {
    glm::dvec3 mean{0.0};
    double worst = 0;
    int texels = 0;
};

std::vector<FaceResult> checkLinearFaces(const char* who, const Scene& scene, const Layout& layout,
                                         const LightmapPages& maps, double meanTolerance, double texelTolerance) {
    std::vector<FaceResult> out;
    for (int f = 0; f < 6; ++f) {
        const glm::dvec3 n(instanceNormal(scene, f));
        const glm::dvec3 expected = glm::dvec3(A) + (2.0 / 3.0) * B * n;
        FaceResult r;
        forEachQuadTexel(scene, layout, maps, f, [&](int page, size_t i, const glm::dvec3&, int, int) {
            const glm::dvec3 v(maps.pages[size_t(page)].pixels[i]);
            r.mean += v;
            ++r.texels;
            for (int c = 0; c < 3; ++c) r.worst = std::max(r.worst, std::fabs(v[c] - expected[c]) / expected[c]);
        });
        r.mean /= double(std::max(r.texels, 1));
        std::printf("[env] %s face %s n (%+.3f %+.3f %+.3f): mean (%.4f %.4f %.4f), expected (%.4f %.4f %.4f), "
                    "worst texel %.2f%%, %d texels\n",
                    who, scene.instances[size_t(f)].name.c_str(), n.x, n.y, n.z, r.mean.x, r.mean.y, r.mean.z,
                    expected.x, expected.y, expected.z, 100 * r.worst, r.texels);
        EXPECT_GT(r.texels, 100) << who << ": face " << f;
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(r.mean[c], expected[c], meanTolerance * expected[c])
                << who << ", face " << scene.instances[size_t(f)].name << ", channel " << c << ": n = (" << n.x << ", "
                << n.y << ", " << n.z << ")";
            // the face tilted towards the bright side of channel c reads brighter than a
            if (std::fabs(n[c]) > 0.2)
                EXPECT_EQ(r.mean[c] > A, n[c] > 0.0)
                    << who << ", face " << scene.instances[size_t(f)].name << ", channel " << c
                    << ": brighter/darker than the mean radiance on the wrong side (mirrored or rotated lookup?)";
        }
        EXPECT_LT(r.worst, texelTolerance) << who << ", face " << scene.instances[size_t(f)].name;
        out.push_back(r);
    }
    return out;
}

// GPU, 256 directions. Measured (OSMesa, seeds 1..4): face means off the
// analytic value by at most 3.7 % (seed 2, the -z face's blue: 0.4339 for
// 0.4504), every texel within 7.0 %. That error is not direction noise: at
// 1024 and 4096 directions (and with a flat history ramp) it stays, as a
// magnification of the directional term, L_lm - a = 1.017 x (2/3) b n on
// every face and channel. That is what skipping grazing samples gives (the
// update pass drops a sample when the texel's own-surface crossing is beyond
// one texel, update.frag): the mean is cosine-weighted over the hemisphere
// minus a band at its horizon (~2 % of the weight would do it), which leans
// towards the normal; a uniform sky cannot show this, a gradient does.
// Samples spread over each texel's footprint (issue 11) put the edge texels'
// points nearer the face's edge, where more grazing samples cross the plane
// past it: the worst texel reads 8.6 % (seed 1; 7.0 % at the texels' centres),
// the face means do not move.
// Tolerance: face mean 5 %, every texel 10 %; L(n) + L(-n) = 2a within 0.5 %
// (the +-d pairing makes opposite faces complementary; measured 0.00 %).
// A mirrored or rotated lookup moves some face by 9..70 % and flips the
// sign check. Reference (256 samples a texel, cosine-weighted, stratified):
// measured face means within 0.06 %, texels 0.72 %: tolerance 0.5 % and 2 %.
// GPU against the reference: relative RMSE 0.98..1.09 % (seeds 1..4): < 2.5 %.
TEST(EnvironmentBake, LinearEnvironmentOnRotatedBoxIsAnalytic) {
    BB_REQUIRE_GL();
    Scene scene = rotatedBox();
    auto layout = packLayout(scene, 128, 36.0f);  // 36 x 36 texels a face, 3 x 2 on one page
    ASSERT_TRUE(layout) << layout.error();
    ASSERT_EQ(layout->pageCount, 1);

    BakeOptions options;
    options.directions = 256;
    options.seed = 1;
    options.environment = linearEnvironment();
    double seconds = 0;
    auto gpu = bakeGpu(scene, *layout, options, &seconds);
    ASSERT_TRUE(gpu) << gpu.error();
    std::printf("[env] GPU bake: %.2f s\n", seconds);
    std::vector<FaceResult> g = checkLinearFaces("bundlebake", scene, *layout, *gpu, 0.05, 0.10);
    for (int f = 0; f < 6; f += 2)
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(g[size_t(f)].mean[c] + g[size_t(f) + 1].mean[c], 2.0 * A, 0.005 * 2.0 * A)
                << "opposite faces " << scene.instances[size_t(f)].name << " and "
                << scene.instances[size_t(f) + 1].name << ", channel " << c << ": L(n) + L(-n) should be 2a";

    ReferenceOptions ro;
    ro.spp = 256;
    ro.environment = options.environment;
    auto cpu = bakeReference(scene, *layout, ro, &seconds);
    ASSERT_TRUE(cpu) << cpu.error();
    std::printf("[env] reference bake: %.2f s\n", seconds);
    checkLinearFaces("reference", scene, *layout, *cpu, 0.005, 0.02);

    MapAgreement a = compareMaps(*gpu, *cpu);
    std::printf("[env] GPU vs reference: %zu texels, relative RMSE %.3f%%\n", a.texels, 100 * a.relativeRmse());
    EXPECT_LT(a.relativeRmse(), 0.025);
}


// --- an occluding scene under a lobe --------------------------------------------

// A warm lobe (peak (5, 3, 1), half width ~18 degrees) 35 degrees above the
// horizon at azimuth atan2(z, x) = 30 degrees, over a dim bluish gradient.
// 128 x 64 pixels, 2.8 degrees each: the lobe spans ~13 pixels.
const glm::dvec3 LOBE_AXIS = [] {
    const double e = 35.0 * PI / 180.0, a = 30.0 * PI / 180.0;
    return glm::dvec3(std::cos(e) * std::cos(a), std::sin(e), std::cos(e) * std::sin(a));
}();

io::ImageRgb lobeEnvironment() {
    return makeEnvironment(128, 64, [](glm::dvec3 d) {
        const double lobe = std::exp((glm::dot(d, LOBE_AXIS) - 1.0) / 0.05);
        return glm::dvec3(5.0, 3.0, 1.0) * lobe + glm::dvec3(0.05, 0.1, 0.2) * (1.2 + d.y);
    });
}

// assets/open_box (black, open at the top), asset layout 32 x 32, under the
// lobe: GPU (1024 directions) against the reference (1024 samples a texel).
// Relative RMSE over the texels both cover < 6 % (measured 4.0..4.6 % over
// seeds 1..4). Per wall (texels grouped by their triangle's normal) the
// GPU's mean within 5 % of the reference's: measured walls within 1.4 %, the
// floor +2.2..+2.9 % on every seed (systematic: the grazing-sample bias of
// the linear-environment test above; the floor's grazing directions see the
// black walls, so leaving them out reads brighter). Orientation: the walls
// facing the lobe (+x, +z) brighter than the walls opposite them, as the
// reference has it: a lookup mirrored in u puts the lobe at azimuth -30
// degrees, which lights the -z-facing wall instead of the +z-facing one.
TEST(EnvironmentBake, OpenBoxUnderLobeMatchesReference) {
    BB_REQUIRE_GL();
    auto scene = loadScene(sourcePath("assets/open_box/open_box.gltf"));
    ASSERT_TRUE(scene) << scene.error();
    auto layout = computeLayout(*scene, assetLayout(32));
    ASSERT_TRUE(layout) << layout.error();
    BakeOptions options;
    options.directions = 1024;
    options.seed = 1;
    options.environment = lobeEnvironment();
    auto baker = Baker::create(*scene, *layout, options);
    ASSERT_TRUE(baker) << baker.error();
    const double seconds = bakeToEnd(**baker);
    LightmapPages gpu = (*baker)->readLightmaps();
    ReferenceOptions ro;
    ro.spp = 1024;
    ro.environment = options.environment;
    double refSeconds = 0;
    auto cpu = bakeReference(*scene, *layout, ro, &refSeconds);
    ASSERT_TRUE(cpu) << cpu.error();

    MapAgreement a = compareMaps(gpu, *cpu);
    std::printf("[env] open box under a lobe: GPU %.2f s, reference %.2f s; %zu texels (%zu only GPU, %zu only CPU), "
                "relative RMSE %.3f%%, means %.5f / %.5f\n",
                seconds, refSeconds, a.texels, a.onlyA, a.onlyB, 100 * a.relativeRmse(), a.meanA, a.meanB);
    EXPECT_LE(a.onlyA + a.onlyB, 2u);
    EXPECT_LT(a.relativeRmse(), 0.06);

    // per wall: group texels by their triangle's normal
    const BakeMesh& mesh = (*baker)->mesh();
    const std::vector<int> owner = texelTriangles(mesh, 32);
    const glm::vec3 axes[5] = {{1, 0, 0}, {-1, 0, 0}, {0, 0, 1}, {0, 0, -1}, {0, 1, 0}};
    const char* names[5] = {"+x-facing wall", "-x-facing wall", "+z-facing wall", "-z-facing wall", "floor"};
    double gpuMean[5] = {}, cpuMean[5] = {};
    int count[5] = {};
    for (size_t i = 0; i < owner.size(); ++i) {
        if (!gpu.covered[0][i] || !cpu->covered[0][i]) continue;
        const int t = owner[i] >= 0 ? owner[i] : nearestTriangle(mesh, 32, i);
        const glm::vec3 n(mesh.vertices[3 * size_t(t)].normal);
        for (int k = 0; k < 5; ++k)
            if (glm::dot(n, axes[k]) > 0.9f) {
                const glm::vec3 g = gpu.pages[0].pixels[i], c = cpu->pages[0].pixels[i];
                gpuMean[k] += (g.r + g.g + g.b) / 3.0;
                cpuMean[k] += (c.r + c.g + c.b) / 3.0;
                ++count[k];
            }
    }
    for (int k = 0; k < 5; ++k) {
        ASSERT_GT(count[k], 20) << names[k];
        gpuMean[k] /= count[k];
        cpuMean[k] /= count[k];
        std::printf("[env] %s: %d texels, GPU %.5f, reference %.5f (%+.2f%%)\n", names[k], count[k], gpuMean[k],
                    cpuMean[k], 100 * (gpuMean[k] / cpuMean[k] - 1));
        EXPECT_NEAR(gpuMean[k], cpuMean[k], 0.05 * cpuMean[k]) << names[k];
    }
    EXPECT_GT(cpuMean[0], 1.5 * cpuMean[1]) << "reference: the +x-facing wall should see the lobe";
    EXPECT_GT(cpuMean[2], 1.5 * cpuMean[3]) << "reference: the +z-facing wall should see the lobe";
    EXPECT_GT(gpuMean[0], 1.5 * gpuMean[1]) << "bundlebake: the +x-facing wall should see the lobe (x mirrored?)";
    EXPECT_GT(gpuMean[2], 1.5 * gpuMean[3]) << "bundlebake: the +z-facing wall should see the lobe (u mirrored?)";
}

// --- the CLI's --env -------------------------------------------------------------

// `bundlebake bake --env FILE` (headless/cli: io::readImageRgb, file row 0 =
// the top = v 0) against the in-process bake with the same map in memory:
// the lobe map written as a half-float EXR, the open box, 64 directions,
// seed 1. The two differ only by the EXR's half rounding of the map (<= 0.05 %
// a pixel), which can move a stochastic rounding draw by one step: relative
// RMSE < 1 % (measured 0.04 %). The same map upside down (rows reversed:
// the lobe below the horizon) gives relative RMSE 113 % against it, so a CLI that
// loaded the file the wrong way up would fail by far.
TEST(EnvironmentBake, CliEnvFileBakesAsInMemoryMap) {
    BB_REQUIRE_GL();
    TempDir tmp("env");
    ASSERT_TRUE(tmp.ok());
    const io::ImageRgb env = lobeEnvironment();
    const Status written = io::writeExr(tmp / "env.exr", env);
    ASSERT_TRUE(written) << written.message();
    CliResult cli = runCli({"bake", sourcePath("assets/open_box/open_box.gltf"), "-o", tmp / "out", "--backend",
                            backendName(defaultTestBackend()), "--uv-layout", "asset", "--resolution", "32",
                            "--directions", "64", "--seed", "1", "--env", tmp / "env.exr", "--no-progress",
                            "--no-preview"},
                           tmp);
    ASSERT_EQ(cli.exitCode, 0) << cli.err;
    auto fromCli = io::readImageRgb(tmp / "out/lightmap_0.exr");
    ASSERT_TRUE(fromCli) << fromCli.error();

    auto scene = loadScene(sourcePath("assets/open_box/open_box.gltf"));
    ASSERT_TRUE(scene) << scene.error();
    auto layout = computeLayout(*scene, assetLayout(32));
    ASSERT_TRUE(layout) << layout.error();
    BakeOptions options;
    options.directions = 64;
    options.seed = 1;
    options.supersample = 0;  // as the CLI's --supersample auto
    options.environment = env;
    auto inMemory = bakeGpu(*scene, *layout, options);
    ASSERT_TRUE(inMemory) << inMemory.error();
    io::ImageRgb flipped = env;
    io::flipRows(flipped);
    options.environment = flipped;
    auto upsideDown = bakeGpu(*scene, *layout, options);
    ASSERT_TRUE(upsideDown) << upsideDown.error();

    LightmapPages cliMaps = *inMemory;
    ASSERT_EQ(fromCli->width, 32);
    ASSERT_EQ(fromCli->height, 32);
    cliMaps.pages[0] = *fromCli;
    const MapAgreement same = compareMaps(cliMaps, *inMemory), other = compareMaps(*upsideDown, *inMemory);
    std::printf("[env] CLI --env vs in-memory map: relative RMSE %.3f%%; upside-down map vs it: %.1f%% (%zu texels)\n",
                100 * same.relativeRmse(), 100 * other.relativeRmse(), same.texels);
    EXPECT_LT(same.relativeRmse(), 0.01) << "the CLI's --env bake differs from the same map passed in memory";
    EXPECT_GT(other.relativeRmse(), 0.2) << "the test cannot tell an upside-down map";
}

}  // namespace
}  // namespace bb::test
