// fp16 and RGBE rounding: stochastic is unbiased, nearest is nearest, and the
// fp16 accumulator stall that motivates stochastic rounding is reproduced.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "bake/rounding.h"

namespace bb {
namespace {

constexpr int SAMPLES = 200000;

// Deterministic [0,1) stream: uniform01(pcgHash(seed + i)).
struct HashStream {
    uint32_t next;
    float operator()() { return uniform01(pcgHash(next++)); }
};

float roundTripHalf(float x, Rounding mode, float u) { return halfToFloat(floatToHalf(x, mode, u)); }

// Spacing-based bracket of |x| in fp16, from the nearest conversion.
struct Bracket {
    float lo, hi;
};
Bracket bracketHalf(float x) {
    const uint16_t h = floatToHalf(x, Rounding::Nearest, 0.0f);
    const float v = halfToFloat(h);
    if (v <= x) return {v, halfToFloat(uint16_t(h + 1))};
    return {halfToFloat(uint16_t(h - 1)), v};
}

TEST(Rounding, PcgHashAndUniformMatchTheGlslDefinition) {
    // reference values computed by hand from the formula in rounding.h
    auto reference = [](uint32_t v) {
        uint32_t state = v * 747796405u + 2891336453u;
        uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
        return (word >> 22u) ^ word;
    };
    for (uint32_t v : {0u, 1u, 2u, 12345u, 0xFFFFFFFFu}) EXPECT_EQ(pcgHash(v), reference(v));
    EXPECT_EQ(uniform01(0u), 0.0f);
    EXPECT_EQ(uniform01(0xFFFFFFFFu), 16777215.0f / 16777216.0f);
    EXPECT_LT(uniform01(0xFFFFFFFFu), 1.0f);
    // the stream is roughly uniform
    HashStream u{7};
    double sum = 0.0;
    for (int i = 0; i < SAMPLES; ++i) sum += u();
    EXPECT_NEAR(sum / SAMPLES, 0.5, 3.0 * std::sqrt(1.0 / 12.0 / SAMPLES));
}

TEST(Rounding, StochasticHalfIsUnbiased) {
    // normal, between 2048 and 4096 (spacing 2), large, subnormal, below the
    // smallest subnormal (2^-24 ~ 5.96e-8), and negative
    const float values[] = {0.1f, 1.0f / 3.0f, 2049.3f, 3001.7f, 40000.3f, 3.0e-6f, 1.0e-7f, 2.0e-8f, -0.7771f};
    for (float x : values) {
        const Bracket b = bracketHalf(std::fabs(x));
        ASSERT_LT(b.lo, std::fabs(x));
        ASSERT_GT(b.hi, std::fabs(x));
        HashStream u{1000};
        double sum = 0.0;
        for (int i = 0; i < SAMPLES; ++i) {
            const float r = roundTripHalf(x, Rounding::Stochastic, u());
            // only the two neighbours are ever chosen, with the sign kept
            ASSERT_TRUE(std::fabs(r) == b.lo || std::fabs(r) == b.hi) << x << " -> " << r;
            ASSERT_EQ(std::signbit(r), std::signbit(x));
            sum += r;
        }
        const double p = (std::fabs(double(x)) - b.lo) / (double(b.hi) - b.lo);
        const double sigma = (double(b.hi) - b.lo) * std::sqrt(p * (1.0 - p) / SAMPLES);
        EXPECT_NEAR(sum / SAMPLES, double(x), 3.0 * sigma) << "x = " << x;
    }
}

TEST(Rounding, StochasticHalfKeepsRepresentableValuesExactly) {
    for (float x : {0.0f, 1.0f, -2.5f, 2048.0f, 2050.0f, 65504.0f, 0x1.0p-24f}) {
        for (float u : {0.0f, 0.5f, 0.999999f}) EXPECT_EQ(roundTripHalf(x, Rounding::Stochastic, u), x);
    }
}

TEST(Rounding, NearestHalfIsTheTrueNearest) {
    HashStream u{42};
    for (int i = 0; i < 20000; ++i) {
        // log-uniform magnitudes over the whole fp16 range, both signs
        const float x = (u() < 0.5f ? -1.0f : 1.0f) * std::exp2(-26.0f + 41.9f * u());
        const float r = roundTripHalf(x, Rounding::Nearest, 0.0f);
        const Bracket b = bracketHalf(std::fabs(x));
        const float dr = std::fabs(std::fabs(r) - std::fabs(x));
        EXPECT_LE(dr, std::fabs(x) - b.lo) << x;
        EXPECT_LE(dr, b.hi - std::fabs(x)) << x;
        EXPECT_EQ(std::signbit(r), std::signbit(x));
    }
    // ties go to even
    EXPECT_EQ(roundTripHalf(2049.0f, Rounding::Nearest, 0.0f), 2048.0f);
    EXPECT_EQ(roundTripHalf(2051.0f, Rounding::Nearest, 0.0f), 2052.0f);
    // u is ignored
    EXPECT_EQ(floatToHalf(0.1f, Rounding::Nearest, 0.0f), floatToHalf(0.1f, Rounding::Nearest, 0.99f));
}

TEST(Rounding, NearestHalfAccumulatorStallsAndStochasticDoesNot) {
    // the classic: 1 + 2048 = 2048 in fp16 with round to nearest
    uint16_t nearest = 0, stochastic = 0;
    HashStream u{0xBEEF};
    for (int i = 0; i < 4096; ++i) {
        nearest = floatToHalf(halfToFloat(nearest) + 1.0f, Rounding::Nearest, 0.0f);
        stochastic = floatToHalf(halfToFloat(stochastic) + 1.0f, Rounding::Stochastic, u());
    }
    EXPECT_EQ(halfToFloat(nearest), 2048.0f);
    EXPECT_NEAR(halfToFloat(stochastic), 4096.0f, 0.03f * 4096.0f);
}

TEST(Rounding, HalfSaturatesAndMapsNanToZero) {
    for (Rounding mode : {Rounding::Nearest, Rounding::Stochastic}) {
        EXPECT_EQ(floatToHalf(1.0e6f, mode, 0.9f), 0x7BFF);
        EXPECT_EQ(floatToHalf(65519.0f, mode, 0.9f), 0x7BFF);
        EXPECT_EQ(floatToHalf(65520.0f, mode, 0.9f), 0x7BFF);  // nearest would give Inf
        EXPECT_EQ(floatToHalf(std::numeric_limits<float>::infinity(), mode, 0.5f), 0x7BFF);
        EXPECT_EQ(floatToHalf(-std::numeric_limits<float>::infinity(), mode, 0.5f), 0xFBFF);
        EXPECT_EQ(floatToHalf(-1.0e9f, mode, 0.5f), 0xFBFF);
        EXPECT_EQ(halfToFloat(0x7BFF), 65504.0f);
        EXPECT_EQ(floatToHalf(std::numeric_limits<float>::quiet_NaN(), mode, 0.5f), 0);
        EXPECT_EQ(floatToHalf(-std::numeric_limits<float>::quiet_NaN(), mode, 0.5f), 0);
    }
    // a value just below 65504 never rounds up past it
    EXPECT_LE(roundTripHalf(65503.0f, Rounding::Stochastic, 0.0f), 65504.0f);
}

glm::vec3 randomColour(HashStream& u) {
    // channels spread over many octaves, like radiance
    glm::vec3 c;
    for (int i = 0; i < 3; ++i) c[i] = std::exp2(-20.0f + 40.0f * u()) * u();
    return c;
}

TEST(Rounding, RgbeNearestRoundTripIsWithinHalfAMantissaStep) {
    HashStream u{9};
    for (int i = 0; i < 20000; ++i) {
        const glm::vec3 c = randomColour(u);
        const uint32_t code = encodeRgbe(c, Rounding::Nearest, glm::vec3(0.0f));
        const glm::vec3 d = decodeRgbe(code);
        const float maxc = std::max(c.r, std::max(c.g, c.b));
        // the largest channel keeps relative error < 1/128 (8-bit mantissa in
        // [128, 256), or 128 after a carry); every channel is within half of
        // the step its exponent byte gives
        const int largest = c.r == maxc ? 0 : (c.g == maxc ? 1 : 2);
        EXPECT_LT(std::fabs(d[largest] - c[largest]), c[largest] / 128.0f) << i;
        const float step = std::ldexp(1.0f, int(code >> 24) - 136);
        for (int k = 0; k < 3; ++k) EXPECT_LE(std::fabs(d[k] - c[k]), 0.5f * step * 1.0001f) << i << " " << k;
    }
}

TEST(Rounding, RgbeStochasticIsUnbiasedPerChannel) {
    const glm::vec3 colours[] = {{0.3f, 0.017f, 1.9f}, {1234.5f, 3.3f, 0.0f}, {1.0e-20f, 3.7e-21f, 5.5e-21f},
                                 {100.3f, 100.7f, 99.1f}};
    for (const glm::vec3& c : colours) {
        HashStream u{77};
        glm::dvec3 sum(0.0);
        uint32_t first = 0;
        bool varied = false;
        for (int i = 0; i < SAMPLES; ++i) {
            const uint32_t code = encodeRgbe(c, Rounding::Stochastic, glm::vec3(u(), u(), u()));
            if (i == 0) first = code;
            varied = varied || code != first;
            sum += glm::dvec3(decodeRgbe(code));
        }
        EXPECT_TRUE(varied);
        const float maxc = std::max(c.r, std::max(c.g, c.b));
        int e = 0;
        std::frexp(maxc, &e);
        const double step = std::ldexp(1.0, e - 8);
        for (int k = 0; k < 3; ++k) {
            const double m = double(c[k]) / step;
            const double p = m - std::floor(m);
            const double sigma = step * std::sqrt(p * (1.0 - p) / SAMPLES);
            EXPECT_NEAR(sum[k] / SAMPLES, double(c[k]), 3.0 * sigma + 1e-12 * step) << "channel " << k;
        }
    }
}

TEST(Rounding, RgbeZeroTinyNegativeAndCarry) {
    for (Rounding mode : {Rounding::Nearest, Rounding::Stochastic}) {
        EXPECT_EQ(encodeRgbe(glm::vec3(0.0f), mode, glm::vec3(0.5f)), 0u);
        EXPECT_EQ(decodeRgbe(0u), glm::vec3(0.0f));
        // below 1e-38 is zero
        EXPECT_EQ(encodeRgbe(glm::vec3(1.0e-39f, 0.0f, 5.0e-40f), mode, glm::vec3(0.9f)), 0u);
        // negatives and NaN clamp to zero, channel by channel
        EXPECT_EQ(encodeRgbe(glm::vec3(-1.0f, -2.0f, -0.5f), mode, glm::vec3(0.5f)), 0u);
        const glm::vec3 mixed =
            decodeRgbe(encodeRgbe(glm::vec3(-1.0f, 2.0f, std::nanf("")), mode, glm::vec3(0.3f)));
        EXPECT_EQ(mixed, glm::vec3(0.0f, 2.0f, 0.0f));
    }
    // tiny but representable: still 8 bits of relative precision (the GLSL
    // exp2(8 - e) form would overflow here); denormal channels are zero (GPUs
    // may flush them)
    for (float x : {1.0e-30f, 2.5e-38f, 3.0e-37f}) {
        const glm::vec3 d = decodeRgbe(encodeRgbe(glm::vec3(x, x * 0.5f, 0.0f), Rounding::Nearest, glm::vec3(0.0f)));
        // tolerances in double: x / 128 in float is a denormal, which a test run
        // with flush-to-zero set (by a library loaded earlier) reads as 0
        EXPECT_NEAR(d.r, x, double(x) / 128.0);
        EXPECT_NEAR(d.g, x * 0.5f, double(x) / 256.0);
        EXPECT_EQ(d.b, 0.0f);
    }
    EXPECT_EQ(decodeRgbe(encodeRgbe(glm::vec3(2.0e-38f, 1.0e-38f, 0.0f), Rounding::Nearest, glm::vec3(0.0f))).g, 0.0f);
    // exact values round-trip exactly: m * 2^(e - 136)
    EXPECT_EQ(decodeRgbe(encodeRgbe(glm::vec3(1.0f, 0.5f, 0.25f), Rounding::Nearest, glm::vec3(0.0f))),
              glm::vec3(1.0f, 0.5f, 0.25f));
    const uint32_t one = encodeRgbe(glm::vec3(1.0f, 0.0f, 0.0f), Rounding::Nearest, glm::vec3(0.0f));
    EXPECT_EQ(one, 128u | (129u << 24));  // 1 = 128 * 2^(129 - 136)
    // mantissa overflow carries into the exponent: 255.9 -> 256 = 128 * 2^(137 - 136)
    const uint32_t carried = encodeRgbe(glm::vec3(255.9f, 1.0f, 0.0f), Rounding::Nearest, glm::vec3(0.0f));
    EXPECT_EQ(carried >> 24, 137u);
    EXPECT_EQ(carried & 255u, 128u);
    EXPECT_EQ(decodeRgbe(carried), glm::vec3(256.0f, 2.0f, 0.0f));  // 1.0 -> 0.5 step -> nearest 2 (tie up)
    // stochastic carry: u near 1 rounds 255.5 up, which must also carry
    const glm::vec3 up = decodeRgbe(encodeRgbe(glm::vec3(255.5f), Rounding::Stochastic, glm::vec3(0.9f)));
    EXPECT_EQ(up, glm::vec3(256.0f));
    // huge values saturate instead of wrapping
    const glm::vec3 huge = decodeRgbe(encodeRgbe(glm::vec3(3.0e38f, 1.0f, 0.0f), Rounding::Nearest, glm::vec3(0.0f)));
    EXPECT_GT(huge.r, 1.0e38f);
    EXPECT_TRUE(std::isfinite(huge.r));
    const glm::vec3 inf = decodeRgbe(encodeRgbe(glm::vec3(std::numeric_limits<float>::infinity()),
                                                Rounding::Nearest, glm::vec3(0.0f)));
    EXPECT_EQ(inf, glm::vec3(std::ldexp(255.0f, 119)));
}

// The accumulators (encodeAccumulator): the mean's channels to 16 bits of
// the largest one, W to 7 significant bits, both unbiased.
TEST(Rounding, AccumulatorStochasticIsUnbiasedPerChannel) {
    const glm::vec4 states[] = {{0.3f, 0.017f, 1.9f, 12.3f}, {1234.5f, 3.3f, 0.0f, 0.0137f},
                                {1.0e-6f, 3.7e-7f, 5.5e-7f, 3000.7f}, {0.61f, 0.61f, 0.61f, 6.1035e-5f}};
    for (const glm::vec4& s : states) {
        HashStream u{91};
        glm::dvec4 sum(0.0);
        for (int i = 0; i < SAMPLES; ++i)
            sum += glm::dvec4(decodeAccumulator(encodeAccumulator(s, Rounding::Stochastic, glm::vec4(u(), u(), u(), u()))));
        const float maxc = std::max({s.r, s.g, s.b});
        int e = 0;
        std::frexp(maxc, &e);
        int ew = 0;
        std::frexp(s.a, &ew);
        for (int k = 0; k < 4; ++k) {
            const double step = k < 3 ? std::ldexp(1.0, std::clamp(e + 15, 0, 31) - 31) : std::ldexp(1.0, std::max(ew - 1, -14) - 6);
            const double m = double(s[k]) / step, p = m - std::floor(m);
            const double sigma = step * std::sqrt(p * (1.0 - p) / SAMPLES);
            EXPECT_NEAR(sum[k] / SAMPLES, double(s[k]), 3.0 * sigma + 1e-9 * step) << "channel " << k;
        }
    }
}

TEST(Rounding, AccumulatorNearestIsWithinHalfAStep) {
    HashStream u{5};
    for (int i = 0; i < 20000; ++i) {
        const glm::vec4 s(std::ldexp(u(), int(u() * 40.0f) - 25), std::ldexp(u(), -3), u(), std::ldexp(u() + 0.01f, int(u() * 30.0f) - 14));
        const glm::vec4 d = decodeAccumulator(encodeAccumulator(s, Rounding::Nearest, glm::vec4(0.0f)));
        int e = 0, ew = 0;
        std::frexp(std::max({s.r, s.g, s.b}), &e);
        std::frexp(s.a, &ew);
        for (int k = 0; k < 3; ++k)
            ASSERT_LE(std::fabs(double(d[k]) - s[k]), std::ldexp(0.5, std::clamp(e + 15, 0, 31) - 31)) << i << " " << k;
        ASSERT_LE(std::fabs(double(d.a) - s.a), std::ldexp(0.5, std::max(ew - 1, -14) - 6)) << i;
    }
}

TEST(Rounding, AccumulatorZeroNegativeNanSaturationAndCarry) {
    for (Rounding mode : {Rounding::Nearest, Rounding::Stochastic}) {
        EXPECT_EQ(encodeAccumulator(glm::vec4(0.0f), mode, glm::vec4(0.9f)), glm::uvec2(0u));
        EXPECT_EQ(decodeAccumulator(glm::uvec2(0u)), glm::vec4(0.0f));
        EXPECT_EQ(decodeAccumulator(encodeAccumulator(glm::vec4(-1.0f, 2.0f, std::nanf(""), -3.0f), mode, glm::vec4(0.3f))),
                  glm::vec4(0.0f, 2.0f, 0.0f, 0.0f));
        // beyond the range saturates
        const glm::vec4 big = decodeAccumulator(encodeAccumulator(glm::vec4(1e9f, 1.0f, 0.0f, 1e9f), mode, glm::vec4(0.5f)));
        EXPECT_EQ(big.r, 65535.0f);
        EXPECT_EQ(big.a, 64512.0f);
        // the smallest weight of a sampled texel (rescale.comp) is kept exactly
        EXPECT_EQ(decodeAccumulator(encodeAccumulator(glm::vec4(1.0f, 1.0f, 1.0f, 6.103515625e-5f), mode, glm::vec4(0.99f))).a,
                  6.103515625e-5f);
    }
    // a mantissa that rounds up to 2^16 carries into the exponent: 1 - 2^-20 rounds to 1 exactly
    EXPECT_EQ(decodeAccumulator(encodeAccumulator(glm::vec4(1.0f - 0x1p-20f, 0.0f, 0.0f, 1.0f), Rounding::Nearest,
                                                  glm::vec4(0.0f))).r, 1.0f);
}

// What the 16-bit mean is for: a running mean over N samples rounded at
// every fold (update.frag's foldSample) gathers rounding noise like sqrt(N).
// After 4096 folds of a signal that varies as much as its mean (L_in 0 or
// up to 2, mean 0.6), fp16's mean was 1.3 % off the exact running mean (rms
// over runs), about as much as the sampling noise itself at 16k samples;
// the accumulator's is 0.1 %.
TEST(Rounding, AccumulatorRunningMeanRoundingNoiseStaysSmall) {
    const int folds = 4096, runs = 200;
    HashStream u{17}, signal{4242};
    double sq = 0.0, mean = 0.0;
    for (int r = 0; r < runs; ++r) {
        glm::uvec2 stored(0u);
        double exact = 0.0, w = 0.0;
        for (int k = 0; k < folds; ++k) {
            const float l = signal() < 0.6f ? 2.0f * signal() : 0.0f;
            const glm::vec4 s = decodeAccumulator(stored);
            const float total = s.a + 1.0f;
            stored = encodeAccumulator(glm::vec4(glm::vec3(s) + (glm::vec3(l) - glm::vec3(s)) * (1.0f / total), total),
                                       Rounding::Stochastic, glm::vec4(u(), u(), u(), u()));
            w += 1.0;
            exact += (double(l) - exact) / w;
        }
        const double d = double(decodeAccumulator(stored).r) - exact;
        sq += d * d;
        mean += exact;
    }
    const double relative = std::sqrt(sq / runs) / (mean / runs);
    std::printf("[accumulator] rms rounding error of a running mean after %d folds: %.4f %% of the mean\n", folds,
                100.0 * relative);
    EXPECT_LT(relative, 0.002);
}

}  // namespace
}  // namespace bb
