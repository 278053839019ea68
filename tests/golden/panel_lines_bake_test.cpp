// No light from the slot above a panel light that hangs just under a ceiling
// on the floor below (issue 11: the shared Cornell box's dotted lines).
//
// A 2 x 2 floor (albedo 0.5) faces a 2 x 2 ceiling (albedo 0.8) 1 above it;
// a strip of double-sided emitter (Le 1, albedo 0.8) as wide as the ceiling
// and 0.2 deep hangs a gap of 0.005 under it, 1/6 of a texel (32 texels a
// unit). The slot between the strip's back and the ceiling holds light of
// ~Le / (1 - 0.64) = 2.8 against ~0.02 on the ceiling outside, and the
// ceiling texels along the strip's two long edges straddle it: their means
// hold the slot's light, their outside parts do not. A ray from the floor
// that meets the outside part of such a texel must read the outside's light.
// Reading the texel's mean, each direction's rays that meet it draw a bright
// line across the floor (at 256 directions the floor is striped, as the
// shared Cornell box's walls were), and converged the lines are a bias: the
// floor reads 6 % bright.
//
// Measured against the reference baker (footprint means, exact visibility;
// 256 spp, whose noise on the floor's mean over 4096 texels is ~0.1 %): the
// floor's mean read +6.3 % reading texel means, +4.5 % with limited slopes
// alone, -0.03 % with the steps when this test was written. Since then the
// floor reads low, by a bias the lines do not explain (they read high): on
// 2026-12-03 -1.43 / -1.82 / -2.10 % with seeds 5 / 6 / 7 at 1024 directions
// and -1.78 % at 4096, the same before and after that day's accumulator
// change; the grazing directions' weights (update.frag, footprintPixel) move
// it by -0.15 % (-1.61 / -1.96 / -2.25 %, -1.94 %), as they do the open box's
// floor (+1.7 -> -0.1 %: from a floor the grazing directions see the black
// open sides). Not found yet (docs/design-notes.md lists it). So the lines
// are tested on their side, within 1.5 % above the reference, and the floor
// within 3 % below it. What the strip's rim leaks
// for real, the slot's light seen through the 0.005 gap, reaches the floor
// as sparse single-texel spots (the gap is narrower than a bundle pixel, so
// a pixel either sees into it or not): unbiased noise, printed, not tested.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

TEST(PanelLinesBake, FloorUnderAPanelInASlotGetsNoLightFromTheSlot) {
    BB_REQUIRE_GL();
    const float gap = 0.005f;
    Scene scene;
    const int floorMaterial = addMaterial(scene, glm::vec3(0.5f));
    const int ceilingMaterial = addMaterial(scene, glm::vec3(0.8f));
    const int panelMaterial = addMaterial(scene, glm::vec3(0.8f), glm::vec3(1.0f));
    scene.materials[size_t(panelMaterial)].doubleSided = true;
    // floor faces +y: (1,0,0) x (0,0,-1) = +y; ceiling and strip face -y
    const int floor = addQuad(scene, glm::vec3(0.0f), glm::vec3(1, 0, 0), glm::vec3(0, 0, -1), floorMaterial, "floor");
    addQuad(scene, glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(1, 0, 0), glm::vec3(0, 0, 1), ceilingMaterial, "ceiling");
    addQuad(scene, glm::vec3(0.0f, 1.0f - gap, 0.0f), glm::vec3(1, 0, 0), glm::vec3(0, 0, 0.1f), panelMaterial,
            "strip");
    auto layout = packLayout(scene, 256, 32.0f);  // 64 texels across the floor and the ceiling
    ASSERT_TRUE(layout) << layout.error();
    const InstanceRect& rect = layout->rects[size_t(floor)];
    ASSERT_EQ(rect.width, 64);
    BakeOptions options;
    options.directions = 1024;
    options.seed = 5;
    BakeStats stats;
    auto maps = bakeGpu(scene, *layout, options, nullptr, &stats);
    ASSERT_TRUE(maps) << maps.error();
    ReferenceOptions referenceOptions;
    referenceOptions.spp = 256;
    referenceOptions.seed = 9;
    auto reference = bakeReference(scene, *layout, referenceOptions);
    ASSERT_TRUE(reference) << reference.error();

    double bake = 0.0, ref = 0.0;
    int texels = 0;
    std::vector<double> value(size_t(rect.width) * rect.height, -1.0);
    forEachQuadTexel(scene, *layout, *maps, floor, [&](int page, size_t i, const glm::dvec3&, int a, int b) {
        const auto& c = maps->pages[size_t(page)].pixels[i];
        const auto& r = reference->pages[size_t(page)].pixels[i];
        value[size_t(b) * rect.width + a] = (c.r + c.g + c.b) / 3.0;
        bake += value[size_t(b) * rect.width + a];
        ref += (r.r + r.g + r.b) / 3.0;
        ++texels;
    });
    ASSERT_EQ(texels, 64 * 64);
    // lines, for the record: texels above the median of their 5 x 5 neighbours by 20 %
    int above = 0;
    for (int b = 2; b < rect.height - 2; ++b)
        for (int a = 2; a < rect.width - 2; ++a) {
            std::vector<double> around;
            for (int y = b - 2; y <= b + 2; ++y)
                for (int x = a - 2; x <= a + 2; ++x)
                    if (x != a || y != b) around.push_back(value[size_t(y) * rect.width + x]);
            std::nth_element(around.begin(), around.begin() + 12, around.end());
            above += value[size_t(b) * rect.width + a] > 1.2 * around[12];
        }
    std::printf("[panel in a slot] floor mean %.5f, reference %.5f (%+.2f %%); %d texels 20 %% above their "
                "neighbours' median; noise estimate %.2f %%; %d directions\n",
                bake / texels, ref / texels, (bake / ref - 1) * 100, above, stats.noiseRelative * 100,
                options.directions);
    EXPECT_LT(bake / ref, 1.015) << "rays that meet the ceiling beside the strip read the slot's light "
                                    "(the straddling texel's mean): lines across the floor";
    EXPECT_GT(bake / ref, 0.97) << "the floor reads darker than its known bias (-1.4 to -2.3 %, see the top)";
}

}  // namespace
}  // namespace bb::test
