// Importance analysis on the CPU (engine/importance/importance.h): Eq. (1),
// (2), (3), (4) of the supplement §1 on hand-made position buffers and meshes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>

#include "importance/importance.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"
#include "scene/scene.h"
#include "../support/importance_meshes.h"

namespace bb {
namespace {

bool allFinite(const std::vector<float>& v) {
    return std::all_of(v.begin(), v.end(), [](float x) { return std::isfinite(x) && x >= 0.0f; });
}

// A fully or partly mapped position buffer from a function of the texel.
template <class Fn>
PositionBuffer makeBuffer(int resolution, Fn positionOrSkip) {
    PositionBuffer b;
    b.resolution = resolution;
    b.texels.resize(size_t(resolution) * resolution);
    for (int y = 0; y < resolution; ++y)
        for (int x = 0; x < resolution; ++x) {
            glm::vec3 p;
            if (positionOrSkip(x, y, p)) b.texels[size_t(y) * resolution + x] = PositionTexel{p, 1};
        }
    return b;
}

TEST(ImportanceCpu, AreaRatioIsTexelsPerWorldArea) {
    // world legs 2 and 3 (area 3), light map legs 16 and 32 texels at R = 64 (area 256)
    BakeVertex t[3];
    t[0].position = glm::vec4(1, 1, 1, 1);
    t[1].position = glm::vec4(3, 1, 1, 1);
    t[2].position = glm::vec4(1, 1, 4, 1);
    t[0].lightmapUv = glm::vec2(0.5f, 0.5f);
    t[1].lightmapUv = glm::vec2(0.75f, 0.5f);
    t[2].lightmapUv = glm::vec2(0.5f, 1.0f);
    EXPECT_DOUBLE_EQ(worldArea(t), 3.0);
    EXPECT_DOUBLE_EQ(texelArea(t, 64), 256.0);
    EXPECT_FLOAT_EQ(areaRatio(t, 64), 256.0f / 3.0f);
    // conventions that keep Eq. (1) finite
    BakeVertex flatUv[3] = {t[0], t[1], t[2]};
    flatUv[2].lightmapUv = glm::vec2(1.0f, 0.5f);  // collinear in the light map: no texels
    EXPECT_EQ(areaRatio(flatUv, 64), 0.0f);
    BakeVertex flatWorld[3] = {t[0], t[1], t[2]};
    flatWorld[2].position = glm::vec4(5, 1, 1, 1);  // collinear in the world
    EXPECT_EQ(areaRatio(flatWorld, 64), MAX_AREA_RATIO);
}

// The curvature term (importance.h curvatureImportance): a triangle of a
// tube of radius R (its shading normals turning by 2 sin(a / 2) over the
// chord 2 R sin(a / 2), i.e. 1 / R per unit length) asks for pixels of R / 2,
// I = (2 / (R pixelsPerTexel))^2, at most 2.5^2 x its own I(t); flat
// triangles and non-receivers (I = 0) keep theirs.
TEST(ImportanceCpu, CurvatureAsksForPixelsOfHalfTheRadiusWithinACap) {
    const double radius = 0.1, a = 0.3, ppt = 2.0;
    BakeVertex t[3];
    const glm::vec3 n0(0.0f, 1.0f, 0.0f), n1(std::sin(a), std::cos(a), 0.0f);
    t[0].position = glm::vec4(glm::vec3(radius) * n0, 1.0f);
    t[1].position = glm::vec4(glm::vec3(radius) * n1, 1.0f);
    t[2].position = glm::vec4(glm::vec3(radius) * n0 + glm::vec3(0.0f, 0.0f, 1.0f), 1.0f);
    t[0].normal = glm::vec4(n0, 0.0f);
    t[1].normal = glm::vec4(n1, 0.0f);
    t[2].normal = glm::vec4(n0, 0.0f);
    const double wanted = std::pow(2.0 / (radius * ppt), 2.0);  // 100
    EXPECT_NEAR(curvatureImportance(t, 50.0f, ppt), wanted, 1e-3 * wanted);   // raised to R / 2 pixels
    EXPECT_NEAR(curvatureImportance(t, 4.0f, ppt), 6.25 * 4.0, 1e-4);         // capped at 2.5x finer pixels
    EXPECT_EQ(curvatureImportance(t, 500.0f, ppt), 500.0f);                   // already finer
    EXPECT_EQ(curvatureImportance(t, 0.0f, ppt), 0.0f);                       // not a receiver
    for (BakeVertex& v : t) v.normal = glm::vec4(0.0f, 1.0f, 0.0f, 0.0f);   // flat
    EXPECT_EQ(curvatureImportance(t, 50.0f, ppt), 50.0f);
}

// Eq. (3) on a grid of spacing h is exactly 1/h^2 = texels per world area,
// inside (4 / 4h^2), on edges (3 / 3h^2) and in corners (2 / 2h^2).
TEST(ImportanceCpu, Eq3OnAUniformGridIsOneOverHSquared) {
    const float h = 0.37f;
    const glm::vec3 u = glm::normalize(glm::vec3(1, 2, 0)), v = glm::normalize(glm::vec3(-2, 1, 3));
    const glm::vec3 w = glm::normalize(v - glm::dot(v, u) * u);
    PositionBuffer b = makeBuffer(8, [&](int x, int y, glm::vec3& p) {
        p = glm::vec3(10, 20, 30) + h * (float(x) * u + float(y) * w);
        return true;
    });
    for (int y = 0; y < 8; ++y)
        for (int x = 0; x < 8; ++x) {
            EXPECT_NEAR(texelDensity(b, x, y), 1.0 / (h * h), 1e-4 / (h * h)) << x << "," << y;
            EXPECT_NEAR(texelDensityEq2(b, x, y), 1.0 / (h * h), 1e-4 / (h * h)) << x << "," << y;
        }
}

// Figure 1 right of the supplement: Eq. (2) divides by zero where
// consecutive neighbours are missing or their edges are collinear; Eq. (3)
// stays finite (and is 0, "no estimate", only when it is 0/0 or n/0 itself).
TEST(ImportanceCpu, Eq2IsSingularWhereEq3IsFinite) {
    const float h = 0.5f;
    // only left and right neighbours (a strip one texel high): Eq. (2) is 0/0
    PositionBuffer strip = makeBuffer(5, [&](int x, int y, glm::vec3& p) {
        p = glm::vec3(h * float(x), 0, 0);
        return y == 2;
    });
    EXPECT_TRUE(std::isnan(texelDensityEq2(strip, 2, 2)));
    EXPECT_FLOAT_EQ(texelDensity(strip, 2, 2), 1.0f / (h * h));
    // collinear neighbours (right at h, up at 2h, left at -h, down at -2h, all on one line): n/0
    PositionBuffer line = makeBuffer(3, [&](int x, int y, glm::vec3& p) {
        const int dx = x - 1, dy = y - 1;
        p = glm::vec3(h * float(dx + 2 * dy), 0, 0);
        return std::abs(dx) + std::abs(dy) <= 1;
    });
    EXPECT_TRUE(std::isinf(texelDensityEq2(line, 1, 1)));
    EXPECT_FLOAT_EQ(texelDensity(line, 1, 1), 4.0f / (10.0f * h * h));
    // every neighbour at p(x): Eq. (3) itself is n/0 -> no estimate (0), finite
    PositionBuffer point = makeBuffer(3, [&](int, int, glm::vec3& p) {
        p = glm::vec3(1, 2, 3);
        return true;
    });
    EXPECT_FALSE(std::isfinite(texelDensityEq2(point, 1, 1)));
    EXPECT_EQ(texelDensity(point, 1, 1), 0.0f);
    // no neighbour at all: 0/0 -> 0
    PositionBuffer lone = makeBuffer(3, [&](int x, int y, glm::vec3& p) {
        p = glm::vec3(0.0f);
        return x == 1 && y == 1;
    });
    EXPECT_TRUE(std::isnan(texelDensityEq2(lone, 1, 1)));
    EXPECT_EQ(texelDensity(lone, 1, 1), 0.0f);
}

// GL's rasterization rules: a region tiled by triangles whose vertices sit on
// texel centres and corners (so centres lie on shared edges and vertices) has
// each of its texel centres covered exactly once.
TEST(ImportanceCpu, RasterizerCoversEveryCentreOnce) {
    const int R = 32;
    std::mt19937 rng(1);
    std::uniform_int_distribution<int> jitter(-2, 2);
    // a 6 x 6 grid of quads over texels [4, 28)^2, inner vertices on a half-texel lattice, each quad
    // cut along a random diagonal
    const int cells = 6;
    std::vector<glm::vec2> grid((cells + 1) * (cells + 1));
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            glm::vec2 t(4.0f + 4.0f * float(i), 4.0f + 4.0f * float(j));
            if (i > 0 && i < cells && j > 0 && j < cells) t += 0.5f * glm::vec2(jitter(rng), jitter(rng));
            grid[size_t(j * (cells + 1) + i)] = t / float(R);
        }
    std::vector<int> count(size_t(R) * R, 0);
    auto draw = [&](glm::vec2 a, glm::vec2 b, glm::vec2 c) {
        const glm::vec2 uv[3] = {a, b, c};
        rasterizeTriangle(uv, R, RasterRules{}, [&](int x, int y, const glm::dvec3& bary) {
            ++count[size_t(y) * R + x];
            EXPECT_NEAR(bary.x + bary.y + bary.z, 1.0, 1e-12);
            EXPECT_GE(std::min({bary.x, bary.y, bary.z}), -1e-9);
        });
    };
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const glm::vec2 a = grid[size_t(j * (cells + 1) + i)], b = grid[size_t(j * (cells + 1) + i + 1)];
            const glm::vec2 c = grid[size_t((j + 1) * (cells + 1) + i + 1)], d = grid[size_t((j + 1) * (cells + 1) + i)];
            if ((i + j) % 2) {
                draw(a, b, c);
                draw(c, d, a);  // mixed windings: both are rasterized
            } else {
                draw(a, b, d);
                draw(b, d, c);
            }
        }
    for (int y = 0; y < R; ++y)
        for (int x = 0; x < R; ++x) {
            const bool inside = x >= 4 && x < 28 && y >= 4 && y < 28;
            EXPECT_EQ(count[size_t(y) * R + x], inside ? 1 : 0) << x << "," << y;
        }
}

// A plane of known world size mapped onto a known texel count, through the
// scene loader's structures, the layout and the bake mesh. The instance is
// scaled by 3 and rotated: the density is per *world* area.
TEST(ImportanceCpu, UniformPlaneIsTexelsPerWorldArea) {
    Scene scene;
    scene.materials.push_back(Material{});
    Primitive prim;
    const int cells = 4;
    for (int j = 0; j <= cells; ++j)
        for (int i = 0; i <= cells; ++i) {
            const glm::vec2 st(float(i) / cells, float(j) / cells);
            prim.positions.push_back(glm::vec3(st, 0.0f));
            prim.normals.push_back(glm::vec3(0, 0, 1));
            prim.uv1.push_back(0.125f + 0.5f * st);  // 32 of 64 texels across in the asset layout
        }
    for (int j = 0; j < cells; ++j)
        for (int i = 0; i < cells; ++i) {
            const uint32_t a = uint32_t(j * (cells + 1) + i), b = a + 1, c = a + cells + 2, d = a + cells + 1;
            prim.indices.insert(prim.indices.end(), {a, b, c, a, c, d});
        }
    prim.material = 0;
    scene.meshes.push_back(Mesh{"plane", {prim}});
    Instance inst;
    inst.mesh = 0;
    inst.worldFromObject = glm::rotate(glm::mat4(1.0f), 0.6f, glm::vec3(0, 1, 1)) * glm::scale(glm::mat4(1.0f), glm::vec3(3.0f));
    scene.instances.push_back(inst);

    auto check = [&](UvLayout mode, float density, const char* what) {
        LayoutOptions o;
        o.mode = mode;
        o.resolution = 64;
        o.texelDensity = density;
        auto layout = computeLayout(scene, o);
        ASSERT_TRUE(layout) << layout.error();
        const InstanceRect& r = layout->rects[0];
        const double texelsAcrossX = mode == UvLayout::Asset ? 32.0 : r.width;
        const double texelsAcrossY = mode == UvLayout::Asset ? 32.0 : r.height;
        const double expected = texelsAcrossX * texelsAcrossY / (3.0 * 3.0);
        const BakeMesh mesh = buildBakeMesh(scene, *layout);
        const Importance imp = computeImportance(mesh, 64);
        ASSERT_EQ(imp.size(), size_t(2 * cells * cells));
        for (size_t t = 0; t < imp.size(); ++t) {
            EXPECT_NEAR(imp.importance[t], expected, 0.01 * expected) << what << " triangle " << t;
            EXPECT_NEAR(imp.maxDensity[t], expected, 0.01 * expected) << what << " triangle " << t;
            EXPECT_NEAR(imp.areaRatio[t], expected, 0.01 * expected) << what << " triangle " << t;
        }
    };
    check(UvLayout::Asset, 0.0f, "asset");
    check(UvLayout::Pack, 10.5f, "pack");  // 31.5 -> 32 texels across 3 world units
}

// Supplement Figure 2 (a), on the CPU: tiny triangles (1/32 texel) with UV
// noise of +-1/4 texel. Eq. (1) is far above the true density, Eq. (4)
// brings every triangle to the neighbourhood estimate.
TEST(ImportanceCpu, NoisyTinyTrianglesAreClampedToTheNeighbourhoodEstimate) {
    const int R = 64, across = 8, cells = 256;
    test::MeshBuilder b;
    test::addNoisyTinyGrid(b, 1.0f, across, glm::vec2(4.0f), R, cells, 0.25f, 7);
    const BakeMesh mesh = b.finish();
    const double truth = double(across) * across;
    const Importance imp = computeImportance(mesh, R);
    std::vector<float> ratio = imp.areaRatio;
    std::sort(ratio.begin(), ratio.end());
    EXPECT_GT(ratio[ratio.size() / 2], 10.0 * truth);
    EXPECT_GT(ratio.back(), 100.0 * truth);
    size_t covering = 0;
    for (size_t t = 0; t < imp.size(); ++t) {
        EXPECT_LE(imp.importance[t], 2.0 * truth) << "triangle " << t;
        if (imp.maxDensity[t] > 0.0f) {
            ++covering;
            EXPECT_GE(imp.maxDensity[t], 0.5 * truth) << "triangle " << t;
            EXPECT_LE(imp.maxDensity[t], 2.0 * truth) << "triangle " << t;
        }
    }
    EXPECT_GE(covering, size_t(across) * across);
    // the same mesh without noise: Eq. (1) is the truth itself
    test::MeshBuilder clean;
    test::addNoisyTinyGrid(clean, 1.0f, across, glm::vec2(4.0f), R, cells, 0.0f, 7);
    const BakeMesh cleanMesh = clean.finish();
    const Importance exact = computeImportance(cleanMesh, R);
    for (size_t t = 0; t < exact.size(); ++t) EXPECT_NEAR(exact.areaRatio[t], truth, 1e-3 * truth) << t;
}

// Degenerate inputs give finite values everywhere: a one-texel strip, a
// triangle with collinear world vertices (A_o = 0), one collapsed to a point,
// one with collinear UVs (A_l = 0), and an isolated sub-texel triangle.
TEST(ImportanceCpu, DegenerateTrianglesGiveNoNonFiniteValues) {
    const int R = 64;
    const float h = 0.25f;
    test::MeshBuilder b;
    test::addGrid(b, glm::scale(glm::mat4(1.0f), glm::vec3(20 * h, h, 1.0f)), 4, 1, glm::vec2(4.0f, 4.0f) / float(R),
                  glm::vec2(24.0f, 5.0f) / float(R));
    const glm::vec3 collinear[3] = {{0, 0, 1}, {1, 1, 1}, {2, 2, 1}};
    const glm::vec3 point[3] = {{5, 5, 5}, {5, 5, 5}, {5, 5, 5}};
    const glm::vec3 normal[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    const glm::vec2 uvA[3] = {glm::vec2(10, 20) / float(R), glm::vec2(16, 20) / float(R), glm::vec2(10, 26) / float(R)};
    const glm::vec2 uvB[3] = {glm::vec2(30, 30) / float(R), glm::vec2(36, 30) / float(R), glm::vec2(30, 36) / float(R)};
    const glm::vec2 uvLine[3] = {glm::vec2(40, 40) / float(R), glm::vec2(44, 44) / float(R), glm::vec2(48, 48) / float(R)};
    const glm::vec2 uvTiny[3] = {glm::vec2(50.3f, 50.3f) / float(R), glm::vec2(50.9f, 50.3f) / float(R),
                                 glm::vec2(50.3f, 50.9f) / float(R)};
    b.add(collinear, uvA);
    b.add(point, uvB);
    b.add(normal, uvLine);
    b.add(normal, uvTiny);
    const BakeMesh mesh = b.finish();
    const Importance imp = computeImportance(mesh, R);
    EXPECT_TRUE(allFinite(imp.importance));
    EXPECT_TRUE(allFinite(imp.areaRatio));
    EXPECT_TRUE(allFinite(imp.maxDensity));
    for (size_t t = 0; t < 8; ++t) EXPECT_NEAR(imp.importance[t], 1.0 / (h * h), 1e-3 / (h * h)) << t;
    EXPECT_EQ(imp.areaRatio[8], MAX_AREA_RATIO);
    EXPECT_GT(imp.maxDensity[8], 0.0f);
    EXPECT_EQ(imp.importance[8], imp.maxDensity[8]);
    EXPECT_EQ(imp.maxDensity[9], NO_DENSITY_ESTIMATE);  // point: every |e| = 0, no estimate,
    EXPECT_EQ(imp.importance[9], 0.0f);                 // and A_o = 0: nothing finite to take
    EXPECT_EQ(imp.areaRatio[10], 0.0f);   // no light map area
    EXPECT_EQ(imp.importance[10], 0.0f);
    // isolated: no neighbour, no estimate; it covers a texel centre, so it takes its own A_l / A_o
    EXPECT_EQ(imp.maxDensity[11], NO_DENSITY_ESTIMATE);
    EXPECT_GT(imp.areaRatio[11], 0.0f);
    EXPECT_EQ(imp.importance[11], imp.areaRatio[11]);
    const PositionBuffer buffer = rasterizePositionBuffer(mesh.vertices, 0, uint32_t(mesh.triangles.size()), R);
    for (int y = 0; y < R; ++y)
        for (int x = 0; x < R; ++x)
            if (buffer.mapped(x, y)) EXPECT_TRUE(std::isfinite(texelDensity(buffer, x, y)));
}

// The supplement's second pass credits I(x) to every triangle that covers x
// (the position buffer keeps the last one drawn); pages are independent.
TEST(ImportanceCpu, OverlapsAndPages) {
    const int R = 32;
    test::MeshBuilder b;
    // page 0: two grids on the same texels, world spacing 1/8 and 1/4 per texel; the second is drawn last
    test::addGrid(b, glm::scale(glm::mat4(1.0f), glm::vec3(1.0f)), 2, 2, glm::vec2(0.25f), glm::vec2(0.5f), 0);
    test::addGrid(b, glm::scale(glm::mat4(1.0f), glm::vec3(2.0f)), 2, 2, glm::vec2(0.25f), glm::vec2(0.5f), 0);
    // page 1: the first grid again, alone
    test::addGrid(b, glm::scale(glm::mat4(1.0f), glm::vec3(1.0f)), 2, 2, glm::vec2(0.25f), glm::vec2(0.5f), 1);
    const BakeMesh mesh = b.finish(2);
    ASSERT_EQ(mesh.pageFirstTriangle, (std::vector<uint32_t>{0, 16, 24}));
    const Importance imp = computeImportance(mesh, R);
    for (size_t t = 0; t < 16; ++t) {
        // the buffer holds the 2-unit grid (8 texels across 2 units: 16 per unit^2) for every triangle
        EXPECT_NEAR(imp.maxDensity[t], 16.0, 1e-3) << t;
    }
    for (size_t t = 0; t < 8; ++t) EXPECT_NEAR(imp.importance[t], 16.0, 1e-3) << t;  // min(64, 16): clamped
    for (size_t t = 8; t < 16; ++t) EXPECT_NEAR(imp.importance[t], 16.0, 1e-3) << t;
    for (size_t t = 16; t < 24; ++t) EXPECT_NEAR(imp.importance[t], 64.0, 1e-2) << t;  // its own page
    const ImportanceSummary s = summarize(imp);
    EXPECT_EQ(s.triangles, 24u);
    EXPECT_EQ(s.clamped, 8u);
    EXPECT_EQ(s.zeroMaxDensity, 0u);
    EXPECT_NEAR(s.min, 16.0f, 1e-3f);
    EXPECT_NEAR(s.median, 16.0f, 1e-3f);
    EXPECT_NEAR(s.max, 64.0f, 1e-2f);
    // given position buffers replace the rasterized ones
    std::vector<PositionBuffer> given = {rasterizePositionBuffer(mesh.vertices, 0, 16, R),
                                         rasterizePositionBuffer(mesh.vertices, 16, 24, R)};
    const Importance same = computeImportance(mesh, R, RasterRules{}, given);
    EXPECT_EQ(same.importance, imp.importance);
}

TEST(ImportanceCpu, SummaryCountsClampedAndZeroTriangles) {
    Importance imp;
    imp.areaRatio = {4, 1, 9, 2, 5, 100};
    imp.maxDensity = {2, 3, 0, 0, 5, 99.5f};
    for (size_t t = 0; t < 6; ++t) imp.importance.push_back(std::min(imp.areaRatio[t], imp.maxDensity[t]));
    const ImportanceSummary s = summarize(imp);
    EXPECT_EQ(s.triangles, 6u);
    EXPECT_EQ(s.clamped, 4u);                // 2 < 4, 0 < 9, 0 < 2, 99.5 < 100
    EXPECT_EQ(s.clampedBeyond1Percent, 3u);  // not 99.5 < 100
    EXPECT_EQ(s.zeroMaxDensity, 2u);
    EXPECT_EQ(s.min, 0.0f);
    EXPECT_EQ(s.median, 1.5f);               // {0, 0, 1, 2, 5, 99.5}
    EXPECT_EQ(s.max, 99.5f);
    EXPECT_EQ(s.minNonZero, 1.0f);
    EXPECT_EQ(summarize(Importance{}).triangles, 0u);
}

}  // namespace
}  // namespace bb
