// The resolution probe's arithmetic (bake/resolution_probe.h): Richardson's
// extrapolation texel by texel from how coarser reads change a texel's light,
// the texels past its range left out, and no bias read from noise alone.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "bake/resolution_probe.h"

namespace bb {
namespace {

// A texel whose baked reads err by `bias` (each channel) as c h^p, seen at
// supersampling k: the first step is bias (k^p - 1), the second k^p (2^p - 1)
// times bias; each half of the probe adds its own noise of `sigma`.
ProbeSteps steps(double bias, double p, int k, double sigma, std::mt19937& rng) {
    std::normal_distribution<double> noise(0.0, sigma);
    const auto jitter = [&] { return glm::dvec3(noise(rng), noise(rng), noise(rng)); };
    const double kp = std::pow(double(k), p);
    const glm::dvec3 first(bias * (kp - 1.0)), second(bias * kp * (std::pow(2.0, p) - 1.0));
    return {first + jitter(), first + jitter(), second + jitter(), second + jitter()};
}

TEST(ResolutionProbe, RichardsonGivesTheBakedReadsBiasAndItsOrder) {
    for (const int k : {2, 4})
        for (const double p : {1.0, 1.5, 2.0}) {
            std::mt19937 rng(7);
            std::vector<ProbeSteps> texels;
            for (int i = 0; i < 1000; ++i) texels.push_back(steps(i % 2 ? 0.02 : 0.0, p, k, 1e-4, rng));
            const ResolutionBias b = richardsonBias(texels, k);
            // half the texels at 0.02 a channel: the mean square 2e-4
            EXPECT_NEAR(std::sqrt(b.meanSquare), std::sqrt(2e-4), 0.02 * std::sqrt(2e-4)) << "k " << k << ", p " << p;
            EXPECT_NEAR(b.order, p, 0.02) << "k " << k;
            EXPECT_LT(b.pastRange, 0.01);
        }
}

// A texel whose second step changes less than its first lost its light's
// detail at the output's texels already: the steps say nothing of the baked
// texels' error (the street canyon's strips, about a texel wide), and taking
// its first step at p = 1 read the canyon's bias 2-3x too high.
TEST(ResolutionProbe, TexelsPastTheRangeAreLeftOut) {
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 1e-4);
    std::vector<ProbeSteps> texels;
    for (int i = 0; i < 1000; ++i) {
        const glm::dvec3 first(0.05), second(0.005);  // the second step a tenth of the first
        texels.push_back({first + noise(rng), first + noise(rng), second + noise(rng), second + noise(rng)});
    }
    ResolutionBias b = richardsonBias(texels, 2);
    EXPECT_EQ(b.meanSquare, 0.0);
    EXPECT_EQ(b.order, 0.0);
    EXPECT_NEAR(b.pastRange, 1.0, 1e-9);
    // and beside texels in range, only theirs count
    for (int i = 0; i < 1000; ++i) texels.push_back(steps(0.01, 2.0, 2, 1e-4, rng));
    b = richardsonBias(texels, 2);
    EXPECT_NEAR(std::sqrt(b.meanSquare), std::sqrt(0.5) * 0.01, 0.0003);
    EXPECT_NEAR(b.order, 2.0, 0.02);
    // their first steps' squares: 0.05^2 against (3 * 0.01)^2
    EXPECT_NEAR(b.pastRange, 0.0025 / (0.0025 + 0.0009), 0.01);
}

// Where coarser reads change nothing but the probe's own noise, the even and
// odd halves' products sum to noise about 0 (each half's steps choose its
// texel's range and order, the other's enter the product), which the
// shrinkage takes to 0 or near it: at 4000 texels a sum one standard deviation
// off 0 reads about a tenth of the noise, where the squares of either half
// alone would read the noise itself.
TEST(ResolutionProbe, NoiseAloneReadsNoBias) {
    for (const unsigned seed : {1u, 2u, 3u, 4u}) {
        std::mt19937 rng(seed);
        std::vector<ProbeSteps> texels;
        for (int i = 0; i < 4000; ++i) texels.push_back(steps(0.0, 1.0, 2, 0.01, rng));
        const ResolutionBias b = richardsonBias(texels, 2);
        EXPECT_LT(std::sqrt(b.meanSquare), 0.2 * 0.01) << "seed " << seed;
    }
}

}  // namespace
}  // namespace bb
