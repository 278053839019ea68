// Importance analysis on the GPU (engine/importance/importance_gl.h) against
// the CPU reference (engine/importance/importance.h), supplement §1.
//
// Tolerances are float error bounds, not fitted constants:
//  - same inputs (the GPU's own position buffer): Eq. (3) is ~10 float
//    operations on values whose differences are exact or nearly so, so it
//    agrees to REL_SAME = 1e-5 (observed <= 3e-7);
//  - Eq. (1): a float evaluation of two cross products; the bound is first
//    order in the edge lengths and the cancellation (areaRatioBound);
//  - the position buffer itself: llvmpipe interpolates each coordinate as a
//    plane a0 + dadx x + dady y in float, so a texel's position may differ
//    from the exact barycentric one by a few ulp of |p| + |grad p| R
//    (positionBound); Eq. (3) and I_max inherit that (densityBound).
#include <gtest/gtest.h>
#include <unistd.h>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "gl/gl.h"
#include "importance/importance.h"
#include "importance/importance_gl.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"
#include "io/image_io.h"
#include "support/bake_helper.h"
#include "support/gl_fixture.h"
#include "support/importance_meshes.h"
#include "support/scratch_dirs.h"

namespace bb {
namespace {

constexpr double EPS = 5.9604644775390625e-8;  // 2^-24, float unit roundoff
constexpr double REL_SAME = 1e-5;

std::unique_ptr<ImportanceAnalyzer> makeAnalyzer() {
    auto a = ImportanceAnalyzer::create();
    EXPECT_TRUE(a) << a.error();
    return a ? std::move(a.value()) : nullptr;
}

BakeMesh assetMesh(const std::string& path, UvLayout mode, int resolution) {
    auto scene = loadScene(test::sourcePath(path));
    EXPECT_TRUE(scene) << scene.error();
    if (!scene) return {};
    LayoutOptions o;
    o.mode = mode;
    o.resolution = resolution;
    auto layout = computeLayout(*scene, o);
    EXPECT_TRUE(layout) << layout.error();
    if (!layout) return {};
    EXPECT_EQ(layout->resolution, resolution);
    return buildBakeMesh(*scene, *layout);
}

bool allFinite(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x) && x >= 0.0f; });
}

// Bound on |GPU - exact| for Eq. (1) of one triangle: each of the two areas is
// a cross product of float edge differences; an edge carries an absolute
// error <= eps * (largest coordinate), the products eps * |a||b|.
double areaRatioBound(const BakeVertex* t, int resolution) {
    auto crossBound = [](glm::dvec3 a, glm::dvec3 b, double coord) {
        const double la = glm::length(a), lb = glm::length(b);
        return EPS * (coord * (la + lb) + 4.0 * la * lb);
    };
    glm::dvec3 p[3], u[3];
    double pMax = 0, uMax = 0;
    for (int k = 0; k < 3; ++k) {
        p[k] = glm::dvec3(t[k].position);
        u[k] = glm::dvec3(glm::dvec2(t[k].lightmapUv) * double(resolution), 0.0);
        pMax = std::max({pMax, std::abs(p[k].x), std::abs(p[k].y), std::abs(p[k].z)});
        uMax = std::max({uMax, std::abs(u[k].x), std::abs(u[k].y)});
    }
    const double ao = 2.0 * worldArea(t), al = 2.0 * texelArea(t, resolution);
    if (!(ao > 0.0) || !(al > 0.0)) return 0.0;
    const double rel = crossBound(p[1] - p[0], p[2] - p[0], 2.0 * pMax) / ao +
                       crossBound(u[1] - u[0], u[2] - u[0], 2.0 * uMax) / al;
    return 4.0 * rel * (al / ao) + 1e-6 * (al / ao);
}

// Bound on |GPU - exact| for the position at a texel of triangle t: llvmpipe
// evaluates a0 + dadx * x + dady * y per coordinate in float (x, y up to R),
// a0 being the plane at the window origin.
double positionBound(const BakeVertex* t, const glm::vec3& p, int resolution) {
    glm::dvec2 w[3];
    for (int k = 0; k < 3; ++k)
        w[k] = glm::dvec2(detail::windowFromUv(t[k].lightmapUv.x, resolution),
                          detail::windowFromUv(t[k].lightmapUv.y, resolution));
    const glm::dvec2 d1 = w[1] - w[0], d2 = w[2] - w[0];
    const double det = d1.x * d2.y - d1.y * d2.x;
    const glm::dvec3 e1 = glm::dvec3(t[1].position - t[0].position), e2 = glm::dvec3(t[2].position - t[0].position);
    const glm::dvec3 dx = (e1 * d2.y - e2 * d1.y) / det, dy = (e2 * d1.x - e1 * d2.x) / det;
    const double grad = std::max({std::abs(dx.x), std::abs(dx.y), std::abs(dx.z), std::abs(dy.x), std::abs(dy.y),
                                  std::abs(dy.z)});
    const double pMax = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
    return 8.0 * EPS * std::sqrt(3.0) * (pMax + 4.0 * grad * resolution);
}

// Absolute bound on Eq. (3) at (x, y) when every position may be off by its
// bound (first order in the bounds, plus the same-input float slack).
double densityBound(const PositionBuffer& buffer, const std::vector<double>& posBound, int x, int y) {
    const int R = buffer.resolution;
    const double density = texelDensity(buffer, x, y);
    const glm::dvec3 p(buffer.at(x, y).position);
    const double bx = posBound[size_t(y) * R + x];
    double sum = 0.0, dsum = 0.0;
    const int dxs[4] = {1, 0, -1, 0}, dys[4] = {0, 1, 0, -1};
    for (int i = 0; i < 4; ++i) {
        const int xi = x + dxs[i], yi = y + dys[i];
        if (!buffer.mapped(xi, yi)) continue;
        const double e = glm::length(glm::dvec3(buffer.at(xi, yi).position) - p);
        const double b = bx + posBound[size_t(yi) * R + xi];
        sum += e * e;
        dsum += 2.0 * e * b + b * b;
    }
    if (!(sum > 0.0)) return 0.0;
    return density * (dsum / std::max(sum - dsum, 1e-300 + 0.5 * sum) + REL_SAME);
}

struct CrossCheck {
    size_t texels = 0, mapped = 0, idMismatches = 0, positionsOutOfBound = 0;
    double worstPositionOverBound = 0;   // max |dp| / bound
    double worstDensitySame = 0;         // Eq. (3) on the GPU buffer: max relative difference
    double worstMaxDensitySame = 0, worstImportanceSame = 0;
    double worstRatioOverBound = 0;      // Eq. (1): max |d| / bound
    double worstFullOverBound = 0;       // independent CPU pipeline: max |dI| / bound
    double worstFullRelative = 0;        // ... and the relative difference, for the record
};

double rel(double a, double b) { return a == b ? 0.0 : std::abs(a - b) / std::max(std::abs(a), std::abs(b)); }

// Runs the GPU analysis with every capture and the CPU reference (both on the
// GPU's position buffers and fully independently) and asserts agreement.
CrossCheck crossCheck(const BakeMesh& mesh, int R, const std::string& name) {
    CrossCheck c;
    auto analyzer = makeAnalyzer();
    if (!analyzer) return c;
    ImportanceCapture capture;
    capture.positionBuffers = capture.texelDensity = capture.texelTriangles = true;
    auto gpu = analyzer->analyze(mesh, R, capture);
    EXPECT_TRUE(gpu) << gpu.error();
    if (!gpu) return c;
    const RasterRules rules = analyzer->rasterRules();
    const int pages = int(mesh.pageFirstTriangle.size()) - 1;
    const size_t n = mesh.triangles.size();
    EXPECT_EQ(gpu->positionBuffers.size(), size_t(pages));
    EXPECT_EQ(gpu->importance.size(), n);
    EXPECT_TRUE(allFinite(gpu->importance.importance)) << name;
    EXPECT_TRUE(allFinite(gpu->importance.areaRatio)) << name;
    EXPECT_TRUE(allFinite(gpu->importance.maxDensity)) << name;

    // the position buffer: same texels, same triangles, positions within the interpolation bound
    std::vector<double> fullTolerance(n, 0.0);
    for (int page = 0; page < pages; ++page) {
        const PositionBuffer& g = gpu->positionBuffers[size_t(page)];
        const PositionBuffer cpu = rasterizePositionBuffer(mesh.vertices, mesh.pageFirstTriangle[size_t(page)],
                                                           mesh.pageFirstTriangle[size_t(page) + 1], R, rules);
        EXPECT_TRUE(allFinite(gpu->texelDensity[size_t(page)])) << name;
        std::vector<double> posBound(cpu.texels.size(), 0.0);
        for (size_t i = 0; i < cpu.texels.size(); ++i) {
            ++c.texels;
            EXPECT_EQ(gpu->texelTriangles[size_t(page)][i], g.texels[i].triangle);
            if (cpu.texels[i].triangle != g.texels[i].triangle) {
                ++c.idMismatches;
                continue;
            }
            if (g.texels[i].triangle == 0) continue;
            ++c.mapped;
            const BakeVertex* t = &mesh.vertices[size_t(g.texels[i].triangle - 1) * 3];
            posBound[i] = positionBound(t, cpu.texels[i].position, R);
            const double d = glm::length(glm::dvec3(cpu.texels[i].position) - glm::dvec3(g.texels[i].position));
            c.worstPositionOverBound = std::max(c.worstPositionOverBound, d / posBound[i]);
            if (d > posBound[i]) ++c.positionsOutOfBound;
        }
        // Eq. (3) per texel on identical inputs, and the bound for the independent pipeline
        std::vector<double> densityTol(cpu.texels.size(), 0.0);
        for (int y = 0; y < R; ++y)
            for (int x = 0; x < R; ++x) {
                const size_t i = size_t(y) * R + x;
                if (!g.mapped(x, y)) continue;
                c.worstDensitySame =
                    std::max(c.worstDensitySame, rel(texelDensity(g, x, y), gpu->texelDensity[size_t(page)][i]));
                if (cpu.mapped(x, y) && cpu.at(x, y).triangle == g.at(x, y).triangle)
                    densityTol[i] = densityBound(cpu, posBound, x, y);
            }
        for (uint32_t t = mesh.pageFirstTriangle[size_t(page)]; t < mesh.pageFirstTriangle[size_t(page) + 1]; ++t) {
            const BakeVertex* v = &mesh.vertices[size_t(t) * 3];
            const glm::vec2 uv[3] = {v[0].lightmapUv, v[1].lightmapUv, v[2].lightmapUv};
            rasterizeTriangle(uv, R, rules, [&](int x, int y, const glm::dvec3&) {
                fullTolerance[t] = std::max(fullTolerance[t], densityTol[size_t(y) * R + x]);
            });
        }
    }
    EXPECT_EQ(c.idMismatches, 0u) << name << ": the CPU rasterizer must see the GPU's texels";
    EXPECT_EQ(c.positionsOutOfBound, 0u) << name << ": worst |dp| / bound " << c.worstPositionOverBound;
    EXPECT_LE(c.worstDensitySame, REL_SAME) << name;

    // Eq. (1), (3), (4) on the GPU's position buffers
    const Importance same = computeImportance(mesh, R, rules, gpu->positionBuffers);
    // and the independent CPU pipeline (its own position buffers)
    const Importance cpu = computeImportance(mesh, R, rules);
    for (size_t t = 0; t < n; ++t) {
        const double g = gpu->importance.importance[t];
        c.worstMaxDensitySame = std::max(c.worstMaxDensitySame, rel(same.maxDensity[t], gpu->importance.maxDensity[t]));
        const double ratioBound = areaRatioBound(&mesh.vertices[t * 3], R);
        const double ratioDiff = std::abs(double(same.areaRatio[t]) - gpu->importance.areaRatio[t]);
        if (ratioDiff > 0) c.worstRatioOverBound = std::max(c.worstRatioOverBound, ratioDiff / ratioBound);
        EXPECT_LE(ratioDiff, ratioBound) << name << " triangle " << t << " A_l/A_o: cpu " << same.areaRatio[t]
                                         << " gpu " << gpu->importance.areaRatio[t];
        // Eq. (4): min is 1-Lipschitz, so it inherits the larger of the two bounds
        const double sameTol = std::max(REL_SAME * same.maxDensity[t], ratioBound);
        EXPECT_LE(std::abs(same.importance[t] - g), sameTol) << name << " triangle " << t;
        c.worstImportanceSame = std::max(c.worstImportanceSame, rel(same.importance[t], g));
        const double fullTol = std::max(fullTolerance[t], ratioBound) + 1e-30;
        const double fullDiff = std::abs(cpu.importance[t] - g);
        EXPECT_LE(fullDiff, fullTol) << name << " triangle " << t << ": cpu " << cpu.importance[t] << " gpu " << g;
        EXPECT_LE(std::abs(cpu.maxDensity[t] - gpu->importance.maxDensity[t]), fullTolerance[t] + 1e-30)
            << name << " triangle " << t;
        c.worstFullOverBound = std::max(c.worstFullOverBound, fullDiff / fullTol);
        c.worstFullRelative = std::max(c.worstFullRelative, rel(cpu.importance[t], g));
    }
    EXPECT_LE(c.worstMaxDensitySame, REL_SAME) << name;
    const ImportanceSummary s = summarize(gpu->importance);
    std::printf("[ %s ] %zu triangles, %zu of %zu texels mapped; id mismatches %zu; |dp|/bound <= %.3g; "
                "Eq.(3) same-input rel <= %.2g; I_max rel <= %.2g; Eq.(1) |d|/bound <= %.3g; I(t) same-input rel <= "
                "%.2g; independent CPU: |dI|/bound <= %.3g (rel <= %.2g); clamped %zu, zero I_max %zu\n",
                name.c_str(), n, c.mapped, c.texels, c.idMismatches, c.worstPositionOverBound, c.worstDensitySame,
                c.worstMaxDensitySame, c.worstRatioOverBound, c.worstImportanceSame, c.worstFullOverBound,
                c.worstFullRelative, s.clamped, s.zeroMaxDensity);
    return c;
}

// ---------------------------------------------------------------------------

// The CPU rasterizer must see exactly the texels llvmpipe draws, ties and
// snapping included: a grid with every vertex on a texel centre (centres on
// edges everywhere), triangles on a quarter-texel lattice, and triangles with
// arbitrary float UVs, overlapping (the last drawn wins). With any other
// fill convention this mesh gives 34-68 mismatched texels.
TEST(ImportanceGl, RasterizationMatchesTheCpuRasterizer) {
    BB_REQUIRE_GL();
    auto analyzer = makeAnalyzer();
    ASSERT_TRUE(analyzer);
    const int R = 64;
    test::MeshBuilder b;
    test::addGrid(b, glm::mat4(1.0f), 8, 8, glm::vec2(0.5f / R), glm::vec2(32.5f / R));
    std::mt19937 rng(3);
    std::uniform_int_distribution<int> lattice(0, 4 * R);
    std::uniform_real_distribution<float> any(0.0f, 1.0f);
    for (int t = 0; t < 800; ++t) {
        glm::vec3 p[3];
        glm::vec2 uv[3];
        for (int k = 0; k < 3; ++k) {
            uv[k] = t < 400 ? glm::vec2(lattice(rng), lattice(rng)) / float(4 * R) : glm::vec2(any(rng), any(rng));
            p[k] = glm::vec3(uv[k], 0.1f * float(k));
        }
        b.add(p, uv);
    }
    const BakeMesh mesh = b.finish();
    ImportanceCapture capture;
    capture.texelTriangles = true;
    auto gpu = analyzer->analyze(mesh, R, capture);
    ASSERT_TRUE(gpu) << gpu.error();
    EXPECT_EQ(analyzer->rasterRules().subpixelBits, 8);  // llvmpipe; other drivers may differ
    const PositionBuffer cpu = rasterizePositionBuffer(mesh.vertices, 0, uint32_t(mesh.triangles.size()), R,
                                                       analyzer->rasterRules());
    size_t mismatches = 0;
    for (size_t i = 0; i < cpu.texels.size(); ++i) mismatches += cpu.texels[i].triangle != gpu->texelTriangles[0][i];
    EXPECT_EQ(mismatches, 0u);
}

TEST(ImportanceGl, CpuReferenceAgreesOnCornellBox) {
    BB_REQUIRE_GL();
    crossCheck(assetMesh("assets/cornell_box/cornell_box.gltf", UvLayout::Asset, 128), 128, "cornell_box asset 128");
    crossCheck(assetMesh("assets/shared/cornell_box/CornellBox.glb", UvLayout::Pack, 256), 256,
               "shared CornellBox.glb pack 256");
}

TEST(ImportanceGl, CpuReferenceAgreesOnFurnace) {
    BB_REQUIRE_GL();
    crossCheck(assetMesh("assets/furnace/furnace.gltf", UvLayout::Asset, 128), 128, "furnace asset 128");
}

TEST(ImportanceGl, CpuReferenceAgreesOnMixedLighting) {
    BB_REQUIRE_GL();
    const std::string path = "assets/shared/mixed_lighting/MixedLightingExample.gltf";
    crossCheck(assetMesh(path, UvLayout::Pack, 256), 256, "mixed_lighting pack 256");
    crossCheck(assetMesh(path, UvLayout::Pack, 1024), 1024, "mixed_lighting pack 1024");
}

// A synthetic mesh over two pages: a rotated, scaled grid, random triangles
// with arbitrary UVs (overlaps, slivers, mirrored), and the noisy tiny grid.
TEST(ImportanceGl, CpuReferenceAgreesOnSyntheticMesh) {
    BB_REQUIRE_GL();
    const int R = 128;
    test::MeshBuilder b;
    const glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1.0f), glm::vec3(3, -2, 5)), 0.7f, glm::vec3(1, 2, 3)) *
                        glm::scale(glm::mat4(1.0f), glm::vec3(2.5f, 1.5f, 1.0f));
    test::addGrid(b, m, 12, 7, glm::vec2(0.05f, 0.1f), glm::vec2(0.55f, 0.45f), 0);
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(0.0f, 1.0f), s(-4.0f, 4.0f);
    for (int t = 0; t < 300; ++t) {
        glm::vec3 p[3];
        glm::vec2 uv[3];
        for (int k = 0; k < 3; ++k) {
            uv[k] = glm::vec2(0.6f, 0.0f) + 0.4f * glm::vec2(u(rng), u(rng));
            p[k] = glm::vec3(s(rng), s(rng), s(rng));
        }
        b.add(p, uv, 0);
    }
    test::addNoisyTinyGrid(b, 0.5f, 8, glm::vec2(10.0f, 70.0f), R, 64, 0.25f, 5, 1);
    test::addGrid(b, glm::scale(glm::mat4(1.0f), glm::vec3(4.0f)), 3, 3, glm::vec2(0.5f), glm::vec2(0.9f), 1);
    crossCheck(b.finish(2), R, "synthetic, 2 pages");
}

// A plane of known size mapped onto a known texel count: Eq. (3) gives
// exactly 1/h^2 at every texel (4/(4h^2) inside, 3/(3h^2) on edges), Eq. (1)
// gives N^2/A. The plane is rotated and scaled by its instance transform:
// the density is per world area.
TEST(ImportanceGl, UniformGridGivesTheTexelDensityEverywhere) {
    BB_REQUIRE_GL();
    auto analyzer = makeAnalyzer();
    ASSERT_TRUE(analyzer);
    const int R = 128, N = 80;           // the plane covers N x N texels
    const float side = 2.0f;             // object units; world = 3 x object
    const glm::mat4 worldFromObject = glm::rotate(glm::mat4(1.0f), 0.9f, glm::normalize(glm::vec3(1, 1, 0))) *
                                      glm::scale(glm::mat4(1.0f), glm::vec3(3.0f * side));
    test::MeshBuilder b;
    test::addGrid(b, worldFromObject, 10, 10, glm::vec2(8.0f / R), glm::vec2(float(8 + N) / R));
    const BakeMesh mesh = b.finish();
    const double expected = double(N) * N / (double(3.0f * side) * (3.0f * side));  // texels per world area
    ImportanceCapture capture;
    capture.texelDensity = capture.texelTriangles = true;
    auto gpu = analyzer->analyze(mesh, R, capture);
    ASSERT_TRUE(gpu) << gpu.error();
    size_t mapped = 0;
    for (size_t i = 0; i < gpu->texelDensity[0].size(); ++i) {
        if (!gpu->texelTriangles[0][i]) continue;
        ++mapped;
        EXPECT_NEAR(gpu->texelDensity[0][i], expected, 0.01 * expected) << "texel " << i % R << "," << i / R;
    }
    EXPECT_EQ(mapped, size_t(N) * N);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        EXPECT_NEAR(gpu->importance.importance[t], expected, 0.01 * expected) << "triangle " << t;
        EXPECT_NEAR(gpu->importance.maxDensity[t], expected, 0.01 * expected) << "triangle " << t;
        EXPECT_NEAR(gpu->importance.areaRatio[t], expected, 0.01 * expected) << "triangle " << t;
    }
}

// Supplement Figure 2 (a): tiny triangles (1/32 texel) whose UVs carry noise
// of +-1/4 texel. Eq. (1) is far above the true density (median ~30x, max
// ~240x); Eq. (4) clamps every triangle to the neighbourhood estimate, which
// stays near the truth (I_max within [0.5, 2] x true for every triangle
// that covers a texel centre; the others get 0).
TEST(ImportanceGl, NoisyTinyTrianglesAreClampedToTheNeighbourhoodEstimate) {
    BB_REQUIRE_GL();
    auto analyzer = makeAnalyzer();
    ASSERT_TRUE(analyzer);
    const int R = 64, across = 8, cells = 256;
    const float side = 1.0f;
    test::MeshBuilder b;
    test::addNoisyTinyGrid(b, side, across, glm::vec2(4.0f), R, cells, 0.25f, 7);
    const BakeMesh mesh = b.finish();
    const double truth = double(across) * across / (double(side) * side);
    auto gpu = analyzer->analyze(mesh, R);
    ASSERT_TRUE(gpu) << gpu.error();
    const Importance& imp = gpu->importance;
    std::vector<float> ratio = imp.areaRatio;
    std::sort(ratio.begin(), ratio.end());
    EXPECT_GT(ratio[ratio.size() / 2], 10.0 * truth) << "Eq. (1) alone: median far above the true density";
    EXPECT_GT(ratio.back(), 100.0 * truth);
    size_t covering = 0;
    for (size_t t = 0; t < imp.size(); ++t) {
        EXPECT_LE(imp.importance[t], 2.0 * truth) << "triangle " << t << ": A_l/A_o " << imp.areaRatio[t];
        if (imp.maxDensity[t] > 0.0f) {
            ++covering;
            EXPECT_GE(imp.maxDensity[t], 0.5 * truth) << "triangle " << t;
            EXPECT_LE(imp.maxDensity[t], 2.0 * truth) << "triangle " << t;
        }
    }
    EXPECT_GE(covering, size_t(across) * across);  // every texel centre is covered by some triangle
    const ImportanceSummary s = summarize(imp);
    EXPECT_GT(s.clamped, imp.size() * 9 / 10);
}

// Where Eq. (2) is singular, Eq. (3) is not, and nothing anywhere is NaN or
// Inf: a strip one texel high (only left/right neighbours: Eq. (2) is 0/0), a
// triangle with collinear world vertices (A_o = 0, all edge vectors
// collinear: n/0), a triangle collapsed to a point (every |e| = 0), and a
// sub-texel triangle with no neighbours.
TEST(ImportanceGl, SingularNeighbourhoodsStayFinite) {
    BB_REQUIRE_GL();
    auto analyzer = makeAnalyzer();
    ASSERT_TRUE(analyzer);
    const int R = 64;
    const float h = 0.25f;  // world units per texel along the strip
    test::MeshBuilder b;
    // strip: 20 x 1 texels at rows [4, 5), world 20h x h
    test::addGrid(b, glm::scale(glm::mat4(1.0f), glm::vec3(20 * h, h, 1.0f)), 4, 1, glm::vec2(4.0f, 4.0f) / float(R),
                  glm::vec2(24.0f, 5.0f) / float(R));
    {   // collinear world vertices, 6 x 6 texels
        const glm::vec3 p[3] = {{0, 0, 1}, {1, 1, 1}, {2, 2, 1}};
        const glm::vec2 uv[3] = {glm::vec2(10, 20) / float(R), glm::vec2(16, 20) / float(R), glm::vec2(10, 26) / float(R)};
        b.add(p, uv);
    }
    {   // collapsed to a point
        const glm::vec3 p[3] = {{5, 5, 5}, {5, 5, 5}, {5, 5, 5}};
        const glm::vec2 uv[3] = {glm::vec2(30, 30) / float(R), glm::vec2(36, 30) / float(R), glm::vec2(30, 36) / float(R)};
        b.add(p, uv);
    }
    {   // isolated, one texel centre
        const glm::vec3 p[3] = {{0, 0, 0}, {0.1f, 0, 0}, {0, 0.1f, 0}};
        const glm::vec2 uv[3] = {glm::vec2(50.3f, 50.3f) / float(R), glm::vec2(50.9f, 50.3f) / float(R),
                                 glm::vec2(50.3f, 50.9f) / float(R)};
        b.add(p, uv);
    }
    const BakeMesh mesh = b.finish();
    ImportanceCapture capture;
    capture.positionBuffers = capture.texelDensity = true;
    auto gpu = analyzer->analyze(mesh, R, capture);
    ASSERT_TRUE(gpu) << gpu.error();
    const PositionBuffer& buffer = gpu->positionBuffers[0];
    size_t eq2Singular = 0, mapped = 0;
    for (int y = 0; y < R; ++y)
        for (int x = 0; x < R; ++x) {
            const size_t i = size_t(y) * R + x;
            EXPECT_TRUE(std::isfinite(gpu->texelDensity[0][i]) && gpu->texelDensity[0][i] >= 0.0f) << x << "," << y;
            EXPECT_TRUE(std::isfinite(buffer.texels[i].position.x) && std::isfinite(buffer.texels[i].position.y) &&
                        std::isfinite(buffer.texels[i].position.z));
            if (!buffer.mapped(x, y)) continue;
            ++mapped;
            eq2Singular += !std::isfinite(texelDensityEq2(buffer, x, y));
            if (y == 4) {  // the strip: Eq. (3) = 2 / (2 h^2) inside, 1 / h^2 at its ends
                EXPECT_NEAR(gpu->texelDensity[0][i], 1.0 / (h * h), 0.01 / (h * h)) << x;
            }
        }
    EXPECT_GT(mapped, 20u);
    EXPECT_GE(eq2Singular, 20u + 1u) << "Eq. (2) must be singular on the strip and the isolated texel";
    EXPECT_TRUE(allFinite(gpu->importance.importance));
    EXPECT_TRUE(allFinite(gpu->importance.areaRatio));
    EXPECT_TRUE(allFinite(gpu->importance.maxDensity));
    const size_t strip = 8, collinear = 8, point = 9, isolated = 10;
    for (size_t t = 0; t < strip; ++t) EXPECT_NEAR(gpu->importance.importance[t], 1.0 / (h * h), 0.01 / (h * h));
    EXPECT_EQ(gpu->importance.areaRatio[collinear], MAX_AREA_RATIO);  // A_o = 0 < A_l: Eq. (4) takes I_max
    EXPECT_GT(gpu->importance.maxDensity[collinear], 0.0f);
    EXPECT_EQ(gpu->importance.importance[collinear], gpu->importance.maxDensity[collinear]);
    // every neighbour at the same position: no estimate, and A_o = 0: nothing finite to take
    EXPECT_EQ(gpu->importance.maxDensity[point], NO_DENSITY_ESTIMATE);
    EXPECT_EQ(gpu->importance.importance[point], 0.0f);
    // no neighbour: no estimate; it covers a texel centre, so it takes its own A_l / A_o
    EXPECT_EQ(gpu->importance.maxDensity[isolated], NO_DENSITY_ESTIMATE);
    EXPECT_GT(gpu->importance.areaRatio[isolated], 0.0f);
    EXPECT_EQ(gpu->importance.importance[isolated], gpu->importance.areaRatio[isolated]);
    crossCheck(mesh, R, "singular cases");
}

// The per-triangle GPU buffer holds I(t) for the tiler, and can be handed over.
TEST(ImportanceGl, ImportanceBufferHoldsEq4) {
    BB_REQUIRE_GL();
    auto analyzer = makeAnalyzer();
    ASSERT_TRUE(analyzer);
    const BakeMesh mesh = assetMesh("assets/furnace/furnace.gltf", UvLayout::Asset, 64);
    auto gpu = analyzer->analyze(mesh, 64);
    ASSERT_TRUE(gpu) << gpu.error();
    gl::Buffer buffer = analyzer->takeImportanceBuffer();
    ASSERT_TRUE(buffer);
    EXPECT_FALSE(analyzer->importanceBuffer());
    EXPECT_EQ(buffer.bytes(), int64_t(mesh.triangles.size() * 4));
    std::vector<float> onGpu(mesh.triangles.size());
    glGetNamedBufferSubData(buffer.id(), 0, GLsizeiptr(onGpu.size() * 4), onGpu.data());
    EXPECT_EQ(onGpu, gpu->importance.importance);
    EXPECT_EQ(glGetError(), GLenum(GL_NO_ERROR));
}

TEST(ImportanceGl, ResolutionAboveTheGlLimitIsAnError) {
    BB_REQUIRE_GL();
    auto analyzer = makeAnalyzer();
    ASSERT_TRUE(analyzer);
    GLint maxTex = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTex);
    test::MeshBuilder b;
    test::addGrid(b, glm::mat4(1.0f), 1, 1, glm::vec2(0.0f), glm::vec2(1.0f));
    auto r = analyzer->analyze(b.finish(), maxTex * 2);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().find('\n'), std::string::npos);
}

// ---------------------------------------------------------------------------
// CLI: `bundlebake importance SCENE -o DIR`

struct CliRun {
    int status = -1;
    std::string out, err;
};

CliRun runCli(const std::string& args) {
    const std::string dir = ::testing::TempDir();
    // per process: ctest -j runs the CLI tests side by side
    const std::string tag = std::to_string(::getpid());
    const std::string out = test::removeAtExit(dir + "/imp_cli_out_" + tag + ".txt"),
                      err = test::removeAtExit(dir + "/imp_cli_err_" + tag + ".txt");
    CliRun r;
    const std::string backend = test::defaultTestBackend() == Backend::Egl ? "egl" : "osmesa";
    const int s = std::system((std::string(BUNDLEBAKE_CLI) + " importance " + args + " --backend " + backend + " >" +
                               out + " 2>" + err).c_str());
    r.status = WIFEXITED(s) ? WEXITSTATUS(s) : -1;
    auto slurp = [](const std::string& p) {
        std::ifstream f(p);
        std::stringstream ss;
        ss << f.rdbuf();
        return ss.str();
    };
    r.out = slurp(out);
    r.err = slurp(err);
    return r;
}

TEST(ImportanceCli, WritesMapsJsonAndPrintsTheDistribution) {
    BB_REQUIRE_GL();
    namespace fs = std::filesystem;
    const std::string dir = ::testing::TempDir() + "/importance_cli";
    fs::remove_all(dir);
    CliRun r = runCli(test::sourcePath("assets/cornell_box/cornell_box.gltf") +
                   " --uv-layout asset --resolution 64 -o " + dir);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_TRUE(fs::exists(dir + "/importance_0.exr"));
    EXPECT_TRUE(fs::exists(dir + "/importance_0.png"));
    ASSERT_TRUE(fs::exists(dir + "/importance.json"));
    for (const char* word : {"min", "median", "max", "clamped", "zero I_max"})
        EXPECT_NE(r.out.find(word), std::string::npos) << word << " in:\n" << r.out;
    std::ifstream f(dir + "/importance.json");
    const nlohmann::json j = nlohmann::json::parse(f);
    EXPECT_EQ(j["triangles"].get<int>(), 32);
    EXPECT_GT(j["importance"]["max"].get<double>(), 0.0);
    EXPECT_GT(j["png"]["log10_max"].get<double>(), j["png"]["log10_min"].get<double>() - 1e-9);
    for (const auto& entry : fs::directory_iterator(dir))
        EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
}

// Every light-map-space image uses one row order: the importance map's
// mapped texels (I(t) > 0 wherever a triangle covers a texel centre) are
// exactly the light map's covered texels, row for row, in the files.
TEST(ImportanceCli, MappedTexelsAreTheLightMapsCoveredTexels) {
    BB_REQUIRE_GL();
    namespace fs = std::filesystem;
    const std::string dir = test::removeAtExit(::testing::TempDir() + "/importance_rows_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    CliRun r = runCli(test::sourcePath("assets/cornell_box/cornell_box.gltf") + " --uv-layout asset --resolution 64 -o " + dir);
    ASSERT_EQ(r.status, 0) << r.err;
    auto importance = io::readImageRgb(dir + "/importance_0.exr");
    ASSERT_TRUE(importance) << importance.error();

    BakeOptions options;
    options.directions = 1;
    auto bake = test::makeBake("assets/cornell_box/cornell_box.gltf", test::assetLayout(64), options);
    ASSERT_TRUE(bake) << bake.error;
    const LightmapPages maps = bake.baker->readLightmaps();
    ASSERT_EQ(maps.resolution, importance->width);
    ASSERT_EQ(maps.resolution, importance->height);
    const int res = maps.resolution;
    // the texels whose centre is covered: partial texels (layout/bake_mesh.h
    // texelOwners) hold no texel centre of a triangle, so no importance
    std::vector<uint8_t> partial;
    texelOwners(bake.baker->mesh(), 0, res, &partial);
    int64_t covered = 0, mismatched = 0, mismatchedIfFlipped = 0;
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) {
            const bool c = maps.covered[0][size_t(y) * res + x] != 0 && !partial[size_t(y) * res + x];
            covered += c;
            mismatched += c != (importance->pixels[size_t(y) * res + x].r > 0.0f);
            mismatchedIfFlipped += c != (importance->pixels[size_t(res - 1 - y) * res + x].r > 0.0f);
        }
    EXPECT_GT(covered, res * res / 4);
    EXPECT_EQ(mismatched, 0) << "of " << covered << " covered texels";
    // the check can fail: the Cornell box atlas is not symmetric top to bottom
    EXPECT_GT(mismatchedIfFlipped, covered / 20);
    fs::remove_all(dir);
}

TEST(ImportanceCli, BadInputIsOneLineAndNonZero) {
    BB_REQUIRE_GL();
    CliRun r = runCli(test::sourcePath("assets/does_not_exist.gltf") + " -o " + ::testing::TempDir() + "/imp_bad");
    EXPECT_NE(r.status, 0);
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    // zdm2 has no TEXCOORD_1: the asset layout refuses it with a hint
    r = runCli(test::sourcePath("assets/shared/zdm2/zdm2.glb") + " --uv-layout asset -o " + ::testing::TempDir() +
               "/imp_zdm2");
    EXPECT_NE(r.status, 0);
    EXPECT_NE(r.err.find("TEXCOORD_1"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace bb
