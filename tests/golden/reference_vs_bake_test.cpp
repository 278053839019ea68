// The CPU reference baker (engine/reference) and the GPU ray-bundle baker on
// the same analytic cases, same layout, same texels: each against the analytic
// answer, and the two against each other. GL (shared headless context).
//
// Tolerances: the reference's are its unit-test bounds (tests/unit/
// reference_test.cpp); the GPU baker's allow its start-up bias (history ramp)
// and direction-sampling noise at the direction counts used here.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "bake/baker.h"
#include "layout/layout.h"
#include "reference/reference_baker.h"
#include "scene/scene.h"
#include "support/gl_fixture.h"
#include "support/hand_scenes.h"

namespace bb {
namespace {

struct Pair {
    Scene scene;
    Layout layout;
    LightmapPages gpu, cpu;
    std::unique_ptr<ReferenceBaker> reference;
};

// Bakes `asset` (asset layout at `res`) with both bakers.
Pair bakeBoth(const std::string& asset, int res, int directions, int spp, glm::vec3 sky) {
    Pair p;
    auto scene = loadScene(test::sourcePath("assets/" + asset));
    EXPECT_TRUE(scene) << scene.error();
    p.scene = std::move(scene.value());
    LayoutOptions lo;
    lo.mode = UvLayout::Asset;
    lo.resolution = res;
    auto layout = computeLayout(p.scene, lo);
    EXPECT_TRUE(layout) << layout.error();
    p.layout = layout.value();

    BakeOptions bo;
    bo.directions = directions;
    bo.sky = sky;
    auto baker = Baker::create(p.scene, p.layout, bo);
    EXPECT_TRUE(baker) << baker.error();
    while (!(*baker)->step(1e9).done()) {
    }
    p.gpu = (*baker)->readLightmaps();

    ReferenceOptions ro;
    ro.spp = spp;
    ro.sky = sky;
    auto ref = ReferenceBaker::create(p.scene, p.layout, ro);
    EXPECT_TRUE(ref) << ref.error();
    while (!(*ref)->step(1e9).done()) {
    }
    p.cpu = (*ref)->readLightmaps();
    p.reference = std::move(ref.value());
    return p;
}

// Over texels covered in both: mean of each map (all channels) and the RMSE between them.
struct Agreement {
    int texels = 0, onlyGpu = 0, onlyCpu = 0;
    double meanGpu = 0, meanCpu = 0, rmse = 0;
};
Agreement agreement(const Pair& p) {
    Agreement a;
    for (size_t i = 0; i < p.gpu.covered[0].size(); ++i) {
        const bool g = p.gpu.covered[0][i], c = p.cpu.covered[0][i];
        a.onlyGpu += g && !c;
        a.onlyCpu += c && !g;
        if (!g || !c) continue;
        ++a.texels;
        for (int ch = 0; ch < 3; ++ch) {
            const double x = p.gpu.pages[0].pixels[i][ch], y = p.cpu.pages[0].pixels[i][ch];
            a.meanGpu += x;
            a.meanCpu += y;
            a.rmse += (x - y) * (x - y);
        }
    }
    const double n = 3.0 * std::max(a.texels, 1);
    a.meanGpu /= n;
    a.meanCpu /= n;
    a.rmse = std::sqrt(a.rmse / n);
    return a;
}

// The same texels: coverage found by GL rasterization and by the CPU's
// centre-inside test with a top-left rule may differ only on exact edge ties.
void expectSameTexels(const Agreement& a) {
    EXPECT_GT(a.texels, 0);
    EXPECT_LE(a.onlyGpu + a.onlyCpu, std::max(2, a.texels / 500)) << a.onlyGpu << " only on the GPU, " << a.onlyCpu
                                                                   << " only on the CPU";
}

// Furnace (Le 1, rho 0.5): L_lm = 2 at every texel.
TEST(ReferenceVsBake, Furnace) {
    BB_REQUIRE_GL();
    Pair p = bakeBoth("furnace/furnace.gltf", 32, 256, 1024, glm::vec3(0.0f));
    Agreement a = agreement(p);
    expectSameTexels(a);
    EXPECT_NEAR(a.meanCpu, 2.0, 0.01);  // 0.5%
    EXPECT_NEAR(a.meanGpu, 2.0, 0.04);  // 2%: the history ramp's start-up bias at 256 directions is ~1%
    EXPECT_LT(a.rmse / 2.0, 0.04) << "relative RMSE between the two bakers";
}

// A plane under a uniform sky: L_lm = S everywhere, both bakers, every texel.
TEST(ReferenceVsBake, SkyPlane) {
    BB_REQUIRE_GL();
    Pair p = bakeBoth("sky_plane/sky_plane.gltf", 32, 64, 16, glm::vec3(1.0f));
    Agreement a = agreement(p);
    expectSameTexels(a);
    for (size_t i = 0; i < p.gpu.covered[0].size(); ++i) {
        if (!p.gpu.covered[0][i] || !p.cpu.covered[0][i]) continue;
        ASSERT_NEAR(p.cpu.pages[0].pixels[i].g, 1.0f, 0.005f) << "reference, texel " << i;
        ASSERT_NEAR(p.gpu.pages[0].pixels[i].g, 1.0f, 0.01f) << "bundlebake, texel " << i;
    }
}

// Open box (black, sky 1): the texels holding the probes of probes.json, each
// baker against the exact sky view factor at the texel's centre (the reference's
// estimator at 2^16 samples there, itself checked against Lambert's formula at
// the probe points in the unit test).
TEST(ReferenceVsBake, OpenBoxProbes) {
    BB_REQUIRE_GL();
    const int res = 64;
    Pair p = bakeBoth("open_box/open_box.gltf", res, 1024, 1024, glm::vec3(1.0f));
    Agreement a = agreement(p);
    expectSameTexels(a);
    std::ifstream in(test::sourcePath("assets/probes.json"));
    const nlohmann::json doc = nlohmann::json::parse(in);
    const BakeMesh& mesh = p.reference->mesh();
    for (const auto& probe : doc["scenes"]["open_box"]["probes"]) {
        const double u = probe["uv1"][0].get<double>(), v = probe["uv1"][1].get<double>();
        const int x = int(u * res), y = int(v * res);
        const size_t t = size_t(y) * res + x;
        ASSERT_TRUE(p.gpu.covered[0][t] && p.cpu.covered[0][t]) << probe["name"];
        // the texel centre in world space (the triangle holding it in page space)
        const glm::dvec2 c(x + 0.5, y + 0.5);
        glm::vec3 centre(0.0f), normal(0.0f);
        for (size_t k = 0; k < mesh.triangles.size(); ++k) {
            glm::dvec2 q[3];
            for (int j = 0; j < 3; ++j) q[j] = glm::dvec2(mesh.vertices[3 * k + j].lightmapUv) * double(res);
            auto edge = [](glm::dvec2 a0, glm::dvec2 a1, glm::dvec2 pt) {
                return (a1.x - a0.x) * (pt.y - a0.y) - (a1.y - a0.y) * (pt.x - a0.x);
            };
            const double area = edge(q[0], q[1], q[2]);
            if (area == 0.0) continue;
            const double w0 = edge(q[1], q[2], c) / area, w1 = edge(q[2], q[0], c) / area, w2 = edge(q[0], q[1], c) / area;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            centre = glm::vec3(w0 * glm::dvec3(mesh.vertices[3 * k].position) +
                               w1 * glm::dvec3(mesh.vertices[3 * k + 1].position) +
                               w2 * glm::dvec3(mesh.vertices[3 * k + 2].position));
            normal = glm::vec3(mesh.vertices[3 * k].normal);
            break;
        }
        ASSERT_GT(glm::length(normal), 0.5f) << probe["name"];
        const double exact = p.reference->estimate(centre, normal, 1 << 16, 11).g;
        const double cpu = p.cpu.pages[0].pixels[t].g, gpu = p.gpu.pages[0].pixels[t].g;
        EXPECT_LT(std::fabs(cpu - exact) / exact, 0.04) << probe["name"] << ": reference " << cpu << " vs " << exact;
        EXPECT_LT(std::fabs(gpu - exact) / exact, 0.05) << probe["name"] << ": bundlebake " << gpu << " vs " << exact;
    }
}

// A chart whose borders run through texel centres: GL's rasterizer and the
// reference settle the ties alike (left and bottom edges count, page space
// being GL's window space), so both cover the same texels, and both take the
// texels past the other two borders as partial ones. The reference
// counted top edges: a 10 x 6 texel quad was covered one row apart.
TEST(ReferenceVsBake, TexelCentresOnChartBordersAreCoveredAlike) {
    BB_REQUIRE_GL();
    Scene scene;
    const int grey = test::addMaterial(scene, glm::vec3(0.5f));
    test::addQuad(scene, glm::vec3(0.0f), glm::vec3(5.0f, 0.0f, 0.0f), glm::vec3(0.0f, 3.0f, 0.0f), grey, "quad");
    const int res = 16;  // borders at texel centres x = 0.5 and 10.5, y = 0.5 and 6.5
    scene.meshes[0].primitives[0].uv1 = {glm::vec2(0.5f, 0.5f) / float(res), glm::vec2(10.5f, 0.5f) / float(res),
                                         glm::vec2(10.5f, 6.5f) / float(res), glm::vec2(0.5f, 6.5f) / float(res)};
    LayoutOptions lo;
    lo.mode = UvLayout::Asset;
    lo.resolution = res;
    auto layout = computeLayout(scene, lo);
    ASSERT_TRUE(layout) << layout.error();
    BakeOptions bo;
    bo.directions = 1;
    auto gpu = test::bakeGpu(scene, *layout, bo);
    ASSERT_TRUE(gpu) << gpu.error();
    ReferenceOptions ro;
    ro.spp = 1;
    auto cpu = test::bakeReference(scene, *layout, ro);
    ASSERT_TRUE(cpu) << cpu.error();
    const test::MapAgreement a = test::compareMaps(*gpu, *cpu);
    // and the texels past the right and top borders hold half of their squares on
    // it (a quarter at the corner): partial texels (layout/bake_mesh.h texelOwners)
    EXPECT_EQ(a.texels, 60u + 6u + 10u + 1u) << "10 x 6 texel centres lie inside or on the left and bottom borders";
    EXPECT_EQ(a.onlyA, 0u) << "covered by the bake only";
    EXPECT_EQ(a.onlyB, 0u) << "covered by the reference only";
}

}  // namespace
}  // namespace bb
