// fp16 and RGBE encodings with stochastic (unbiased) or nearest rounding, and
// the PCG hash that feeds them random numbers. glsl/lib/rounding.glsl is the
// GPU twin; keep the two in step.
//
// Based on: Connolly, Higham, Mary, "Stochastic rounding and its probabilistic
// backward error analysis", SIAM J. Sci. Comput. 43(1), 2021 (mode 1: round up
// with probability proportional to the distance from the lower neighbour);
// Ward, "Real Pixels", Graphics Gems II, 1991 (RGBE); Jarzynski and Olano,
// "Hash Functions for GPU Rendering", JCGT 9(3), 2020 (PCG hash).
#include "bake/rounding.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Imath/half.h>

namespace bb {
namespace {

constexpr uint16_t SIGN_BIT = 0x8000;
constexpr uint16_t LARGEST_HALF_BITS = 0x7BFF;  // 65504, the largest finite fp16
constexpr float LARGEST_HALF = 65504.0f;

// Round a non-negative mantissa to an integer: floor(m + u), u = 0.5 for nearest.
uint32_t roundMantissa(float m, float u) { return uint32_t(std::floor(m + u)); }

}  // namespace

uint16_t floatToHalf(float x, Rounding mode, float u) {
    if (std::isnan(x)) return 0;
    const uint16_t sign = x < 0.0f ? SIGN_BIT : 0;  // as the GLSL twin: -0 -> +0
    // saturate: anything at or beyond the largest finite half (Inf included)
    const float a = std::fabs(x);
    if (a >= LARGEST_HALF) return sign | LARGEST_HALF_BITS;

    // nearest, ties to even (Imath); only 65504 < a < 65520 could round to Inf,
    // and those were caught above
    uint16_t h = imath_float_to_half(a);
    if (mode == Rounding::Nearest) return sign | h;

    const float v = imath_half_to_float(h);
    if (v == a) return sign | h;
    // the two neighbours bracketing a: positive halves are monotonic in their bits
    const uint16_t lo = v < a ? h : uint16_t(h - 1);
    const uint16_t hi = uint16_t(lo + 1);
    const float vlo = imath_half_to_float(lo);
    const float vhi = imath_half_to_float(hi);
    // pick hi with probability (a - vlo) / (vhi - vlo). Both differences are
    // exact (Sterbenz; vhi - vlo is a power of two), written as the GLSL twin
    // writes it so the two agree bit for bit.
    h = (u * (vhi - vlo) < a - vlo) ? hi : lo;
    return sign | std::min(h, LARGEST_HALF_BITS);
}

float halfToFloat(uint16_t h) { return imath_half_to_float(h); }

uint32_t encodeRgbe(glm::vec3 rgb, Rounding mode, glm::vec3 u) {
    // negatives, NaN and denormals -> 0 (the comparison is false for NaN;
    // GPUs may flush denormals, so the GLSL twin could not keep them); +Inf ->
    // the largest float, which then saturates below like any value >= 2^127
    for (int i = 0; i < 3; ++i)
        rgb[i] = rgb[i] >= std::numeric_limits<float>::min() ? std::min(rgb[i], std::numeric_limits<float>::max()) : 0.0f;
    const float maxc = std::max(rgb.r, std::max(rgb.g, rgb.b));
    if (maxc == 0.0f) return 0;  // (not a denormal threshold: with DAZ set, as Embree sets it, that reads as 0)
    if (mode == Rounding::Nearest) u = glm::vec3(0.5f);

    int e = 0;
    std::frexp(maxc, &e);  // maxc = f * 2^e, f in [0.5, 1), so maxc < 2^e
    for (int attempt = 0; attempt < 2; ++attempt) {
        // the largest exponent byte is 255 (e = 127): beyond it (maxc >= 2^127)
        // saturate the mantissas at 255
        const int es = std::min(e, 127);
        // ldexp, not x * exp2(8 - e): 2^(8 - e) overflows a float for maxc < 2^-120
        uint32_t q[3];
        for (int i = 0; i < 3; ++i) q[i] = roundMantissa(std::min(std::ldexp(rgb[i], 8 - es), 256.0f), u[i]);
        if (e > 127) {
            for (uint32_t& qi : q) qi = std::min(qi, 255u);
        }
        if (std::max(q[0], std::max(q[1], q[2])) < 256u) {
            // e >= -125 for maxc >= FLT_MIN, so the byte is >= 3: never the "zero" byte
            const uint32_t eb = uint32_t(std::clamp(es + 128, 0, 255));
            return q[0] | (q[1] << 8) | (q[2] << 16) | (eb << 24);
        }
        // a mantissa rounded up to 256: carry into the exponent and round again
        // with the same u (the largest mantissa then rounds to 128 exactly)
        e += 1;
    }
    return 0;  // unreachable: after the carry every mantissa is <= 128
}

// floor(x) + 1 with probability fract(x) (exact: floor(x + u) would round
// x + u to a float first, a bias of up to 2^-9 of a step at 16 bits)
float roundUpWithProbability(float x, float u) {
    const float f = std::floor(x);
    return u < x - f ? f + 1.0f : f;
}

uint32_t encodeAccumulatorWeight(float w, Rounding mode, float u) {
    if (mode == Rounding::Nearest) u = 0.5f;
    if (!(w > 0.0f)) return 0;
    constexpr float LARGEST = 64512.0f;  // the largest fp16 with 7 significant bits
    w = std::min(w, LARGEST);
    int e = 0;
    std::frexp(w, &e);
    const int k = std::max(e - 1, -14) - 6;  // w's ulp: 2^k
    const float q = std::min(std::ldexp(roundUpWithProbability(std::ldexp(w, -k), u), k), LARGEST);
    return uint32_t(imath_float_to_half(q) & 0x7FFF) >> 4;  // exact: q has 7 significant bits
}

float decodeAccumulatorWeight(uint32_t bits) { return imath_half_to_float(uint16_t((bits & 0x7FFu) << 4)); }

glm::uvec2 encodeAccumulator(glm::vec4 s, Rounding mode, glm::vec4 u) {
    if (mode == Rounding::Nearest) u = glm::vec4(0.5f);
    glm::vec3 c(s);
    for (int i = 0; i < 3; ++i) c[i] = c[i] > 0.0f ? std::min(c[i], 65535.0f) : 0.0f;  // NaN -> 0 too
    const float maxc = std::max({c.r, c.g, c.b});
    uint32_t q[3] = {0, 0, 0};
    int ex = 0;
    if (maxc > 0.0f) {
        int e = 0;
        std::frexp(maxc, &e);  // maxc < 2^e
        ex = std::clamp(e + 15, 0, 31);
        const auto round = [&]() {
            for (int i = 0; i < 3; ++i) q[i] = uint32_t(roundUpWithProbability(std::ldexp(c[i], 31 - ex), u[i]));
        };
        round();
        if (std::max({q[0], q[1], q[2]}) > 65535u && ex < 31) {
            ex += 1;  // a mantissa rounded up to 2^16: carry into the exponent and round again
            round();
        }
        for (uint32_t& qi : q) qi = std::min(qi, 65535u);
    }
    return glm::uvec2(q[0] | (q[1] << 16),
                      q[2] | (uint32_t(ex) << 16) | (encodeAccumulatorWeight(s.a, mode, u.a) << 21));
}

glm::vec4 decodeAccumulator(glm::uvec2 p) {
    const int k = int((p.y >> 16) & 31u) - 31;
    return glm::vec4(std::ldexp(float(p.x & 0xFFFFu), k), std::ldexp(float(p.x >> 16), k),
                     std::ldexp(float(p.y & 0xFFFFu), k), decodeAccumulatorWeight(p.y >> 21));
}

glm::vec3 decodeRgbe(uint32_t rgbe) {
    const int eb = int(rgbe >> 24);
    if (eb == 0) return glm::vec3(0.0f);
    const glm::vec3 m(float(rgbe & 255u), float((rgbe >> 8) & 255u), float((rgbe >> 16) & 255u));
    // ldexp keeps tiny exponents exact where exp2 * m would not
    return glm::vec3(std::ldexp(m.r, eb - 136), std::ldexp(m.g, eb - 136), std::ldexp(m.b, eb - 136));
}

uint32_t pcgHash(uint32_t v) {
    const uint32_t state = v * 747796405u + 2891336453u;
    const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

float uniform01(uint32_t bits) { return float(bits >> 8) * (1.0f / 16777216.0f); }

}  // namespace bb
