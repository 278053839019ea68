// `bundlebake compare` on two hand-made EXR pages with every texel compared
// (--mask none): its rel_rmse, and the split into interior texels (the texel
// and its 8 neighbours compared) and border texels (the rest; here the page's
// outer ring), each over mean b of all, against sums done here.
#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "io/image_io.h"
#include "support/cli_helper.h"

namespace bb::test {
namespace {

TEST(CliCompare, SplitsTheErrorIntoInteriorAndBorderTexels) {
    TempDir tmp("compare");
    const int size = 8;
    io::ImageRgb reference, measured;
    reference.width = measured.width = size;
    reference.height = measured.height = size;
    reference.pixels.assign(size * size, glm::vec3(2.0f));
    measured.pixels = reference.pixels;
    // +0.5 on the outer ring (28 texels), +0.125 on one interior texel
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x)
            if (x == 0 || y == 0 || x == size - 1 || y == size - 1) measured.pixels[size_t(y * size + x)] += 0.5f;
    measured.pixels[size_t(3 * size + 4)] += 0.125f;
    ASSERT_TRUE(io::writeExr((tmp.path() / "b.exr").string(), reference));
    ASSERT_TRUE(io::writeExr((tmp.path() / "a.exr").string(), measured));

    CliResult r = runCli({"compare", (tmp.path() / "a.exr").string(), (tmp.path() / "b.exr").string(), "--mask", "none",
                          "--json"},
                         tmp);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const double meanB = 2.0;
    const int border = 4 * size - 4, interior = size * size - border;
    EXPECT_EQ(j.at("texels").get<int>(), size * size);
    EXPECT_EQ(j.at("interior_texels").get<int>(), interior);
    const double interiorSq = 0.125 * 0.125, borderSq = border * 0.5 * 0.5;
    EXPECT_NEAR(j.at("interior_rel_rmse").get<double>(), std::sqrt(interiorSq / interior) / meanB, 1e-6);
    EXPECT_NEAR(j.at("border_rel_rmse").get<double>(), std::sqrt(borderSq / border) / meanB, 1e-6);
    EXPECT_NEAR(j.at("rel_rmse").get<double>(), std::sqrt((interiorSq + borderSq) / (size * size)) / meanB, 1e-6);
}

}  // namespace
}  // namespace bb::test
