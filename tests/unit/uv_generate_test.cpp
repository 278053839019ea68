// Light map UV generation (engine/layout/uv_generate.h) and the layouts that
// use it: charts split at hard edges, low stretch, no overlapping charts on
// the shared scenes without TEXCOORD_1, charts >= 2 free texels apart and on
// texel boundaries of the page, the same bytes twice, instance copies.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include "layout/layout.h"
#include "layout/uv_generate.h"
#include "scene/scene.h"

namespace bb {
namespace {

std::string sourcePath(const std::string& relative) { return std::string(BUNDLEBAKE_SOURCE_DIR) + "/" + relative; }

// One mesh, one instance (identity transform), one default material.
Scene sceneOf(Mesh mesh) {
    Scene scene;
    Material m;
    m.name = "grey";
    scene.materials.push_back(m);
    scene.meshes.push_back(std::move(mesh));
    Instance inst;
    inst.name = "instance";
    inst.mesh = 0;
    inst.node = 0;
    scene.instances.push_back(inst);
    for (const Primitive& p : scene.meshes[0].primitives)
        for (const glm::vec3& x : p.positions) scene.bounds.extend(x);
    return scene;
}

// A unit cube of 8 shared vertices (smooth normals: only the geometry says
// where the hard edges are), 12 triangles counter-clockwise seen from outside.
Mesh cubeMesh() {
    Primitive p;
    p.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
    for (const glm::vec3& x : p.positions) p.normals.push_back(glm::normalize(x - glm::vec3(0.5f)));
    const uint32_t faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
    for (const auto& f : faces) p.indices.insert(p.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
    p.material = 0;
    Mesh m;
    m.name = "cube";
    m.primitives.push_back(std::move(p));
    return m;
}

// A UV sphere of radius r (rings x segments), shared vertices, smooth normals.
Mesh sphereMesh(float r, int rings, int segments) {
    Primitive p;
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j < segments; ++j) {
            const float theta = float(M_PI) * float(i) / float(rings), phi = 2.0f * float(M_PI) * float(j) / float(segments);
            const glm::vec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            p.positions.push_back(r * n);
            p.normals.push_back(n);
        }
    auto at = [&](int i, int j) { return uint32_t(i * segments + (j % segments)); };
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            // counter-clockwise seen from outside
            if (i > 0) p.indices.insert(p.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j)});
            if (i + 1 < rings) p.indices.insert(p.indices.end(), {at(i, j + 1), at(i + 1, j + 1), at(i + 1, j)});
        }
    p.material = 0;
    Mesh m;
    m.name = "sphere";
    m.primitives.push_back(std::move(p));
    return m;
}

LayoutOptions packOptions(int resolution, float density) {
    LayoutOptions o;
    o.mode = UvLayout::Pack;
    o.resolution = resolution;
    o.texelDensity = density;
    return o;
}

// Texel centres of a grid owned by each chart (-1 none, -2 two charts), from
// the triangles' generated TEXCOORD_1 and the charts of their vertices.
std::vector<int> chartOwners(const Mesh& mesh, const MeshCharts& charts, int width, int height) {
    std::vector<int> owner(size_t(width) * size_t(height), -1);
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        const Primitive& prim = mesh.primitives[p];
        for (size_t t = 0; t + 2 < prim.indices.size(); t += 3) {
            glm::dvec2 q[3];
            for (int k = 0; k < 3; ++k) q[k] = glm::dvec2(prim.uv1[prim.indices[t + size_t(k)]]) * glm::dvec2(width, height);
            const int chart = int(charts.vertexChart[p][prim.indices[t]]);
            const double area = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
            if (area == 0.0) continue;
            for (int y = std::max(0, int(std::floor(std::min({q[0].y, q[1].y, q[2].y}))));
                 y <= std::min(height - 1, int(std::ceil(std::max({q[0].y, q[1].y, q[2].y})))); ++y)
                for (int x = std::max(0, int(std::floor(std::min({q[0].x, q[1].x, q[2].x}))));
                     x <= std::min(width - 1, int(std::ceil(std::max({q[0].x, q[1].x, q[2].x})))); ++x) {
                    const glm::dvec2 c(x + 0.5, y + 0.5);
                    bool inside = true;
                    for (int k = 0; k < 3 && inside; ++k) {
                        const glm::dvec2 a = q[k], b = q[(k + 1) % 3];
                        inside = (area > 0 ? 1.0 : -1.0) * ((b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x)) >= 0.0;
                    }
                    if (!inside) continue;
                    int& o = owner[size_t(y) * size_t(width) + size_t(x)];
                    o = (o == -1 || o == chart) ? chart : -2;
                }
        }
    }
    return owner;
}

TEST(UvGenerate, CubeSplitsIntoSixFlatChartsAtItsHardEdges) {
    Scene scene = sceneOf(cubeMesh());
    const Expected<Layout> layout = computeLayout(scene, packOptions(64, 16.0f));
    ASSERT_TRUE(layout) << layout.error();
    EXPECT_EQ(layout->uv.meshes, 1u);
    EXPECT_EQ(layout->uv.charts, 6u);
    EXPECT_EQ(layout->uv.lscmCharts, 0u);
    EXPECT_NEAR(layout->uv.worstStretch, 1.0, 1e-9);
    // 8 corners, each in 3 faces' charts
    const Primitive& p = scene.meshes[0].primitives[0];
    EXPECT_EQ(p.positions.size(), 24u);
    EXPECT_EQ(p.normals.size(), 24u);
    EXPECT_EQ(p.uv1.size(), 24u);
    EXPECT_EQ(p.indices.size(), 36u);
    // six faces of exactly 16 x 16 texels, 2 texels between them
    const glm::ivec2 grid = scene.meshes[0].uv1Grid;
    EXPECT_GE(grid.x * grid.y, 6 * 16 * 16);
    EXPECT_EQ(layout->rects[0].width, grid.x);
    EXPECT_EQ(layout->rects[0].height, grid.y);
    // every texel centre of the six faces but the 16 on each face's diagonal
    // (on the edge between its two triangles: counted for neither)
    EXPECT_EQ(layout->uv.coveredTexels, 6u * (16u * 16u - 16u));
    EXPECT_EQ(measureCoverage(scene, *layout).overlapping, 0u);

    // a hard angle above 90 degrees joins faces until the cone (60) stops them
    Scene soft = sceneOf(cubeMesh());
    LayoutOptions o = packOptions(64, 16.0f);
    o.charts.hardAngleDegrees = 100.0f;
    o.charts.coneAngleDegrees = 89.0f;
    const Expected<Layout> joined = computeLayout(soft, o);
    ASSERT_TRUE(joined) << joined.error();
    EXPECT_EQ(joined->uv.charts, 6u) << "a 90-degree edge is outside an 89-degree cone";
}

TEST(UvGenerate, SphereChartsAreFewWithLowStretchAndNoOverlap) {
    Scene scene = sceneOf(sphereMesh(1.0f, 24, 48));
    const Expected<Layout> layout = computeLayout(scene, packOptions(512, 64.0f));
    ASSERT_TRUE(layout) << layout.error();
    const UvGenerationStats& uv = layout->uv;
    std::printf("[sphere] %zu charts (%zu LSCM), worst stretch %.4f, mean %.4f, %zu of %zu texels covered\n", uv.charts,
                uv.lscmCharts, uv.worstStretch, uv.meanStretch, uv.coveredTexels, uv.gridTexels);
    // a 60-degree cone cuts the sphere into a handful of caps, most by LSCM
    // (measured: 10 charts, 8 by LSCM, worst stretch 1.014)
    EXPECT_GE(uv.charts, 4u);
    EXPECT_LE(uv.charts, 16u);
    EXPECT_GE(2 * uv.lscmCharts, uv.charts);
    EXPECT_LT(uv.worstStretch, 1.15);
    EXPECT_EQ(uv.overlappingTexels, 0u);
    EXPECT_EQ(measureCoverage(scene, *layout).overlapping, 0u);
    // area 4 pi at 64 texels per unit: covered texels within 3 % of 4 pi 64^2
    const double expected = 4.0 * M_PI * 64.0 * 64.0;
    EXPECT_NEAR(double(uv.coveredTexels), expected, 0.03 * expected);
}

// living_room and zdm2 have no TEXCOORD_1: the default pack layout generates
// it. No texel centre of any page lies in two triangles; and zdm2 (58 k
// triangles) takes seconds (measured 0.2 s on the 2-core VM; bound 10 s).
void checkSharedScene(const std::string& file, int resolution) {
    auto loaded = loadScene(sourcePath(file));
    ASSERT_TRUE(loaded) << loaded.error();
    Scene& scene = *loaded;
    ASSERT_FALSE(scene.allHaveUv1());
    LayoutOptions o = packOptions(resolution, 0.0f);
    const auto t0 = std::chrono::steady_clock::now();
    const Expected<Layout> layout = computeLayout(scene, o);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_TRUE(layout) << layout.error();
    EXPECT_TRUE(scene.allHaveUv1());
    const UvGenerationStats& uv = layout->uv;
    const TexelCoverage cov = measureCoverage(scene, *layout);
    std::printf("[%s at %d] %.2f s: %zu charts (%zu LSCM), worst stretch %.4f, %.1f %% of %zu rectangle texels covered, "
                "%zu overlapping; density %.3g, %d page(s)\n",
                file.c_str(), resolution, seconds, uv.charts, uv.lscmCharts, uv.worstStretch,
                100.0 * double(uv.coveredTexels) / double(uv.gridTexels), uv.gridTexels, cov.overlapping,
                layout->texelDensity, layout->pageCount);
    EXPECT_EQ(cov.overlapping, 0u) << "texel (" << cov.x << ", " << cov.y << ") of page " << cov.page << " lies in "
                                   << cov.first << " and " << cov.second;
    EXPECT_EQ(uv.overlappingTexels, 0u);
    EXPECT_GT(cov.covered, size_t(resolution) * size_t(resolution) / 10);
    EXPECT_LT(uv.worstStretch, 1.25);
    EXPECT_LT(seconds, 10.0);
}

TEST(UvGenerate, LivingRoomChartsDoNotOverlap) {
    checkSharedScene("assets/shared/living_room/living_room.glb", 512);
    checkSharedScene("assets/shared/living_room/living_room.glb", 2048);
}

TEST(UvGenerate, Zdm2ChartsDoNotOverlap) { checkSharedScene("assets/shared/zdm2/zdm2.glb", 2048); }

// Charts keep >= 2 free texels between them (Chebyshev distance >= 3 between
// texel centres of two charts) and lie inside their rectangles, which start
// and end on whole texels.
TEST(UvGenerate, ChartsAreTwoTexelsApartOnTexelBoundaries) {
    auto loaded = loadScene(sourcePath("assets/shared/living_room/living_room.glb"));
    ASSERT_TRUE(loaded) << loaded.error();
    for (double density : {4.0, 12.0, 40.0}) {
        Mesh mesh = loaded->meshes[0];
        const MeshCharts charts = makeCharts(mesh, glm::dmat3(1.0));
        const ChartPacking pk = packCharts(charts, density, 2);
        writeUv1(mesh, charts, pk);
        ASSERT_EQ(mesh.uv1Grid, glm::ivec2(pk.width, pk.height));
        // every vertex inside its chart's rectangle
        double worstInset = 1e30;
        for (size_t p = 0; p < mesh.primitives.size(); ++p)
            for (size_t v = 0; v < mesh.primitives[p].uv1.size(); ++v) {
                const uint32_t c = charts.vertexChart[p][v];
                const glm::dvec2 texel = glm::dvec2(mesh.primitives[p].uv1[v]) * glm::dvec2(pk.width, pk.height);
                const glm::dvec2 lo = texel - glm::dvec2(pk.origin[c]), hi = glm::dvec2(pk.origin[c] + pk.size[c]) - texel;
                worstInset = std::min({worstInset, lo.x, lo.y, hi.x, hi.y});
            }
        EXPECT_GE(worstInset, -1e-3) << "density " << density;
        // texel centres of different charts at Chebyshev distance >= 3
        const std::vector<int> owner = chartOwners(mesh, charts, pk.width, pk.height);
        size_t close = 0, shared = 0, covered = 0;
        for (int y = 0; y < pk.height; ++y)
            for (int x = 0; x < pk.width; ++x) {
                const int a = owner[size_t(y) * size_t(pk.width) + size_t(x)];
                if (a == -1) continue;
                ++covered;
                if (a == -2) {
                    ++shared;
                    continue;
                }
                for (int dy = -2; dy <= 2; ++dy)
                    for (int dx = -2; dx <= 2; ++dx) {
                        const int qx = x + dx, qy = y + dy;
                        if (qx < 0 || qy < 0 || qx >= pk.width || qy >= pk.height) continue;
                        const int b = owner[size_t(qy) * size_t(pk.width) + size_t(qx)];
                        if (b >= 0 && b != a) ++close;
                    }
            }
        std::printf("[living_room cube] density %.0f: %zu charts on %dx%d, %zu texels covered\n", density,
                    charts.chartCount(), pk.width, pk.height, covered);
        EXPECT_GT(covered, 0u);
        EXPECT_EQ(shared, 0u) << "density " << density;
        EXPECT_EQ(close, 0u) << "texel pairs of two charts closer than 3 texels at density " << density;
    }

    // in the page: each generated instance's rectangle is its grid, at a whole texel
    Scene& scene = *loaded;
    const Expected<Layout> layout = computeLayout(scene, packOptions(512, 0.0f));
    ASSERT_TRUE(layout) << layout.error();
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const InstanceRect& r = layout->rects[i];
        const glm::ivec2 grid = scene.meshes[size_t(scene.instances[i].mesh)].uv1Grid;
        EXPECT_EQ(glm::ivec2(r.width, r.height), grid);
        EXPECT_NEAR(double(r.scale.x) * 512.0, grid.x, 1e-3);
        EXPECT_NEAR(double(r.scale.y) * 512.0, grid.y, 1e-3);
        EXPECT_NEAR(double(r.offset.x) * 512.0, r.x, 1e-3);
        EXPECT_NEAR(double(r.offset.y) * 512.0, r.y, 1e-3);
    }
}

TEST(UvGenerate, SameSceneSameBytes) {
    auto a = loadScene(sourcePath("assets/shared/living_room/living_room.glb"));
    auto b = loadScene(sourcePath("assets/shared/living_room/living_room.glb"));
    ASSERT_TRUE(a && b);
    ASSERT_TRUE(computeLayout(*a, packOptions(256, 0.0f)));
    ASSERT_TRUE(computeLayout(*b, packOptions(256, 0.0f)));
    for (size_t m = 0; m < a->meshes.size(); ++m)
        for (size_t p = 0; p < a->meshes[m].primitives.size(); ++p) {
            const Primitive &pa = a->meshes[m].primitives[p], &pb = b->meshes[m].primitives[p];
            ASSERT_EQ(pa.uv1.size(), pb.uv1.size());
            EXPECT_EQ(0, std::memcmp(pa.uv1.data(), pb.uv1.data(), pa.uv1.size() * sizeof(glm::vec2)));
            EXPECT_EQ(pa.indices, pb.indices);
        }
}

// --uv-layout generate replaces TEXCOORD_1 that the file has; pack keeps it.
TEST(UvGenerate, GenerateModeReplacesFileUvs) {
    auto loaded = loadScene(sourcePath("assets/cornell_box/cornell_box.gltf"));
    ASSERT_TRUE(loaded) << loaded.error();
    ASSERT_TRUE(loaded->allHaveUv1());
    Scene pack = *loaded;
    const Expected<Layout> kept = computeLayout(pack, packOptions(256, 0.0f));
    ASSERT_TRUE(kept) << kept.error();
    EXPECT_EQ(kept->uv.meshes, 0u);
    EXPECT_EQ(pack.meshes[0].uv1Grid, glm::ivec2(0));

    LayoutOptions o = packOptions(256, 0.0f);
    o.mode = UvLayout::Generate;
    Scene gen = *loaded;
    const Expected<Layout> made = computeLayout(gen, o);
    ASSERT_TRUE(made) << made.error();
    EXPECT_EQ(made->mode, UvLayout::Generate);
    EXPECT_GE(made->uv.meshes, 1u);
    for (const Instance& inst : gen.instances) EXPECT_GT(gen.meshes[size_t(inst.mesh)].uv1Grid.x, 0);
    EXPECT_EQ(measureCoverage(gen, *made).overlapping, 0u);
    // the const overload keeps the generated grids as the rectangles
    const Expected<Layout> again = computeLayout(std::as_const(gen), packOptions(256, 0.0f));
    ASSERT_TRUE(again) << again.error();
    for (size_t i = 0; i < gen.instances.size(); ++i) {
        EXPECT_EQ(again->rects[i].width, made->rects[i].width);
        EXPECT_EQ(again->rects[i].height, made->rects[i].height);
    }
}

// Two instances of one mesh at scales 1 and 2 get one copy each (uniform
// density: the large one's rectangle is about twice as wide); two at the same
// scale, one rotated, share the mesh.
TEST(UvGenerate, InstancesOfOtherSizeGetTheirOwnCopy) {
    Scene scene = sceneOf(cubeMesh());
    Instance big = scene.instances[0];
    big.name = "big";
    big.setWorldFromObject(glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(5, 0, 0)), glm::dvec3(2.0)));
    Instance turned = scene.instances[0];
    turned.name = "turned";
    turned.setWorldFromObject(glm::rotate(glm::translate(glm::dmat4(1.0), glm::dvec3(-5, 0, 0)), 0.7, glm::dvec3(0, 1, 0)));
    scene.instances.push_back(big);
    scene.instances.push_back(turned);
    const Expected<Layout> layout = computeLayout(scene, packOptions(256, 10.0f));
    ASSERT_TRUE(layout) << layout.error();
    EXPECT_EQ(layout->uv.meshes, 2u);
    EXPECT_EQ(layout->uv.copiedMeshes, 1u);
    EXPECT_EQ(scene.meshes.size(), 2u);
    EXPECT_EQ(scene.instances[0].mesh, scene.instances[2].mesh);
    EXPECT_NE(scene.instances[0].mesh, scene.instances[1].mesh);
    EXPECT_EQ(layout->uv.charts, 12u);
    const InstanceRect &small = layout->rects[0], &large = layout->rects[1];
    // faces of 10 and 20 texels, 2 between: the gaps weigh more in the small one
    const double ratio = double(large.width * large.height) / double(small.width * small.height);
    EXPECT_GT(ratio, 3.0);
    EXPECT_LT(ratio, 4.0);
    EXPECT_EQ(measureCoverage(scene, *layout).overlapping, 0u);
    // every face's texel centres but those on its diagonal
    EXPECT_EQ(layout->uv.coveredTexels, 2u * 6u * (100u - 10u) + 6u * (400u - 20u));
}

TEST(UvGenerate, TooManyChartsForThePageIsAnError) {
    // 2 000 separate triangles at 1 texel + 2 between do not fit 16 x 16
    Primitive p;
    for (int i = 0; i < 2000; ++i) {
        const glm::vec3 o(float(i) * 2.0f, 0.0f, 0.0f);
        const uint32_t b = uint32_t(p.positions.size());
        p.positions.insert(p.positions.end(), {o, o + glm::vec3(1, 0, 0), o + glm::vec3(0, 1, 0)});
        p.normals.insert(p.normals.end(), 3, glm::vec3(0, 0, 1));
        p.indices.insert(p.indices.end(), {b, b + 1, b + 2});
    }
    p.material = 0;
    Mesh m;
    m.name = "confetti";
    m.primitives.push_back(std::move(p));
    Scene scene = sceneOf(std::move(m));
    LayoutOptions o = packOptions(16, 0.0f);
    o.padding = 1;
    const Expected<Layout> layout = computeLayout(scene, o);
    ASSERT_FALSE(layout);
    EXPECT_NE(layout.error().find("'confetti' has 2000 light map charts"), std::string::npos) << layout.error();
    EXPECT_NE(layout.error().find("--resolution"), std::string::npos) << layout.error();
}

}  // namespace
}  // namespace bb
