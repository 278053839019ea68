// No light into a closed box: six single-sided black quads facing in (each
// its own chart, its texels partial along the edges), under a sky and a sun.
// Nothing outside can be seen from inside, so every texel's L_lm is exactly 0
// (the bundles carry 0 from the black walls, the sun pass adds nothing where
// something is in the way, and zero sums store exactly).
//
// What it catches: samples whose ray runs outside the box near its edges. The
// bundle pass covers a pixel where its snapped triangle does (vertices on the
// raster's subpixel grid) and gives the node the true plane's depth there, so
// a wall nearly edge-on to d has nodes up to millimetres past the box's edge;
// a ray crossing a wall's plane at or past the wall's chart border took such a
// node, or the edge itself, for its own surface and saw the sky and the sun
// from outside (update.frag ownCrossing). A partial texel's sun sample drawn
// toward its centre, which lies off the chart, started outside the box too
// (planeSample). Before both, this test read 1 of 2400 texels lit at 256
// directions (the sky's 0.3 %) and 9 at 1024 (up to 174: 0.55 % of the sun's
// E / pi); the furnace's box, black under a sky of 1, about 1e-6 of the sky
// over its texels at 256-2048 directions.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

TEST(ClosedBoxBake, NoSkyOrSunReachesInside) {
    BB_REQUIRE_GL();
    Scene scene;
    const int black = addMaterial(scene, glm::vec3(0.0f));
    const int first = addBox(scene, glm::vec3(0.0f, 0.5f, 0.0f), glm::vec3(0.5f), black, false, "box");
    // a sun from low and from high, neither along an axis, and one nearly
    // along the box's walls (the most edge-on faces)
    scene.lights.push_back({"low sun", glm::normalize(glm::vec3(0.55f, -0.35f, -0.76f)), glm::vec3(1e5f)});
    scene.lights.push_back({"high sun", glm::normalize(glm::vec3(-0.3f, -0.9f, 0.31f)), glm::vec3(1e5f)});
    scene.lights.push_back({"grazing sun", glm::normalize(glm::vec3(0.02f, -0.015f, -1.0f)), glm::vec3(1e5f)});
    auto layout = packLayout(scene, 128, 20.0f);  // 20 x 20 texels a face
    ASSERT_TRUE(layout) << layout.error();
    for (const int directions : {256, 1024}) {
        BakeOptions options;
        options.directions = directions;
        options.seed = 1;
        options.sky = glm::vec3(1.0f);
        auto maps = bakeGpu(scene, *layout, options);
        ASSERT_TRUE(maps) << maps.error();
        Summary brightest;  // each texel's brightest channel
        int lit = 0;
        for (int face = first; face < first + 6; ++face)
            forEachQuadTexel(scene, *layout, *maps, face, [&](int page, size_t i, const glm::dvec3&, int, int) {
                const glm::vec3 v = maps->pages[size_t(page)].pixels[i];
                const double m = std::max(v.r, std::max(v.g, v.b));
                lit += m > 0.0;
                brightest.add(m, i);
            });
        brightest.finish();
        std::printf("[closed box] %d directions: %d of %zu texels lit, worst %.3g, mean %.3g\n", directions, lit,
                    brightest.count, brightest.max, brightest.mean);
        EXPECT_GT(brightest.count, 2000u);
        EXPECT_EQ(lit, 0) << directions << " directions: light inside a closed box (worst L_lm " << brightest.max
                          << "; the sun's E / pi is " << 1e5 / 3.14159265 << ", the sky's 1)";
    }
}

}  // namespace
}  // namespace bb::test
