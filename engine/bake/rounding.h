// Lower-precision storage with stochastic rounding (unbiased): fp16 for light
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

// Deterministic hash-based random numbers shared with GLSL (PCG hash,
// Jarzynski & Olano 2020). uniform01 returns [0,1) with 24 bits.
uint32_t pcgHash(uint32_t v);
float uniform01(uint32_t bits);

}  // namespace bb
