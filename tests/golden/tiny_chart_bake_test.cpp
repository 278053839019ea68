// A chart too small for two texel centres is baked like any other: a furnace
// (a closed box facing in, Le = 1, albedo 0.5, so every surface facing into
// it reads L_lm = Le / (1 - rho) = 2) holding a small double-sided card of
// the same material (both its sides read 2 as well, and it hides nothing
// from the walls that is not also 2). At the pack layout's density the card
// is a 1 x 1 texel rectangle: its one texel centre has no covered neighbour,
// so Eq. (3) has no estimate there. Before, Eq. (4) then read I(t) = 0 ("the
// triangle covers no texel centre"), the update pass never drew the card and
// its texel stayed 0 (black texels on the chair of mixed_lighting, where
// hundreds of triangles share a texel); now I(t) = the card's own A_l / A_o.
//
// Tolerance: the furnace's own (furnace_bake_test.cpp): 2 % at 256 directions.
#include <gtest/gtest.h>

#include <cstdio>

#include "support/bake_helper.h"
#include "support/hand_scenes.h"

namespace bb::test {
namespace {

TEST(TinyChartBake, OneTexelCardInAFurnaceReadsTheFurnaceValue) {
    BB_REQUIRE_GL();
    Scene scene;
    const int material = addMaterial(scene, glm::vec3(0.5f), glm::vec3(1.0f));
    scene.materials[size_t(material)].doubleSided = true;
    addBox(scene, glm::vec3(0.0f), glm::vec3(1.0f), material, false, "furnace");
    // 0.04 x 0.04 at 16 texels a unit: 0.64 texels across, one texel centre
    const int card = addQuad(scene, glm::vec3(0.1f, 0.2f, 0.3f), glm::vec3(0.02f, 0.0f, 0.0f),
                             glm::vec3(0.0f, 0.014f, 0.014f), material, "card");
    auto layout = packLayout(scene, 128, 16.0f);
    ASSERT_TRUE(layout) << layout.error();
    const InstanceRect& r = layout->rects[size_t(card)];
    ASSERT_EQ(r.width * r.height, 1) << "the card should be one texel (" << r.width << " x " << r.height << ")";
    BakeOptions options;
    options.directions = 256;
    options.seed = 5;
    auto maps = bakeGpu(scene, *layout, options);
    ASSERT_TRUE(maps) << maps.error();
    int covered = 0;
    glm::vec3 value(0.0f);
    forEachQuadTexel(scene, *layout, *maps, card, [&](int page, size_t i, const glm::dvec3&, int, int) {
        ++covered;
        const auto& c = maps->pages[size_t(page)].pixels[i];
        value = glm::vec3(c.r, c.g, c.b);
    });
    Summary walls = summarizeCovered(*maps, layout->rects[0].page);
    std::printf("[tiny chart] card texel L_lm (%.4f, %.4f, %.4f), furnace walls' page %s\n", value.r, value.g,
                value.b, describe(walls, maps->resolution).c_str());
    ASSERT_EQ(covered, 1) << "the card's texel centre must be covered";
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(value[c], 2.0, 0.04) << "the card's lone texel was not baked (0: never updated)";
}

}  // namespace
}  // namespace bb::test
