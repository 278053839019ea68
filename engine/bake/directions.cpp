// Bundle directions: two spherical Fibonacci sets over the hemisphere z > 0,
// each with a seeded uniform random rotation and a van der Corput order so
// prefixes stay spread, interleaved (bake/directions.h).
//
// Based on: Marques, Bouville, Ribardiere, Santos, Bouatouch, "Spherical
// Fibonacci Point Sets for Illumination Integrals", CGF 32(8), 2013 (the set);
// Shoemake, "Uniform Random Rotations", Graphics Gems III, 1992 (the rotation);
// Duff, Burgess, Christensen, Hery, Kensler, Liani, Villemin, "Building an
// Orthonormal Basis, Revisited", JCGT 6(1), 2017 (the basis).
#include "bake/directions.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"
#include "core/hash.h"

namespace bb {
namespace {

constexpr double PI = 3.14159265358979323846;

// Base-2 radical inverse (van der Corput) of i as a 32-bit fraction: i's bits
// mirrored, so the value is reverseBits(i) / 2^32 in [0, 1).
uint32_t reverseBits(uint32_t i) {
    i = (i << 16) | (i >> 16);
    i = ((i & 0x00FF00FFu) << 8) | ((i & 0xFF00FF00u) >> 8);
    i = ((i & 0x0F0F0F0Fu) << 4) | ((i & 0xF0F0F0F0u) >> 4);
    i = ((i & 0x33333333u) << 2) | ((i & 0xCCCCCCCCu) >> 2);
    i = ((i & 0x55555555u) << 1) | ((i & 0xAAAAAAAAu) >> 1);
    return i;
}

}  // namespace

glm::dmat3 randomRotation(uint64_t seed) {
    SplitMix64 rng{seed};
    const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
    const double s1 = std::sqrt(1.0 - u1), s2 = std::sqrt(u1);
    const double x = s1 * std::sin(2.0 * PI * u2), y = s1 * std::cos(2.0 * PI * u2);
    const double z = s2 * std::sin(2.0 * PI * u3), w = s2 * std::cos(2.0 * PI * u3);
    // unit quaternion (x, y, z, w) -> matrix; glm is column-major: m[col][row]
    glm::dmat3 m;
    m[0] = glm::dvec3(1.0 - 2.0 * (y * y + z * z), 2.0 * (x * y + z * w), 2.0 * (x * z - y * w));
    m[1] = glm::dvec3(2.0 * (x * y - z * w), 1.0 - 2.0 * (x * x + z * z), 2.0 * (y * z + x * w));
    m[2] = glm::dvec3(2.0 * (x * z + y * w), 2.0 * (y * z - x * w), 1.0 - 2.0 * (x * x + y * y));
    return m;
}

namespace {
// One spherical Fibonacci set of `count` points over the hemisphere, rotated,
// in van der Corput order.
std::vector<glm::vec3> fibonacciSet(size_t count, const glm::dmat3& rotation) {
    const double goldenFraction = (std::sqrt(5.0) - 1.0) / 2.0;  // 1/phi
    // order: Fibonacci index j_i = floor(radicalInverse2(k) * count) for
    // k = 0, 1, 2, ..., skipping indices already taken. Once 2^m >= count the
    // first 2^m values of k hit every j, so this ends by k < 2 * count. Any
    // aligned run of 2^m outputs is then one point per 1/2^m band of z.
    std::vector<uint32_t> order;
    order.reserve(count);
    std::vector<bool> taken(count, false);
    for (uint32_t k = 0; order.size() < count; ++k) {
        // floor(radicalInverse2(k) * count) in exact integer arithmetic
        const size_t j = size_t((uint64_t(reverseBits(k)) * uint64_t(count)) >> 32);
        if (taken[j]) continue;
        taken[j] = true;
        order.push_back(uint32_t(j));
    }
    std::vector<glm::vec3> directions;
    directions.reserve(count);
    for (uint32_t j : order) {
        // spherical Fibonacci point j: equal-area bands in z, golden-ratio azimuths
        const double z = 1.0 - (double(j) + 0.5) / double(count);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        double turns = double(j) * goldenFraction;
        turns -= std::floor(turns);
        const double phi = 2.0 * PI * turns;
        const glm::dvec3 d = rotation * glm::dvec3(r * std::cos(phi), r * std::sin(phi), z);
        directions.push_back(glm::vec3(glm::normalize(d)));
    }
    return directions;
}
}  // namespace

std::vector<glm::vec3> makeDirections(int count, uint64_t seed) {
    CHECK_GE(count, 1);
    // two independently rotated sets, interleaved (replicates)
    const std::vector<glm::vec3> even = fibonacciSet(size_t(count + 1) / 2, randomRotation(seed));
    const std::vector<glm::vec3> odd = fibonacciSet(size_t(count) / 2, randomRotation(seed ^ 0x5851F42D4C957F2Dull));
    std::vector<glm::vec3> directions;
    directions.reserve(size_t(count));
    for (size_t k = 0; k < size_t(count); ++k) directions.push_back(k % 2 == 0 ? even[k / 2] : odd[k / 2]);
    return directions;
}

void orthonormalBasis(const glm::vec3& d, glm::vec3& u, glm::vec3& v) {
    // Duff et al. 2017, listing 3 (branchless). For z >= 0 this gives
    // u = (1,0,0), v = (0,1,0) at d = +z and varies smoothly; for z < 0 it gives
    // u = (1,0,0), v = (0,-1,0) at d = -z. Both branches are right-handed
    // (u x v = d): the determinant is continuous on each half and checked at
    // the poles; tests/unit/directions_test.cpp holds it for many d.
    const float sign = std::copysign(1.0f, d.z);
    const float a = -1.0f / (sign + d.z);
    const float b = d.x * d.y * a;
    u = glm::vec3(1.0f + sign * d.x * d.x * a, sign * b, -sign * d.x);
    v = glm::vec3(b, sign + d.y * d.y * a, -d.y);
}

}  // namespace bb
