// The light inside a texel at a chart's edge (issue 11: the radiance read at
// light-map resolution).
//
// A soffit 10 cm deep over a wall under a sky sees the wall's top centimetres
// the most, where the wall is darkest (the soffit shades it). The wall's top
// texel holds its top 9 cm, its next row 23 cm. A ray that lands near the
// corner read that texel's mean, brighter than the light where it landed: the
// soffit's inner texels read 18 % bright at 2048 directions against the
// reference. Along an axis with no neighbour on its chart to take a slope
// from, the bundle pass now reads the slope the update pass measured inside
// the texel from its own samples (their first moments, lightmap/meta.frag
// slopeInside): +3.0 % (the outer texels -3.3 → -1.6 %). Tolerance 8 %: the
// inner texels' spread over seeds is a few percent (+4.7 / -2.1 % at 1024
// directions, seeds 1 and 2, against a 65536-spp reference of the same).
#include <gtest/gtest.h>

#include <cstdio>

#include "layout/layout.h"
#include "reference/reference_baker.h"
#include "scene/scene.h"
#include "support/bake_helper.h"
#include "support/gl_fixture.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

constexpr int kResolution = 32;

// Quad `instance`'s TEXCOORD_1 onto the page texels [x0, x1] x [y0, y1].
void placeQuad(Scene& scene, int instance, float x0, float y0, float x1, float y1) {
    auto& uv = scene.meshes[size_t(scene.instances[size_t(instance)].mesh)].primitives[0].uv1;
    for (glm::vec2& t : uv) t = glm::vec2(x0 + (x1 - x0) * t.x, y0 + (y1 - y0) * t.y) / float(kResolution);
}

TEST(TexelSlopeBake, SoffitOverAWallReadsTheWallsLightNearTheCorner) {
    BB_REQUIRE_GL();
    Scene scene;
    const int white = addMaterial(scene, glm::vec3(0.8f)), black = addMaterial(scene, glm::vec3(0.0f));
    // the wall: x = 0 facing +x, 1 m tall under y = 0, 4 m along z; 4.4 texels
    // tall, so its top texel row holds 0.4 of a texel (9 cm)
    const int wall = addQuad(scene, {0, -0.5f, 0}, {0, 0, -2}, {0, 0.5f, 0}, white, "wall");
    placeQuad(scene, wall, 2, 2, 30, 6.4f);
    // the soffit over it, 10 cm deep, facing down: two texels across (inner x 2, outer x 3), 20 along
    const int soffit = addQuad(scene, {0.05f, 0, 0}, {0.05f, 0, 0}, {0, 0, 2}, black, "soffit");
    placeQuad(scene, soffit, 2, 10, 4, 30);
    const int ground = addQuad(scene, {10, -1, 0}, {10, 0, 0}, {0, 0, -20}, black, "ground");  // at the wall's foot
    placeQuad(scene, ground, 8, 10, 12, 14);
    auto layout = computeLayout(scene, assetLayout(kResolution));
    ASSERT_TRUE(layout) << layout.error();

    BakeOptions bo;
    bo.directions = 2048;
    bo.sky = glm::vec3(1.0f);
    bo.supersample = 2;  // the CLI's `auto` here
    auto gpu = bakeGpu(scene, *layout, bo);
    ASSERT_TRUE(gpu) << gpu.error();
    ReferenceOptions ro;
    ro.spp = 8192;
    ro.seed = 7;
    ro.sky = glm::vec3(1.0f);
    auto cpu = bakeReference(scene, *layout, ro);
    ASSERT_TRUE(cpu) << cpu.error();

    // the soffit's two columns, each over its 20 texels
    for (int column : {2, 3}) {
        double baked = 0, reference = 0;
        int texels = 0;
        for (int y = 10; y < 30; ++y) {
            const size_t i = size_t(y) * kResolution + size_t(column);
            ASSERT_TRUE(gpu->covered[0][i] && cpu->covered[0][i]) << "texel (" << column << ", " << y << ")";
            baked += gpu->pages[0].pixels[i].g;
            reference += cpu->pages[0].pixels[i].g;
            ++texels;
        }
        const double excess = baked / reference - 1.0;
        std::printf("[slope] soffit's %s texels: %.5f, reference %.5f: %+.1f %%\n", column == 2 ? "inner" : "outer",
                    baked / texels, reference / texels, 100 * excess);
        EXPECT_LT(std::abs(excess), 0.08) << (column == 2 ? "inner" : "outer") << " column";
    }
}

}  // namespace
}  // namespace bb::test
