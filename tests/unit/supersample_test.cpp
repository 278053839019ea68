// Supersampled bakes' reduction (bake/supersample.h): a texel of the layout
// is the mean of its k x k texels, each weighted by its part of the texel's
// footprint, over those baked on the texel's own chart.
#include <gtest/gtest.h>

#include "bake/supersample.h"
#include "support/page_meshes.h"

namespace bb {
namespace {

// Two charts on an 8 x 8 page (texel units): A over x 1..4.6, y 1..5, and B
// over x 4.6..7, y 1..6 (its left edge's ends are not A's: another chart).
// Texel (4, 2) is A's (its centre 4.5 is on A): 0.6 of its square, the left
// quarters whole and a fifth of the right ones, whose half-size texels'
// centres are on B.
BakeMesh twoCharts() {
    BakeMesh m;
    addPageQuad(m, {1.0f, 1.0f}, {4.6f, 5.0f}, 8.0f);
    addPageQuad(m, {4.6f, 1.0f}, {7.0f, 6.0f}, 8.0f);
    m.pageFirstTriangle = {0, 4};
    return m;
}

TEST(Supersample, ATexelIsItsChartsHalfSizeTexelsWeightedByItsFootprint) {
    const BakeMesh mesh = twoCharts();
    const std::vector<uint32_t> charts = findLightmapCharts(mesh);
    ASSERT_NE(charts[0], charts[2]) << "A and B are two charts";
    Layout layout;
    layout.resolution = 8;
    layout.pageCount = 1;
    layout.padding = 1;

    // the texel's quarters: left ones whole, right ones 0.2 (3 of the grid's 16 columns)
    const std::vector<int32_t> owners = texelOwners(mesh, 0, 8);
    const std::vector<TexelFootprint> footprints = texelFootprints(mesh, 0, 8, owners, charts);
    const size_t t = 2 * 8 + 4;
    ASSERT_GE(owners[t], 0);
    EXPECT_EQ(charts[size_t(owners[t])], charts[0]);
    EXPECT_EQ(footprints[t].part(2, 0, 0), 256);
    EXPECT_EQ(footprints[t].part(2, 0, 1), 256);
    EXPECT_EQ(footprints[t].part(2, 1, 0), 48);
    EXPECT_EQ(footprints[t].part(2, 1, 1), 48);
    for (int q = 0; q < 16; ++q) EXPECT_EQ(footprints[2 * 8 + 2].sixteenths[size_t(q)], 64) << "a whole texel";

    // the fine bake: A's half-size texels read their x, B's 100 more
    LightmapPages fine;
    fine.resolution = 16;
    const std::vector<int32_t> fineOwners = halfTexelOwners(mesh, charts, 0, 8);
    io::ImageRgb img;
    img.width = img.height = 16;
    img.pixels.resize(256);
    std::vector<uint8_t> covered(256);
    for (size_t i = 0; i < 256; ++i) {
        if (fineOwners[i] < 0) continue;
        covered[i] = 1;
        img.pixels[i] = glm::vec3(float(i % 16) + (charts[size_t(fineOwners[i])] == charts[0] ? 0.0f : 100.0f));
    }
    fine.pages.push_back(img);
    fine.covered.push_back(covered);
    // the right quarters' half-size texels hold 0.2 of their squares of A: A's, as texel (4, 2) is
    const std::vector<int32_t> centreOwners = texelOwners(mesh, 0, 16, nullptr, kMinPartialTexelArea / 4.0);
    ASSERT_EQ(charts[size_t(centreOwners[4 * 16 + 9])], charts[2]) << "their centres are on B";
    EXPECT_EQ(charts[size_t(fineOwners[4 * 16 + 9])], charts[0]);
    EXPECT_EQ(charts[size_t(fineOwners[5 * 16 + 9])], charts[0]);
    EXPECT_EQ(charts[size_t(fineOwners[4 * 16 + 10])], charts[2]) << "B's own texel (5, 2) keeps its half-size texels";

    const LightmapPages out = reduceLightmaps(fine, mesh, charts, layout);
    ASSERT_EQ(out.resolution, 8);
    EXPECT_EQ(out.filledTexels, 0);
    EXPECT_FLOAT_EQ(out.pages[0].pixels[2 * 8 + 2].x, 4.5f) << "a whole texel: the mean of its four";
    // A's part: the left quarters (x 8) whole, the right ones (x 9) by their 48 of 256 footprint points;
    // a fine bake that gave the right quarters to B read 8, its left part's mean alone
    EXPECT_FLOAT_EQ(out.pages[0].pixels[t].x, (8.0f * 512.0f + 9.0f * 96.0f) / 608.0f);
    EXPECT_TRUE(out.covered[0][t]);
    // B's texel (5, 2): B's half-size texels 10 and 11
    EXPECT_FLOAT_EQ(out.pages[0].pixels[2 * 8 + 5].x, 110.5f);
    // padding takes its covered neighbours' mean, covered only where the layout covers
    EXPECT_FALSE(out.covered[0][0]);
    EXPECT_FLOAT_EQ(out.pages[0].pixels[0].x, out.pages[0].pixels[1 * 8 + 1].x);
}


// A bake 4 x 4 to a texel reduces in two levels (quarter-size texels to half-size
// ones, those to the texel), each weighted by the footprint's points in its
// quarters: the composition is the mean over the texel's footprint on its chart,
// to the 32 x 32 grid's resolution, and the noise estimate's per-texel weights
// (fineTexelWeights) give the same mean.
TEST(Supersample, AQuarterSizeBakeReducesToTheMeanOverTheTexelsFootprint) {
    const BakeMesh mesh = twoCharts();
    const std::vector<uint32_t> charts = findLightmapCharts(mesh);
    Layout layout;
    layout.resolution = 8;
    layout.pageCount = 1;
    layout.padding = 1;
    // the fine bake: every quarter-size texel reads its x (in quarter-size texels, centre), B's 100 more
    const std::vector<int32_t> owners = fineTexelOwners(mesh, charts, 0, 8, 4);
    ASSERT_EQ(owners.size(), size_t(32 * 32));
    LightmapPages fine;
    fine.resolution = 32;
    io::ImageRgb img;
    img.width = img.height = 32;
    img.pixels.resize(owners.size());
    std::vector<uint8_t> covered(owners.size());
    for (size_t i = 0; i < owners.size(); ++i) {
        if (owners[i] < 0) continue;
        covered[i] = 1;
        img.pixels[i] = glm::vec3(float(i % 32) + 0.5f + (charts[size_t(owners[i])] == charts[0] ? 0.0f : 100.0f));
    }
    fine.pages.push_back(img);
    fine.covered.push_back(covered);
    const LightmapPages out = reduceLightmaps(fine, mesh, charts, layout);
    ASSERT_EQ(out.resolution, 8);
    // A over x 4..4.6 of texel (4, 2): quarter-size columns 16 and 17 whole and 0.4 of 18, their mean
    // (16.5 + 17.5 + 0.4 x 18.5) / 2.4 = 17.25 (the grid counts 0.375 of 18: 17.237)
    const size_t t = 2 * 8 + 4;
    EXPECT_NEAR(out.pages[0].pixels[t].x, 17.25f, 0.02f) << "A's part's mean; with B's slice it would be over 100";
    EXPECT_FLOAT_EQ(out.pages[0].pixels[2 * 8 + 2].x, 10.0f) << "a whole texel: its sixteen's mean";
    EXPECT_FLOAT_EQ(out.pages[0].pixels[2 * 8 + 5].x, 122.0f) << "B's texel (5, 2): B's alone";
    EXPECT_EQ(out.filledTexels + out.lostTexels, 0);

    const std::vector<float> weights = fineTexelWeights(mesh, charts, 0, 8, 4);
    double sum = 0.0, weight = 0.0;
    for (int y = 8; y < 12; ++y)
        for (int x = 16; x < 20; ++x) {
            const size_t i = size_t(y) * 32 + size_t(x);
            if (weights[i] == 0.0f) continue;
            EXPECT_EQ(charts[size_t(owners[i])], charts[0]) << "only A's quarter-size texels weigh in A's texel";
            sum += weights[i] * img.pixels[i].x;
            weight += weights[i];
        }
    EXPECT_NEAR(sum / weight, out.pages[0].pixels[t].x, 1e-3);
}

// A strip B (y 3.7..3.82, x 1..7 of an 8 x 8 page) lies only in the upper
// half-size row of texel row 3, whose chart C (y 3.2..3.6) holds 0.1 of it; D
// (y 3.92..6) owns the rows above. B takes half-size texels of that row from C
// (as in HalfTexelOwners.AStripWithNoFreeHalfSizeTexelTakesOnesItsTexelsChartCanSpare),
// so 2 x 2 leaves C's part there out of its texels' values. 4 x 4 gives C the
// quarter-size texels it holds a sixteenth of first (row 14, y 3.5..3.75, of
// which B holds a fifth), B's taken half-size texels or not: every texel of
// row 3 weighs its whole footprint (its sixteenths' points), and B keeps
// quarter-size texels above (row 15).
TEST(Supersample, AQuarterSizeBakeWeighsTheWholeFootprintWhereAStripTookAHalfSizeTexel) {
    BakeMesh m;
    addPageQuad(m, {1.0f, 3.2f}, {7.0f, 3.6f}, 8.0f);
    addPageQuad(m, {1.0f, 3.7f}, {7.0f, 3.82f}, 8.0f);
    addPageQuad(m, {1.0f, 3.92f}, {7.0f, 6.0f}, 8.0f);
    m.pageFirstTriangle = {0, 6};
    const std::vector<uint32_t> charts = findLightmapCharts(m);
    const std::vector<int32_t> owners = texelOwners(m, 0, 8);
    const std::vector<TexelFootprint> footprints = texelFootprints(m, 0, 8, owners, charts);
    const std::vector<int32_t> quarterOwners = fineTexelOwners(m, charts, 0, 8, 4);
    const std::vector<float> weights2 = fineTexelWeights(m, charts, 0, 8, 2);
    const std::vector<float> weights4 = fineTexelWeights(m, charts, 0, 8, 4);
    auto weighed = [&](int k, int x) {  // the points of texel (x, 3)'s footprint its k x k texels weigh
        const std::vector<float>& w = k == 2 ? weights2 : weights4;
        double sum = 0.0;
        for (int fy = 3 * k; fy < 4 * k; ++fy)
            for (int fx = x * k; fx < (x + 1) * k; ++fx) sum += w[size_t(fy) * size_t(8 * k) + size_t(fx)];
        return sum;
    };
    int cut = 0;
    for (int x = 1; x <= 6; ++x) {
        const TexelFootprint& f = footprints[size_t(3 * 8 + x)];
        const double whole = f.part(1, 0, 0);
        ASSERT_GT(whole, 0.0);
        EXPECT_DOUBLE_EQ(weighed(4, x), whole) << "texel (" << x << ", 3)";
        cut += weighed(2, x) < whole;
        // B keeps a quarter-size texel in each texel, above C's
        int ownB = 0;
        for (int fx = 4 * x; fx < 4 * x + 4; ++fx) {
            const int32_t o = quarterOwners[size_t(15) * 32 + size_t(fx)];
            ownB += o >= 0 && charts[size_t(o)] == charts[2];
        }
        EXPECT_GE(ownB, 1) << "texel (" << x << ", 3)";
    }
    EXPECT_GE(cut, 3) << "at 2 x 2 B's half-size texels cut C's texels: the test can fail";
}

// auto: 4 where a fifth of the half-size texels are cut by a chart's edge or
// shared, 2 on wide charts, each only where its state fits half the budget
// (65 bytes a baked texel, 102 with double-sided triangles' back sides).
TEST(Supersample, AutoBakesQuarterSizeTexelsWhereChartsAreNarrowerThanTexels) {
    Layout layout;
    layout.resolution = 16;
    layout.pageCount = 1;
    BakeMesh wide;  // one chart over 1..15, texel-aligned
    addPageQuad(wide, {1.0f, 1.0f}, {15.0f, 15.0f}, 16.0f);
    wide.pageFirstTriangle = {0, 2};
    BakeMesh strips;  // strips 0.3 texel tall off the half-size texels' centres: each one cuts the two it lies in
    for (int j = 0; j < 14; ++j) addPageQuad(strips, {1.0f, 1.275f + float(j)}, {15.0f, 1.575f + float(j)}, 16.0f);
    strips.pageFirstTriangle = {0, uint32_t(strips.triangles.size())};
    const int64_t budget = 1 << 20;  // 16 x 256 texels x 65 bytes = 266 KB: fits half
    EXPECT_EQ(autoSupersample(wide, findLightmapCharts(wide), layout, budget), 2);
    EXPECT_EQ(autoSupersample(strips, findLightmapCharts(strips), layout, budget), 4);
    EXPECT_EQ(autoSupersample(strips, findLightmapCharts(strips), layout, 300 << 10), 2) << "16x the state does not fit";
    EXPECT_EQ(autoSupersample(strips, findLightmapCharts(strips), layout, 60 << 10), 1) << "nor 4x";
    // double-sided: 16 x 256 x 102 = 418 KB does not fit half of 600 KB, 266 KB would
    BakeMesh twoSided = strips;
    for (BakeTriangle& t : twoSided.triangles) t.flags |= TRIANGLE_DOUBLE_SIDED;
    EXPECT_EQ(autoSupersample(strips, findLightmapCharts(strips), layout, 600 << 10), 4);
    EXPECT_EQ(autoSupersample(twoSided, findLightmapCharts(twoSided), layout, 600 << 10), 2)
        << "the back sides' layers count";
}

}  // namespace
}  // namespace bb
