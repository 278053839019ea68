// Light leaking through a thin wall (assets/two_rooms/two_rooms.gltf): two
// sealed 2 m rooms side by side, A (x < -0.01) lit by a 0.5 m ceiling panel
// (Le = 10), B (x > 0.01) with no emitter, separated by a 0.02 m slab with
// one face in each room. Room B is exactly 0 at every texel for any number
// of iterations (sealed), so anything above 0 there is light that went
// through the slab, or around the seams where the slab meets the floor,
// ceiling and side walls.
//
// Resolution: pack layout at 50 texels per metre (LayoutOptions::texelDensity),
// so a texel is 2 cm, the slab's thickness: the wall is one texel thick (the
// design's no-leak claim: the default bundle pixel is half a texel, 1 cm, "no
// leaks through walls >= 1 texel"). The three instances fit one 720 x 720 page.
//
// Texels are assigned to rooms on the CPU: each covered texel's centre is
// located in a triangle of the bake mesh in light map space (the nearest
// triangle when rounding on an edge puts it in none), and the triangle's world
// centroid x says the room (x > 0: room B, whose slab face is at x = +0.01).
//
// Tolerance: max L_lm over room B < 1e-3 x the mean L_lm of room A (the exact
// answer is 0; 1e-3 allows fp16 / RGBE rounding of zero sums, which is exact,
// and nothing else). 128 directions: a leak is systematic, not noise, but it
// may only open for some directions (grazing ones along the slab), so the test
// samples the sphere reasonably densely.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

// bundleResolution 0: the default (half a texel per bundle pixel).
void checkSealedRoomStaysDark(int bundleResolution, int directions,
                              BakeOptions::Tiling tiling = BakeOptions::Tiling::Adaptive) {
    BB_REQUIRE_GL();
    LayoutOptions layout = packLayout(720);
    layout.texelDensity = 50.0f;  // 2 cm texels: the slab is one texel thick
    BakeOptions options;
    options.directions = directions;
    options.seed = 1;
    options.bundleResolution = bundleResolution;
    options.tiling = tiling;
    SceneBake bake = makeBake("assets/two_rooms/two_rooms.gltf", layout, options);
    ASSERT_TRUE(bake) << bake.error;
    ASSERT_NEAR(bake.layout.texelDensity, 50.0f, 1e-3f);
    const double seconds = bakeToEnd(*bake.baker);
    LightmapPages maps = bake.baker->readLightmaps();
    const BakeMesh& mesh = bake.baker->mesh();
    const int res = maps.resolution;

    Summary roomA, roomB;
    size_t unassigned = 0, leakingTexels = 0;
    glm::vec3 worstPoint(0.0f);
    int worstPage = 0;
    for (int page = 0; page < int(maps.pages.size()); ++page) {
        std::vector<int> owner = texelTriangles(mesh, res, page);
        const auto& img = maps.pages[size_t(page)];
        const auto& cov = maps.covered[size_t(page)];
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            if (!cov[i]) continue;
            int t = owner[i];
            if (t < 0) {
                ++unassigned;
                t = nearestTriangle(mesh, res, i, page);
            }
            ASSERT_GE(t, 0);
            const glm::vec3 c = triangleCentroid(mesh, t);
            const double value = std::max({img.pixels[i].r, img.pixels[i].g, img.pixels[i].b});
            if (c.x > 0.0f) {
                if (value > roomB.max) worstPoint = c, worstPage = page;
                roomB.add(value, i);
            } else {
                roomA.add(img.pixels[i].g, i);
            }
        }
    }
    roomA.finish();
    roomB.finish();
    const double limit = 1e-3 * roomA.mean;
    glm::vec3 leakMin(1e30f), leakMax(-1e30f);
    size_t leakNearSlab = 0;
    std::string leakSamples;
    for (int page = 0; page < int(maps.pages.size()); ++page) {
        std::vector<int> owner = texelTriangles(mesh, res, page);
        const auto& img = maps.pages[size_t(page)];
        for (size_t i = 0; i < img.pixels.size(); ++i) {
            if (!maps.covered[size_t(page)][i]) continue;
            int t = owner[i] >= 0 ? owner[i] : nearestTriangle(mesh, res, i, page);
            const double value = std::max({img.pixels[i].r, img.pixels[i].g, img.pixels[i].b});
            if (triangleCentroid(mesh, t).x > 0.0f && value >= limit) {
                ++leakingTexels;
                const glm::vec3 w(texelWorldPoint(mesh, res, t, i));
                leakMin = glm::min(leakMin, w);
                leakMax = glm::max(leakMax, w);
                const float toSlab = w.x - 0.01f;  // room B's slab face
                if (toSlab < 0.05f) ++leakNearSlab;
                if (leakingTexels <= 5)
                    leakSamples += " (" + std::to_string(w.x) + ", " + std::to_string(w.y) + ", " + std::to_string(w.z) +
                                   "): " + std::to_string(value) + ";";
            }
        }
    }
    std::printf("[thin wall] bundle %.0f pixels of %.4f m; %zu page(s) of %d, %d directions, %.2f s; room A: %s; room B: %s; %zu room-B texels >= "
                "%.3g; worst on page %d in the triangle centred at (%.3f, %.3f, %.3f); %zu texels assigned by "
                "nearest triangle\n",
                bake.baker->stats().bundleResolution, bake.baker->stats().pixelSize, maps.pages.size(), res,
                options.directions, seconds, describe(roomA, res).c_str(),
                describe(roomB, res).c_str(), leakingTexels, limit, worstPage, worstPoint.x, worstPoint.y,
                worstPoint.z, unassigned);

    // both rooms are there: 24 m^2 each at 2500 texels per m^2
    ASSERT_GT(roomA.count, 50000u);
    ASSERT_GT(roomB.count, 50000u);
    // room A is lit: its area mean tends to 0.2083 (all bounces; 0.104 after one iteration)
    ASSERT_GT(roomA.mean, 0.1) << "room A is not lit: " << describe(roomA, res);
    EXPECT_LT(roomB.max, limit) << "light leaks into the sealed room B through the 2 cm (one texel) slab with "
                                << bake.baker->stats().pixelSize << " m bundle pixels: "
                                << leakingTexels << " of " << roomB.count << " room-B texels reach 1e-3 x room A's mean ("
                                << limit << "); " << describe(roomB, res) << "; worst in the triangle centred at ("
                                << worstPoint.x << ", " << worstPoint.y << ", " << worstPoint.z << "); leaking texels span (" << leakMin.x << ", " << leakMin.y << ", " << leakMin.z
                                << ") .. (" << leakMax.x << ", " << leakMax.y << ", " << leakMax.z << "), " << leakNearSlab
                                << " of them within 5 cm of the slab; first ones:" << leakSamples;
}

TEST(ThinWallBake, SealedRoomBehindOneTexelWallStaysDark) { checkSealedRoomStaysDark(0, 128); }

// The explicit emitter's direct light alone (every albedo 0) through the same
// slab at the asset atlas's 64^2 (14 cm texels: the slab is a seventh of a
// texel and of a bundle pixel): room B must stay exactly dark. The shadow
// cube maps compared distances within half a bundle pixel (3.5 cm here), so
// the texels of room B within a few centimetres of the slab saw room A's
// panel through it: up to 4 % of room A's mean on room B's floor. Tolerance:
// 1e-4 x room A's mean (0 exactly but for fp16 rounding of zero sums, which
// is exact).
TEST(ThinWallBake, NoDirectLightThroughASlabThinnerThanABundlePixel) {
    BB_REQUIRE_GL();
    BakeOptions options;
    options.directions = 16;
    SceneBake bake = makeBake("assets/two_rooms/two_rooms.gltf", assetLayout(64), options, [](Scene& scene) {
        for (Material& m : scene.materials) {
            m.albedo = glm::vec3(0.0f);
            m.albedoTexture = -1;
        }
    });
    ASSERT_TRUE(bake) << bake.error;
    bakeToEnd(*bake.baker);
    const LightmapPages maps = bake.baker->readLightmaps();
    const BakeMesh& mesh = bake.baker->mesh();
    const std::vector<int> owner = texelTriangles(mesh, maps.resolution);
    Summary roomA, roomB;
    for (size_t i = 0; i < owner.size(); ++i) {
        if (!maps.covered[0][i] || owner[i] < 0) continue;
        const auto v = maps.pages[0].pixels[i];
        (triangleCentroid(mesh, owner[i]).x > 0.0f ? roomB : roomA).add(std::max({v.r, v.g, v.b}), i);
    }
    roomA.finish();
    roomB.finish();
    std::printf("[thin slab, direct light] room A: %s; room B: %s\n", describe(roomA, maps.resolution).c_str(),
                describe(roomB, maps.resolution).c_str());
    ASSERT_GT(roomB.count, 500u);
    ASSERT_GT(roomA.mean, 0.01);
    EXPECT_LT(roomB.max, 1e-4 * roomA.mean) << describe(roomB, maps.resolution);
}
TEST(ThinWallBake, UniformTilingSealedRoomStaysDark) { checkSealedRoomStaysDark(0, 128, BakeOptions::Tiling::Uniform); }

// Direct light at a grazing angle to a floor that runs on under a wall: a
// panel light (Le 1) stands 1-5 cm over room A's floor, 0.6 m from a 4 cm
// wall 2 m tall; room B's floor, in the same plane on the wall's other side,
// sees the panel only through the wall (every albedo 0: the direct light
// alone). A shadow cube texel whose centre ray is steeper than the ray to a
// point of room B's floor meets the floors' plane in room A, short of the
// wall, and reads room A's floor there as if it were the point's own
// surface: taken as such (lib/cube_visibility.glsl reads the texel one step
// shallower there) room B's floor read up to 3.3e-4 x room A's mean.
// Tolerance: 1e-4 x room A's mean (the answer is 0).
TEST(ThinWallBake, NoDirectLightUnderAWallFromALightAtFloorLevel) {
    BB_REQUIRE_GL();
    Scene scene;
    const int black = addMaterial(scene, glm::vec3(0.0f));
    const int light = addMaterial(scene, glm::vec3(0.0f), glm::vec3(1.0f));
    const int floorA = addQuad(scene, {-0.5f, 0.0f, 0.0f}, {0.48f, 0, 0}, {0, 0, -0.5f}, black, "floor A");
    const int floorB = addQuad(scene, {0.5f, 0.0f, 0.0f}, {0.48f, 0, 0}, {0, 0, -0.5f}, black, "floor B");
    addBox(scene, {0.0f, 1.0f, 0.0f}, {0.02f, 1.0f, 0.6f}, black, true, "wall");
    addQuad(scene, {-0.6f, 0.03f, 0.0f}, {0, 0.02f, 0}, {0, 0, 0.3f}, light, "panel");
    auto layout = packLayout(scene, 256, 32.0f);
    ASSERT_TRUE(layout) << layout.error();
    BakeOptions options;
    options.directions = 16;
    options.emitterSamples = 256;
    auto maps = bakeGpu(scene, *layout, options);
    ASSERT_TRUE(maps) << maps.error();
    double sumA = 0.0, maxB = 0.0;
    int countA = 0, countB = 0;
    forEachQuadTexel(scene, *layout, *maps, floorA, [&](int page, size_t i, const glm::dvec3&, int, int) {
        sumA += maps->pages[size_t(page)].pixels[i].g;
        ++countA;
    });
    forEachQuadTexel(scene, *layout, *maps, floorB, [&](int page, size_t i, const glm::dvec3&, int, int) {
        maxB = std::max(maxB, double(maps->pages[size_t(page)].pixels[i].g));
        ++countB;
    });
    const double meanA = sumA / std::max(countA, 1);
    std::printf("[floor under a wall] room A's floor: mean %.5f over %d texels; room B's: max %.3g over %d\n", meanA,
                countA, maxB, countB);
    ASSERT_GT(countB, 500);
    ASSERT_GT(meanA, 1e-3);
    EXPECT_LT(maxB, 1e-4 * meanA);
}

}  // namespace
}  // namespace bb::test
