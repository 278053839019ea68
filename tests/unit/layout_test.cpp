// Light map layout (pack and asset) and the bake mesh, on scenes built by hand.
#include <gtest/gtest.h>

#include <utility>

#include <cmath>
#include <limits>
#include <string>

#include <glm/gtc/matrix_transform.hpp>

#include "core/log.h"
#include "layout/bake_mesh.h"
#include "layout/layout.h"

namespace bb {
namespace {

// A w x h quad in the z = 0 plane, facing +z (counter-clockwise seen from +z),
// TEXCOORD_1 spanning [uvMin, uvMax].
Mesh quadMesh(const std::string& name, float w, float h, glm::vec2 uvMin = glm::vec2(0.0f),
              glm::vec2 uvMax = glm::vec2(1.0f), int material = 0) {
    Primitive p;
    p.positions = {{0, 0, 0}, {w, 0, 0}, {w, h, 0}, {0, h, 0}};
    p.normals.assign(4, glm::vec3(0, 0, 1));
    p.uv1 = {{uvMin.x, uvMin.y}, {uvMax.x, uvMin.y}, {uvMax.x, uvMax.y}, {uvMin.x, uvMax.y}};
    p.indices = {0, 1, 2, 0, 2, 3};
    p.material = material;
    Mesh m;
    m.name = name;
    m.primitives.push_back(std::move(p));
    return m;
}

// A quad whose TEXCOORD_1 has the same aspect as its world size, so that the
// rectangle is ceil(T*w) x ceil(T*h) at density T.
Mesh proportionalQuad(const std::string& name, float w, float h) {
    const float longest = std::max(w, h);
    return quadMesh(name, w, h, glm::vec2(0.0f), glm::vec2(w / longest, h / longest));
}

// An axis-aligned box of size s, six faces facing outward, TEXCOORD_1 in a 3x2
// grid of cells (each face gets one cell, with a small gutter).
Mesh boxMesh(const std::string& name, glm::vec3 s) {
    Primitive p;
    const glm::vec3 c[8] = {{0, 0, 0},      {s.x, 0, 0},      {s.x, s.y, 0},      {0, s.y, 0},
                            {0, 0, s.z},    {s.x, 0, s.z},    {s.x, s.y, s.z},    {0, s.y, s.z}};
    // corners counter-clockwise seen from outside, with outward normals
    const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 1, 5, 4}, {3, 7, 6, 2}, {0, 4, 7, 3}, {1, 2, 6, 5}};
    const glm::vec3 normals[6] = {{0, 0, -1}, {0, 0, 1}, {0, -1, 0}, {0, 1, 0}, {-1, 0, 0}, {1, 0, 0}};
    for (int f = 0; f < 6; ++f) {
        const glm::vec2 cell(float(f % 3) / 3.0f, float(f / 3) / 2.0f);
        const glm::vec2 size(0.3f, 0.45f);
        const glm::vec2 uv[4] = {cell, cell + glm::vec2(size.x, 0), cell + size, cell + glm::vec2(0, size.y)};
        const uint32_t base = uint32_t(p.positions.size());
        for (int k = 0; k < 4; ++k) {
            p.positions.push_back(c[faces[f][k]]);
            p.normals.push_back(normals[f]);
            p.uv1.push_back(uv[k]);
        }
        p.indices.insert(p.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    p.material = 0;
    Mesh m;
    m.name = name;
    m.primitives.push_back(std::move(p));
    return m;
}

Scene emptyScene() {
    Scene scene;
    Material m;
    m.name = "grey";
    scene.materials.push_back(m);
    return scene;
}

void addInstance(Scene& scene, int mesh, const glm::mat4& worldFromObject = glm::mat4(1.0f),
                 float texelDensity = 0.0f) {
    Instance inst;
    inst.name = "node " + std::to_string(scene.instances.size());
    inst.mesh = mesh;
    inst.node = int(scene.instances.size());
    inst.worldFromObject = worldFromObject;
    inst.texelDensity = texelDensity;
    scene.instances.push_back(inst);
}

int addMesh(Scene& scene, Mesh mesh) {
    scene.meshes.push_back(std::move(mesh));
    return int(scene.meshes.size()) - 1;
}

glm::mat4 translate(float x, float y, float z) { return glm::translate(glm::mat4(1.0f), glm::vec3(x, y, z)); }

// Quads of many sizes and aspects (world units), proportional UVs.
Scene mixedQuads(int count) {
    Scene scene = emptyScene();
    for (int i = 0; i < count; ++i) {
        const float w = 0.5f + float((i * 7) % 13) * 0.37f;
        const float h = 0.25f + float((i * 5) % 11) * 0.61f;
        const int mesh = addMesh(scene, proportionalQuad("quad" + std::to_string(i), w, h));
        addInstance(scene, mesh, translate(float(i) * 10.0f, 0.0f, 0.0f));
    }
    return scene;
}

// Metres or millimetres: a Cornell-box-like scene (five walls, two blocks).
Scene cornellBox(float unit) {
    Scene scene = emptyScene();
    const float s = 5.5f * unit;
    const int wall = addMesh(scene, quadMesh("wall", s, s));
    const glm::mat4 r90x = glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(1, 0, 0));
    const glm::mat4 r90y = glm::rotate(glm::mat4(1.0f), glm::radians(90.0f), glm::vec3(0, 1, 0));
    addInstance(scene, wall, translate(0, 0, -s));                    // back
    addInstance(scene, wall, r90x);                                   // floor
    addInstance(scene, wall, translate(0, s, 0) * r90x);              // ceiling
    addInstance(scene, wall, r90y);                                   // left
    addInstance(scene, wall, translate(s, 0, 0) * r90y);              // right
    const int tall = addMesh(scene, boxMesh("tall", glm::vec3(1.65f, 3.3f, 1.65f) * unit));
    const int small = addMesh(scene, boxMesh("short", glm::vec3(1.65f) * unit));
    addInstance(scene, tall, translate(1.0f * unit, 0, -4.0f * unit));
    addInstance(scene, small, translate(3.0f * unit, 0, -2.0f * unit));
    return scene;
}

Layout layoutOrDie(const Scene& scene, const LayoutOptions& options) {
    Expected<Layout> layout = computeLayout(scene, options);
    EXPECT_TRUE(layout.hasValue()) << (layout ? std::string() : layout.error());
    if (!layout) return Layout{};
    return std::move(layout).value();
}

// Every rectangle inside its page with `padding` free texels to the border,
// and no two padded rectangles on one page overlap (so neighbours are at
// least 2 * padding apart).
void expectValidPacking(const Layout& layout) {
    const int p = layout.padding, res = layout.resolution;
    for (size_t i = 0; i < layout.rects.size(); ++i) {
        const InstanceRect& a = layout.rects[i];
        EXPECT_GE(a.page, 0) << "rect " << i;
        EXPECT_LT(a.page, layout.pageCount) << "rect " << i;
        EXPECT_GE(a.width, 1) << "rect " << i;
        EXPECT_GE(a.height, 1) << "rect " << i;
        EXPECT_GE(a.x, p) << "rect " << i;
        EXPECT_GE(a.y, p) << "rect " << i;
        EXPECT_LE(a.x + a.width + p, res) << "rect " << i;
        EXPECT_LE(a.y + a.height + p, res) << "rect " << i;
        for (size_t j = i + 1; j < layout.rects.size(); ++j) {
            const InstanceRect& b = layout.rects[j];
            if (a.page != b.page) continue;
            const bool apart = a.x + a.width + 2 * p <= b.x || b.x + b.width + 2 * p <= a.x ||
                               a.y + a.height + 2 * p <= b.y || b.y + b.height + 2 * p <= a.y;
            EXPECT_TRUE(apart) << "rects " << i << " and " << j << " closer than 2*padding on page " << a.page;
        }
    }
    // every page in [0, pageCount) holds at least one rectangle
    std::vector<int> used(size_t(layout.pageCount), 0);
    for (const InstanceRect& r : layout.rects) ++used[size_t(r.page)];
    for (int page = 0; page < layout.pageCount; ++page) EXPECT_GT(used[size_t(page)], 0) << "page " << page;
}

bool sameRects(const Layout& a, const Layout& b) {
    if (a.rects.size() != b.rects.size() || a.pageCount != b.pageCount) return false;
    for (size_t i = 0; i < a.rects.size(); ++i) {
        const InstanceRect& x = a.rects[i];
        const InstanceRect& y = b.rects[i];
        if (x.page != y.page || x.x != y.x || x.y != y.y || x.width != y.width || x.height != y.height) return false;
    }
    return true;
}

// ---------------------------------------------------------------- pack --

TEST(LayoutPack, RectanglesInsidePageAndPaddedApart) {
    const Scene scene = mixedQuads(60);
    for (int padding : {0, 1, 2, 5}) {
        LayoutOptions options;
        options.resolution = 256;
        options.texelDensity = 6.0f;
        options.padding = padding;
        const Layout layout = layoutOrDie(scene, options);
        ASSERT_EQ(layout.rects.size(), scene.instances.size());
        EXPECT_EQ(layout.padding, padding);
        EXPECT_GE(layout.pageCount, 1);
        expectValidPacking(layout);
    }
}

TEST(LayoutPack, RectangleSizeFollowsWorldArea) {
    // proportional UVs: the rectangle is exactly ceil(T*w) x ceil(T*h)
    const Scene scene = mixedQuads(40);
    LayoutOptions options;
    options.resolution = 1024;
    options.texelDensity = 9.5f;
    const Layout layout = layoutOrDie(scene, options);
    EXPECT_FLOAT_EQ(layout.texelDensity, 9.5f);
    const double t = 9.5;
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Primitive& prim = scene.meshes[size_t(scene.instances[i].mesh)].primitives[0];
        const double w = prim.positions[2].x, h = prim.positions[2].y;
        const InstanceRect& r = layout.rects[i];
        // ceil with a little slack for float rounding of T*w at an integer
        EXPECT_GE(r.width, t * w - 1e-3) << i;
        EXPECT_LT(r.width, t * w + 1.0 + 1e-3) << i;
        EXPECT_GE(r.height, t * h - 1e-3) << i;
        EXPECT_LT(r.height, t * h + 1.0 + 1e-3) << i;
        // texel area / world area against T^2, with the bound that ceil allows
        const double ratio = double(r.width) * r.height / (w * h);
        EXPECT_GE(ratio, t * t * (1.0 - 1e-4)) << i;
        EXPECT_LE(ratio, (t * w + 1.0) * (t * h + 1.0) / (w * h) * (1.0 + 1e-4)) << i;
        EXPECT_FLOAT_EQ(r.texelDensity, 9.5f) << i;
    }
}

TEST(LayoutPack, NonProportionalUvsKeepTexelAreaPerWorldArea) {
    // a 4 x 1 quad with square UVs: the rectangle is square and its texel
    // area is T^2 * world area (the UV stretch is the asset's business)
    Scene scene = emptyScene();
    addInstance(scene, addMesh(scene, quadMesh("strip", 4.0f, 1.0f)));
    LayoutOptions options;
    options.resolution = 512;
    options.texelDensity = 10.0f;
    const Layout layout = layoutOrDie(scene, options);
    // s = T * sqrt(4 / 1) = 20 texels per UV unit
    EXPECT_EQ(layout.rects[0].width, 20);
    EXPECT_EQ(layout.rects[0].height, 20);
}

TEST(LayoutPack, InstancesOfOneMeshGetTheirOwnRectangles) {
    Scene scene = emptyScene();
    const int mesh = addMesh(scene, quadMesh("tile", 1.0f, 1.0f));
    for (int i = 0; i < 20; ++i) addInstance(scene, mesh, translate(float(i), 0, 0));
    addInstance(scene, mesh, glm::scale(glm::mat4(1.0f), glm::vec3(2.0f)));  // twice the size
    LayoutOptions options;
    options.resolution = 128;
    options.texelDensity = 8.0f;
    const Layout layout = layoutOrDie(scene, options);
    expectValidPacking(layout);  // includes: no two rectangles overlap
    for (int i = 0; i < 20; ++i) {
        EXPECT_EQ(layout.rects[size_t(i)].width, 8) << i;
        EXPECT_EQ(layout.rects[size_t(i)].height, 8) << i;
    }
    EXPECT_EQ(layout.rects[20].width, 16);
    EXPECT_EQ(layout.rects[20].height, 16);
    // distinct origins, so distinct scale/offset mappings
    for (size_t i = 0; i < layout.rects.size(); ++i)
        for (size_t j = i + 1; j < layout.rects.size(); ++j)
            EXPECT_FALSE(layout.rects[i].page == layout.rects[j].page && layout.rects[i].x == layout.rects[j].x &&
                         layout.rects[i].y == layout.rects[j].y)
                << i << " " << j;
}

TEST(LayoutPack, PerInstanceDensityOverrideWins) {
    Scene scene = emptyScene();
    const int mesh = addMesh(scene, quadMesh("tile", 2.0f, 2.0f));
    addInstance(scene, mesh);
    addInstance(scene, mesh, translate(5, 0, 0), 12.5f);
    for (float global : {4.0f, 0.0f}) {  // fixed and auto global density
        LayoutOptions options;
        options.resolution = 256;
        options.texelDensity = global;
        const Layout layout = layoutOrDie(scene, options);
        EXPECT_EQ(layout.rects[1].width, 25) << global;
        EXPECT_EQ(layout.rects[1].height, 25) << global;
        EXPECT_FLOAT_EQ(layout.rects[1].texelDensity, 12.5f) << global;
        EXPECT_FLOAT_EQ(layout.rects[0].texelDensity, layout.texelDensity) << global;
        if (global > 0.0f) {
            EXPECT_EQ(layout.rects[0].width, 8);
            EXPECT_FLOAT_EQ(layout.texelDensity, 4.0f);
        }
    }
}

TEST(LayoutPack, OverflowingSceneUsesSeveralPages) {
    // 100 quads of 2 x 2 at 10 texels per unit: 20 + 2*2 = 24 texels padded,
    // 5 per shelf and 5 shelves on a 128 page -> 25 per page, 4 pages
    Scene scene = emptyScene();
    const int mesh = addMesh(scene, quadMesh("tile", 2.0f, 2.0f));
    for (int i = 0; i < 100; ++i) addInstance(scene, mesh, translate(float(i) * 3.0f, 0, 0));
    LayoutOptions options;
    options.resolution = 128;
    options.texelDensity = 10.0f;
    options.padding = 2;
    const Layout layout = layoutOrDie(scene, options);
    EXPECT_EQ(layout.pageCount, 4);
    EXPECT_EQ(layout.texelCount(), size_t(4 * 128 * 128));
    expectValidPacking(layout);
    // mixed sizes on several pages too
    const Scene mixed = mixedQuads(80);
    options.texelDensity = 12.0f;
    const Layout mixedLayout = layoutOrDie(mixed, options);
    EXPECT_GT(mixedLayout.pageCount, 2);
    expectValidPacking(mixedLayout);
}

TEST(LayoutPack, TooLargeInstanceIsShrunkToThePage) {
    Scene scene = emptyScene();
    addInstance(scene, addMesh(scene, proportionalQuad("huge", 100.0f, 50.0f)));
    addInstance(scene, addMesh(scene, proportionalQuad("small", 1.0f, 1.0f)));
    LayoutOptions options;
    options.resolution = 64;
    options.texelDensity = 10.0f;
    options.padding = 3;
    const int warningsBefore = warningCount();
    const Layout layout = layoutOrDie(scene, options);
    EXPECT_EQ(warningCount(), warningsBefore + 1);  // one warning for the count, not one per instance
    EXPECT_EQ(layout.rects[0].width, 64 - 6);
    EXPECT_EQ(layout.rects[0].height, 29);  // ceil(58 / 2)
    EXPECT_NEAR(layout.rects[0].texelDensity, 0.58f, 1e-5f);
    EXPECT_EQ(layout.rects[1].width, 10);
    EXPECT_FLOAT_EQ(layout.rects[1].texelDensity, 10.0f);
    EXPECT_EQ(layout.pageCount, 1);
    expectValidPacking(layout);
}

TEST(LayoutPack, ZeroAreaInstanceGetsOneTexel) {
    Scene scene = emptyScene();
    const int mesh = addMesh(scene, quadMesh("tile", 1.0f, 1.0f));
    addInstance(scene, mesh, glm::scale(glm::mat4(1.0f), glm::vec3(0.0f, 1.0f, 1.0f)));  // flattened to a line
    addInstance(scene, addMesh(scene, quadMesh("flatUv", 1.0f, 1.0f, glm::vec2(0.5f), glm::vec2(0.5f))));
    addInstance(scene, mesh);
    LayoutOptions options;
    options.resolution = 64;
    options.texelDensity = 16.0f;
    const int warningsBefore = warningCount();
    const Layout layout = layoutOrDie(scene, options);
    EXPECT_EQ(warningCount(), warningsBefore + 1);
    for (size_t i : {size_t(0), size_t(1)}) {
        EXPECT_EQ(layout.rects[i].width, 1) << i;
        EXPECT_EQ(layout.rects[i].height, 1) << i;
    }
    EXPECT_EQ(layout.rects[2].width, 16);
    // the degenerate UV set maps to the middle of its 1x1 rectangle
    const InstanceRect& r = layout.rects[1];
    const glm::vec2 texel = (glm::vec2(0.5f) * r.scale + r.offset) * 64.0f;
    EXPECT_FLOAT_EQ(texel.x, float(r.x) + 0.5f);
    EXPECT_FLOAT_EQ(texel.y, float(r.y) + 0.5f);
    expectValidPacking(layout);
}

TEST(LayoutPack, ScaleOffsetMapUvBoundsOntoTheRectangle) {
    Scene scene = emptyScene();
    addInstance(scene, addMesh(scene, proportionalQuad("a", 3.0f, 1.0f)));
    addInstance(scene, addMesh(scene, quadMesh("b", 1.0f, 2.0f, glm::vec2(0.25f, 0.1f), glm::vec2(0.75f, 1.1f))));
    LayoutOptions options;
    options.resolution = 128;
    options.texelDensity = 7.0f;
    const Layout layout = layoutOrDie(scene, options);
    for (size_t i = 0; i < scene.instances.size(); ++i) {
        const Primitive& prim = scene.meshes[size_t(scene.instances[i].mesh)].primitives[0];
        const InstanceRect& r = layout.rects[i];
        const glm::vec2 uvMin = prim.uv1[0], uvMax = prim.uv1[2];
        const glm::vec2 lo = (uvMin * r.scale + r.offset) * 128.0f;
        const glm::vec2 hi = (uvMax * r.scale + r.offset) * 128.0f;
        // u to the right, v up the texel rows
        EXPECT_NEAR(lo.x, float(r.x), 1e-4f) << i;
        EXPECT_NEAR(lo.y, float(r.y), 1e-4f) << i;
        EXPECT_NEAR(hi.x, float(r.x + r.width), 1e-4f) << i;
        EXPECT_NEAR(hi.y, float(r.y + r.height), 1e-4f) << i;
    }
}

TEST(LayoutPack, AutoDensityFillsAboutOnePage) {
    for (int res : {64, 256, 1024}) {
        for (const Scene& scene : {cornellBox(1.0f), mixedQuads(30)}) {
            LayoutOptions options;
            options.resolution = res;
            options.texelDensity = 0.0f;
            const Layout layout = layoutOrDie(scene, options);
            EXPECT_EQ(layout.pageCount, 1) << res;
            EXPECT_GT(layout.texelDensity, 0.0f) << res;
            double padded = 0.0;
            for (const InstanceRect& r : layout.rects)
                padded += double(r.width + 2 * layout.padding) * (r.height + 2 * layout.padding);
            const double page = double(res) * res;
            EXPECT_LE(padded, 0.7 * page) << res;
            EXPECT_GE(padded, 0.4 * page) << res;  // not pointlessly small
            expectValidPacking(layout);
        }
    }
}

TEST(LayoutPack, AutoDensityIsUnitIndependent) {
    const Scene metres = cornellBox(1.0f);
    const Scene millimetres = cornellBox(1000.0f);
    for (int res : {128, 512, 2048}) {
        LayoutOptions options;
        options.resolution = res;
        const Layout a = layoutOrDie(metres, options);
        const Layout b = layoutOrDie(millimetres, options);
        EXPECT_TRUE(sameRects(a, b)) << res;
        EXPECT_NEAR(a.texelDensity / b.texelDensity, 1000.0, 1000.0 * 1e-5) << res;
        // and the mixed-quads scene, scaled by a whole-scene transform
        Scene big = mixedQuads(25);
        const Scene small = mixedQuads(25);
        for (Instance& inst : big.instances)
            inst.worldFromObject = glm::scale(glm::mat4(1.0f), glm::vec3(1000.0f)) * inst.worldFromObject;
        EXPECT_TRUE(sameRects(layoutOrDie(small, options), layoutOrDie(big, options))) << res;
    }
}

TEST(LayoutPack, IsDeterministic) {
    const Scene scene = mixedQuads(50);
    for (float density : {0.0f, 5.0f}) {
        LayoutOptions options;
        options.resolution = 256;
        options.texelDensity = density;
        const Layout a = layoutOrDie(scene, options);
        const Layout b = layoutOrDie(scene, options);
        EXPECT_TRUE(sameRects(a, b));
        EXPECT_EQ(a.texelDensity, b.texelDensity);
        for (size_t i = 0; i < a.rects.size(); ++i) {
            EXPECT_EQ(a.rects[i].scale, b.rects[i].scale);
            EXPECT_EQ(a.rects[i].offset, b.rects[i].offset);
        }
    }
}

TEST(LayoutPack, EqualHeightsPackInIndexOrder) {
    // ties in height are broken by instance index: rectangles go left to right
    Scene scene = emptyScene();
    const int mesh = addMesh(scene, quadMesh("tile", 1.0f, 1.0f));
    for (int i = 0; i < 4; ++i) addInstance(scene, mesh, translate(float(i), 0, 0));
    LayoutOptions options;
    options.resolution = 64;
    options.texelDensity = 4.0f;
    options.padding = 1;
    const Layout layout = layoutOrDie(scene, options);
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(layout.rects[size_t(i)].x, 1 + 6 * i);
        EXPECT_EQ(layout.rects[size_t(i)].y, 1);
    }
}

TEST(LayoutPack, MissingUv1IsGeneratedOrOnAConstSceneAOneLineError) {
    Scene scene = emptyScene();
    Mesh mesh = quadMesh("noLightmapUvs", 1.0f, 1.0f);
    mesh.primitives[0].uv1.clear();
    addInstance(scene, addMesh(scene, quadMesh("fine", 1.0f, 1.0f)));
    addInstance(scene, addMesh(scene, mesh));
    // a scene the layout may change gets generated light-map UVs (engine/layout/uv_generate.h) ...
    Scene generated = scene;
    ASSERT_TRUE(computeLayout(generated, LayoutOptions{}).hasValue());
    EXPECT_FALSE(generated.meshes[1].primitives[0].uv1.empty());
    // ... one it may not is refused with a hint
    const Expected<Layout> layout = computeLayout(std::as_const(scene), LayoutOptions{});
    ASSERT_FALSE(layout.hasValue());
    EXPECT_EQ(layout.error().find('\n'), std::string::npos) << layout.error();
    EXPECT_NE(layout.error().find("noLightmapUvs"), std::string::npos) << layout.error();
    EXPECT_NE(layout.error().find("TEXCOORD_1"), std::string::npos) << layout.error();
}

// ---------------------------------------------------------------- asset --

TEST(LayoutAsset, OnePageIdentityMapping) {
    const Scene scene = cornellBox(1.0f);
    LayoutOptions options;
    options.mode = UvLayout::Asset;
    options.resolution = 512;
    const Layout layout = layoutOrDie(scene, options);
    EXPECT_EQ(layout.mode, UvLayout::Asset);
    EXPECT_EQ(layout.pageCount, 1);
    EXPECT_EQ(layout.resolution, 512);
    ASSERT_EQ(layout.rects.size(), scene.instances.size());
    for (const InstanceRect& r : layout.rects) {
        EXPECT_EQ(r.page, 0);
        EXPECT_EQ(r.x, 0);
        EXPECT_EQ(r.y, 0);
        EXPECT_EQ(r.width, 512);
        EXPECT_EQ(r.height, 512);
        EXPECT_EQ(r.scale, glm::vec2(1.0f));
        EXPECT_EQ(r.offset, glm::vec2(0.0f));
    }
}

TEST(LayoutAsset, WarnsWhenAMeshIsInstancedMoreThanOnce) {
    Scene scene = emptyScene();
    // two charts side by side in the atlas: no overlap until 'shared' is instanced twice
    const int shared = addMesh(scene, quadMesh("shared", 1.0f, 1.0f, glm::vec2(0.5f, 0.0f), glm::vec2(1.0f, 1.0f)));
    const int single = addMesh(scene, quadMesh("single", 1.0f, 1.0f, glm::vec2(0.0f), glm::vec2(0.5f, 1.0f)));
    addInstance(scene, single);
    addInstance(scene, shared);
    LayoutOptions options;
    options.mode = UvLayout::Asset;
    int before = warningCount();
    layoutOrDie(scene, options);
    EXPECT_EQ(warningCount(), before);
    addInstance(scene, shared, translate(2, 0, 0));
    before = warningCount();
    layoutOrDie(scene, options);
    EXPECT_EQ(warningCount(), before + 1);
}

TEST(LayoutAsset, MissingUv1IsAOneLineError) {
    Scene scene = emptyScene();
    Mesh mesh = quadMesh("withoutUv1", 1.0f, 1.0f);
    mesh.primitives[0].uv1.clear();
    addInstance(scene, addMesh(scene, mesh));
    LayoutOptions options;
    options.mode = UvLayout::Asset;
    const Expected<Layout> layout = computeLayout(scene, options);
    ASSERT_FALSE(layout.hasValue());
    EXPECT_EQ(layout.error().find('\n'), std::string::npos) << layout.error();
    EXPECT_NE(layout.error().find("withoutUv1"), std::string::npos) << layout.error();
    EXPECT_NE(layout.error().find("TEXCOORD_1"), std::string::npos) << layout.error();
}

// ------------------------------------------------------------- options --

TEST(LayoutOptions, RejectsBadInputWithOneLine) {
    const Scene scene = cornellBox(1.0f);
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    struct Case { int resolution; float density; int padding; };
    const Case bad[] = {{15, 0.0f, 2},  {16385, 0.0f, 2}, {0, 0.0f, 2},  {-512, 0.0f, 2}, {512, -1.0f, 2},
                        {512, nan, 2},   {512, inf, 2},     {512, 0.0f, -1}, {16, 0.0f, 8},   {512, 0.0f, 256}};
    for (UvLayout mode : {UvLayout::Pack, UvLayout::Asset}) {
        for (const Case& c : bad) {
            LayoutOptions options;
            options.mode = mode;
            options.resolution = c.resolution;
            options.texelDensity = c.density;
            options.padding = c.padding;
            const Expected<Layout> layout = computeLayout(scene, options);
            ASSERT_FALSE(layout.hasValue()) << c.resolution << " " << c.density << " " << c.padding;
            EXPECT_FALSE(layout.error().empty());
            EXPECT_EQ(layout.error().find('\n'), std::string::npos) << layout.error();
        }
    }
    // the limits themselves are fine
    const Case good[] = {{16, 0.0f, 7}, {16384, 0.0f, 2}, {512, 0.0f, 0}};
    for (const Case& c : good) {
        LayoutOptions options;
        options.resolution = c.resolution;
        options.texelDensity = c.density;
        options.padding = c.padding;
        EXPECT_TRUE(computeLayout(scene, options).hasValue()) << c.resolution << " " << c.padding;
    }
}

TEST(LayoutOptions, RejectsBadInstanceDensity) {
    Scene scene = emptyScene();
    addInstance(scene, addMesh(scene, quadMesh("tile", 1.0f, 1.0f)), glm::mat4(1.0f), -2.0f);
    const Expected<Layout> layout = computeLayout(scene, LayoutOptions{});
    ASSERT_FALSE(layout.hasValue());
    EXPECT_EQ(layout.error().find('\n'), std::string::npos) << layout.error();
}

// ------------------------------------------------------------ bake mesh --

TEST(BakeMesh, LightmapUvsLieInTheirInstanceRectangle) {
    Scene scene = cornellBox(1.0f);
    const Scene quads = mixedQuads(40);
    for (const Mesh& m : quads.meshes) scene.meshes.push_back(m);
    for (Instance inst : quads.instances) {
        inst.mesh += 3;  // after cornellBox's 3 meshes
        scene.instances.push_back(inst);
    }
    LayoutOptions options;
    options.resolution = 128;
    options.texelDensity = 8.0f;
    const Layout layout = layoutOrDie(scene, options);
    ASSERT_GT(layout.pageCount, 1);
    const BakeMesh mesh = buildBakeMesh(scene, layout);
    size_t expected = 0;
    for (const Instance& inst : scene.instances)
        for (const Primitive& p : scene.meshes[size_t(inst.mesh)].primitives) expected += p.triangleCount();
    ASSERT_EQ(mesh.triangleCount(), expected);
    ASSERT_EQ(mesh.vertices.size(), 3 * expected);
    const float eps = 1e-3f;  // texels
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const BakeTriangle& tri = mesh.triangles[t];
        ASSERT_LT(tri.instance, scene.instances.size());
        const InstanceRect& r = layout.rects[tri.instance];
        EXPECT_EQ(tri.page, uint32_t(r.page)) << t;
        for (int k = 0; k < 3; ++k) {
            const glm::vec2 texel = mesh.vertices[3 * t + size_t(k)].lightmapUv * float(layout.resolution);
            EXPECT_GE(texel.x, float(r.x) - eps) << t;
            EXPECT_LE(texel.x, float(r.x + r.width) + eps) << t;
            EXPECT_GE(texel.y, float(r.y) - eps) << t;
            EXPECT_LE(texel.y, float(r.y + r.height) + eps) << t;
        }
    }
}

TEST(BakeMesh, SortedByPageWithFirstTriangleTable) {
    Scene scene = emptyScene();
    const int mesh = addMesh(scene, quadMesh("tile", 2.0f, 2.0f));
    for (int i = 0; i < 60; ++i) addInstance(scene, mesh, translate(float(i) * 3.0f, 0, 0));
    LayoutOptions options;
    options.resolution = 128;
    options.texelDensity = 10.0f;
    const Layout layout = layoutOrDie(scene, options);
    ASSERT_EQ(layout.pageCount, 3);
    const BakeMesh bake = buildBakeMesh(scene, layout);
    ASSERT_EQ(bake.pageFirstTriangle.size(), size_t(layout.pageCount) + 1);
    EXPECT_EQ(bake.pageFirstTriangle.front(), 0u);
    EXPECT_EQ(bake.pageFirstTriangle.back(), uint32_t(bake.triangleCount()));
    EXPECT_EQ(bake.triangleCount(), size_t(60 * 2));
    for (int page = 0; page < layout.pageCount; ++page) {
        const uint32_t begin = bake.pageFirstTriangle[size_t(page)], end = bake.pageFirstTriangle[size_t(page) + 1];
        EXPECT_LT(begin, end) << page;
        uint32_t lastInstance = 0;
        for (uint32_t t = begin; t < end; ++t) {
            EXPECT_EQ(bake.triangles[t].page, uint32_t(page)) << t;
            EXPECT_GE(bake.triangles[t].instance, lastInstance) << t;  // stable: instance order kept
            lastInstance = bake.triangles[t].instance;
        }
    }
}

TEST(BakeMesh, MirroredTransformKeepsNormalConsistentWithWinding) {
    Scene scene = emptyScene();
    const int box = addMesh(scene, boxMesh("box", glm::vec3(1.0f, 2.0f, 3.0f)));
    const glm::mat4 rotate = glm::rotate(glm::mat4(1.0f), 0.7f, glm::normalize(glm::vec3(1, 2, 3)));
    addInstance(scene, box);                                                            // identity
    addInstance(scene, box, glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 1.0f, 1.0f)));  // mirror
    addInstance(scene, box, rotate * glm::scale(glm::mat4(1.0f), glm::vec3(3.0f, -0.5f, 2.0f)));  // mirror, non-uniform
    addInstance(scene, box, translate(5, 0, 0) * glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f)));  // det < 0 point mirror
    addInstance(scene, box, glm::scale(glm::mat4(1.0f), glm::vec3(2.0f, 0.25f, 1.0f)));  // non-uniform, no mirror
    // non-uniform scale after a rotation shears the faces: only the inverse
    // transpose keeps normals perpendicular to them
    addInstance(scene, box, glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, 4.0f, 0.5f)) * rotate);
    addInstance(scene, box, glm::scale(glm::mat4(1.0f), glm::vec3(-1.0f, 4.0f, 0.5f)) * rotate);
    LayoutOptions options;
    options.resolution = 256;
    const Layout layout = layoutOrDie(scene, options);
    const BakeMesh mesh = buildBakeMesh(scene, layout);
    ASSERT_EQ(mesh.triangleCount(), size_t(7 * 12));
    for (size_t t = 0; t < mesh.triangleCount(); ++t) {
        const BakeVertex* v = &mesh.vertices[3 * t];
        const glm::vec3 face = glm::normalize(glm::cross(glm::vec3(v[1].position - v[0].position),
                                                         glm::vec3(v[2].position - v[0].position)));
        // the box centre is inside: outward normals point away from it
        const glm::vec3 centre =
            glm::vec3(scene.instances[mesh.triangles[t].instance].worldFromObject * glm::vec4(0.5f, 1.0f, 1.5f, 1.0f));
        const glm::vec3 triCentre = glm::vec3(v[0].position + v[1].position + v[2].position) / 3.0f;
        EXPECT_GT(glm::dot(face, triCentre - centre), 0.0f) << "triangle " << t << " faces inward";
        for (int k = 0; k < 3; ++k) {
            const glm::vec3 n = glm::vec3(v[k].normal);
            EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
            EXPECT_EQ(v[k].normal.w, 0.0f);
            EXPECT_EQ(v[k].position.w, 1.0f);
            // flat faces: the transformed shading normal equals the face normal
            EXPECT_NEAR(glm::dot(n, face), 1.0f, 1e-4f) << "triangle " << t << " instance "
                                                         << mesh.triangles[t].instance;
        }
    }
}

TEST(BakeMesh, AttributesFlagsAndBounds) {
    Scene scene = emptyScene();
    Material emitter;
    emitter.emission = glm::vec3(0.0f, 0.0f, 3.0f);
    Material twoSided;
    twoSided.doubleSided = true;
    scene.materials.push_back(emitter);   // 1
    scene.materials.push_back(twoSided);  // 2
    Mesh plain = quadMesh("plain", 1.0f, 1.0f);
    Mesh textured = quadMesh("textured", 1.0f, 1.0f, glm::vec2(0.0f), glm::vec2(1.0f), 1);
    textured.primitives[0].uv0 = {{0.1f, 0.2f}, {0.3f, 0.4f}, {0.5f, 0.6f}, {0.7f, 0.8f}};
    Primitive second = quadMesh("", 1.0f, 1.0f, glm::vec2(0.0f), glm::vec2(1.0f), 2).primitives[0];
    textured.primitives.push_back(second);
    addInstance(scene, addMesh(scene, plain), translate(-1, -2, -3));
    addInstance(scene, addMesh(scene, textured), translate(10, 20, 30));
    LayoutOptions options;
    options.mode = UvLayout::Asset;
    const Layout layout = layoutOrDie(scene, options);
    const BakeMesh mesh = buildBakeMesh(scene, layout);
    ASSERT_EQ(mesh.triangleCount(), size_t(6));
    ASSERT_EQ(mesh.pageFirstTriangle, (std::vector<uint32_t>{0, 6}));
    // plain: material 0, no flags, uv0 zero, asset layout -> lightmapUv == uv1
    for (size_t t = 0; t < 2; ++t) {
        EXPECT_EQ(mesh.triangles[t].material, 0u);
        EXPECT_EQ(mesh.triangles[t].flags, 0u);
        EXPECT_EQ(mesh.triangles[t].instance, 0u);
        for (int k = 0; k < 3; ++k) {
            const BakeVertex& v = mesh.vertices[3 * t + size_t(k)];
            EXPECT_EQ(v.uv0, glm::vec2(0.0f));
            EXPECT_EQ(v.lightmapUv, glm::vec2(v.position.x + 1.0f, v.position.y + 2.0f));
            EXPECT_EQ(v.position.z, -3.0f);
        }
    }
    // textured, first primitive: emissive, uv0 copied through the index
    EXPECT_EQ(mesh.triangles[2].flags, TRIANGLE_EMISSIVE);
    EXPECT_EQ(mesh.triangles[2].material, 1u);
    EXPECT_EQ(mesh.vertices[3 * 2 + 0].uv0, glm::vec2(0.1f, 0.2f));
    EXPECT_EQ(mesh.vertices[3 * 2 + 1].uv0, glm::vec2(0.3f, 0.4f));
    EXPECT_EQ(mesh.vertices[3 * 2 + 2].uv0, glm::vec2(0.5f, 0.6f));
    EXPECT_EQ(mesh.vertices[3 * 2 + 0].position, glm::vec4(10.0f, 20.0f, 30.0f, 1.0f));
    // second primitive: double-sided, no uv0 in it
    EXPECT_EQ(mesh.triangles[4].flags, TRIANGLE_DOUBLE_SIDED);
    EXPECT_EQ(mesh.triangles[5].material, 2u);
    EXPECT_EQ(mesh.vertices[3 * 4].uv0, glm::vec2(0.0f));
    EXPECT_EQ(mesh.bounds.min, glm::vec3(-1.0f, -2.0f, -3.0f));
    EXPECT_EQ(mesh.bounds.max, glm::vec3(11.0f, 21.0f, 30.0f));
}

TEST(BakeMesh, MissingNormalsFallBackToTheFaceNormal) {
    Scene scene = emptyScene();
    Mesh m = quadMesh("noNormals", 2.0f, 1.0f);
    m.primitives[0].normals.clear();
    addInstance(scene, addMesh(scene, m), glm::scale(glm::mat4(1.0f), glm::vec3(1.0f, 1.0f, -1.0f)));
    const BakeMesh mesh = buildBakeMesh(scene, layoutOrDie(scene, LayoutOptions{}));
    // mirrored through z: the front face now looks down -z, and so does the
    // normal taken from the re-ordered winding
    ASSERT_EQ(mesh.vertices.size(), size_t(6));
    for (const BakeVertex& v : mesh.vertices) EXPECT_EQ(v.normal, glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
}

}  // namespace
}  // namespace bb

namespace bb {
namespace {

// Asset charts: texel centres in two TEXCOORD_1 triangles are counted and
// reported (issue 13); --uv-overlap fail refuses the scene.
TEST(LayoutAsset, OverlappingChartsAreCountedAndCanBeRefused) {
    // two quads whose uv squares overlap in [0.25, 0.5]^2 of a 16-texel page:
    // 4 x 4 texel centres, less the 4 on both quads' diagonal (x = y: a centre
    // on an edge belongs to neither triangle)
    Scene scene = emptyScene();
    Mesh m = proportionalQuad("a", 1.0f, 1.0f);
    for (glm::vec2& uv : m.primitives[0].uv1) uv *= 0.5f;                          // [0, 0.5]^2
    Mesh n = proportionalQuad("b", 1.0f, 1.0f);
    for (glm::vec2& uv : n.primitives[0].uv1) uv = uv * 0.5f + glm::vec2(0.25f);  // [0.25, 0.75]^2
    addInstance(scene, addMesh(scene, m));
    addInstance(scene, addMesh(scene, n), translate(5, 0, 0));
    LayoutOptions o;
    o.mode = UvLayout::Asset;
    o.resolution = 16;
    auto layout = computeLayout(scene, o);
    ASSERT_TRUE(layout) << layout.error();
    EXPECT_EQ(layout->overlappingTexels, 12u);
    o.failOnOverlap = true;
    auto refused = computeLayout(scene, o);
    ASSERT_FALSE(refused);
    EXPECT_NE(refused.error().find("12 light map texel(s)"), std::string::npos) << refused.error();
    EXPECT_NE(refused.error().find("node 0 and node 1"), std::string::npos) << refused.error();
    // apart, they do not overlap (the shared diagonal of each quad counts once)
    for (glm::vec2& uv : scene.meshes[1].primitives[0].uv1) uv += glm::vec2(0.25f);  // [0.5, 1]^2
    auto apart = computeLayout(scene, o);
    ASSERT_TRUE(apart) << apart.error();
    EXPECT_EQ(apart->overlappingTexels, 0u);
}

}  // namespace
}  // namespace bb
