// Lower-precision storage with stochastic rounding (unbiased): fp16 for the
// direct light, a shared-exponent RGB and a short float weight for the light
// map accumulators, RGBE (Ward's shared-exponent, 8-bit mantissas) for bundle
// nodes. The GLSL twins are in glsl/lib/rounding.glsl; these CPU versions are
// the reference the tests hold the shaders to, and they decode readbacks.
//
// Stochastic rounding picks the upper neighbour with probability
// (x - lower) / (upper - lower), so E[decode(encode(x, u))] = x for u ~ U[0,1).
// Nearest rounding (u = 0.5 in these functions' `nearest` mode) is biased:
// summing many small values into a large fp16 sum stalls (1 + 2048 = 2048).
#pragma once

#include <cstdint>

#include <glm/glm.hpp>

namespace bb {

enum class Rounding { Stochastic, Nearest };

// fp16 bits of x (finite, any sign). u in [0,1): the random number for
// stochastic rounding; ignored for Nearest (round to nearest, ties to even).
// Values beyond the fp16 range saturate to +-65504 (never Inf).
uint16_t floatToHalf(float x, Rounding mode, float u);
float halfToFloat(uint16_t h);

// RGBE: 8-bit mantissas r,g,b in bits 0..23, biased exponent e in 24..31.
// Decoded value = m * 2^(e - 136) (no +0.5 offset: with stochastic rounding
// the encoding is unbiased; with Nearest it rounds each mantissa to nearest).
// Negative inputs are clamped to 0. Max ~ 2^119.
uint32_t encodeRgbe(glm::vec3 rgb, Rounding mode, glm::vec3 u);
glm::vec3 decodeRgbe(uint32_t rgbe);

// The light map accumulators (a running mean RGB and its weight W) in 64
// bits, an rg32ui texel (x, y): RGB with a shared exponent e and 16-bit
// mantissas, value = m * 2^(e - 31) (e in 0..31, up to 65535), W as an fp16
// without sign and its 4 low mantissa bits (7 significant bits);
// x = r | g << 16, y = b | e << 16 | w << 21. u: one random number per
// channel (rgb, W); NaN and negatives -> 0, larger values saturate.
glm::uvec2 encodeAccumulator(glm::vec4 meanAndWeight, Rounding mode, glm::vec4 u);
glm::vec4 decodeAccumulator(glm::uvec2 bits);
uint32_t encodeAccumulatorWeight(float w, Rounding mode, float u);  // the 11 bits of W
float decodeAccumulatorWeight(uint32_t bits);

// Deterministic hash-based random numbers shared with GLSL (PCG hash,
// Jarzynski & Olano 2020). uniform01 returns [0,1) with 24 bits.
uint32_t pcgHash(uint32_t v);
float uniform01(uint32_t bits);

}  // namespace bb
