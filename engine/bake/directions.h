// Bundle directions: two stratified sets over the hemisphere z > 0 (spherical
// Fibonacci), each rotated by its own seeded random rotation, interleaved:
// even k from the first, odd k from the second. Each direction d serves d
// and -d (a texel takes the side its normal faces), so {+-d_i} covers the
// sphere uniformly and every texel gets one sample per direction.
//
// Two independent randomizations (replicates, as in randomized quasi-Monte
// Carlo) make the bake's noise measurable: the odd and even directions'
// estimates are independent and alike, so their difference gives the
// standard error (engine/bake/noise.cpp). The price: their union is less even
// than one set of all the directions (8-27 % more noise at equal directions
// on the Cornell box, two rooms and open box; docs/design-notes.md).
//
// Order: within each set a low-discrepancy permutation of the Fibonacci
// indices (van der Corput on the index), so every prefix of the sequence is
// itself spread over the hemisphere: a bake stopped early (viewer,
// checkpoints) is still stratified.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

namespace bb {

// count >= 1. Unit vectors; the same (count, seed) gives the same bits.
std::vector<glm::vec3> makeDirections(int count, uint64_t seed);

// A uniformly distributed rotation (Shoemake's random unit quaternion); the
// same seed gives the same bits.
glm::dmat3 randomRotation(uint64_t seed);

// A right-handed orthonormal basis (u, v) with u x v = d, for bundle planes.
void orthonormalBasis(const glm::vec3& d, glm::vec3& u, glm::vec3& v);

}  // namespace bb
