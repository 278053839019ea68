// Bundle directions: unit, distinct, uniform as the set {+-d}, seeded and
// deterministic; even and odd directions each a rotated copy of one fixed set
// (two independent replicates), each stratified in every aligned run (so a
// bake stopped early is still well spread).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "bake/directions.h"
#include "bake/rounding.h"

namespace bb {
namespace {

// Deterministic [0,1) stream.
struct HashStream {
    uint32_t next;
    float operator()() { return uniform01(pcgHash(next++)); }
};

glm::dvec3 randomUnit(HashStream& u) {
    const double z = 1.0 - 2.0 * u();
    const double phi = 2.0 * 3.14159265358979323846 * u();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
}

// Mean of |n . d| over directions [begin, end): 1/2 for a uniform sphere.
double meanAbsCos(const std::vector<glm::vec3>& dirs, size_t begin, size_t end, const glm::dvec3& n) {
    double sum = 0.0;
    for (size_t i = begin; i < end; ++i) sum += std::fabs(glm::dot(n, glm::dvec3(dirs[i])));
    return sum / double(end - begin);
}

// RMS over many axes n of (mean |n.d| over [begin, end) - 1/2): how well the
// run integrates the cosine lobes a texel sees, whatever its normal.
double rmsCosineError(const std::vector<glm::vec3>& dirs, size_t begin, size_t end) {
    HashStream u{555};
    double sum2 = 0.0;
    const int axes = 200;
    for (int a = 0; a < axes; ++a) {
        const double e = meanAbsCos(dirs, begin, end, randomUnit(u)) - 0.5;
        sum2 += e * e;
    }
    return std::sqrt(sum2 / axes);
}

TEST(Directions, CountAndUnitLength) {
    for (int count : {1, 2, 3, 7, 64, 256, 1000}) {
        const std::vector<glm::vec3> dirs = makeDirections(count, 17);
        ASSERT_EQ(dirs.size(), size_t(count));
        for (const glm::vec3& d : dirs) EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
    }
}

TEST(Directions, NoDuplicatesOrAntipodalPairs) {
    // each d also serves -d, so d_j = +-d_i would waste a direction
    for (int count : {256, 1000}) {
        const std::vector<glm::vec3> dirs = makeDirections(count, 3);
        double closest = 4.0;
        for (size_t i = 0; i < dirs.size(); ++i) {
            for (size_t j = i + 1; j < dirs.size(); ++j) {
                const glm::dvec3 a(dirs[i]), b(dirs[j]);
                closest = std::min({closest, glm::length(a - b), glm::length(a + b)});
            }
        }
        // a spherical Fibonacci set keeps neighbours ~sqrt(2 pi / count) apart;
        // across the equator the z bands alone keep them >= 2 / count apart
        EXPECT_GT(closest, 1.0 / count) << "count " << count;
    }
}

TEST(Directions, SymmetrisedSetIsUniform) {
    // over {+-d}, the mean of |n.d| is 1/2 for every normal n
    const std::vector<glm::vec3> dirs = makeDirections(256, 12345);
    HashStream u{99};
    for (int k = 0; k < 32; ++k) {
        const glm::dvec3 n = randomUnit(u);
        // 2% of 1/2; measured worst over 50 seeds: 0.0017
        EXPECT_NEAR(meanAbsCos(dirs, 0, dirs.size(), n), 0.5, 0.01) << "normal " << k;
    }
    for (const glm::dvec3& n : {glm::dvec3(0, 0, 1), glm::dvec3(1, 0, 0), glm::dvec3(0, -1, 0)})
        EXPECT_NEAR(meanAbsCos(dirs, 0, dirs.size(), n), 0.5, 0.01);
    // and the first moment of the set folded onto any hemisphere is (1/2) a
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 a = randomUnit(u);
        glm::dvec3 mean(0.0);
        for (const glm::vec3& d : dirs) {
            const glm::dvec3 dd(d);
            mean += glm::dot(dd, a) >= 0.0 ? dd : -dd;
        }
        mean /= double(dirs.size());
        EXPECT_LT(glm::length(mean - 0.5 * a), 0.02) << "axis " << k;
    }
}

TEST(Directions, SameSeedSameBitsOtherSeedOtherSet) {
    const std::vector<glm::vec3> a = makeDirections(256, 42);
    const std::vector<glm::vec3> b = makeDirections(256, 42);
    const std::vector<glm::vec3> c = makeDirections(256, 43);
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].x, b[i].x);
        EXPECT_EQ(a[i].y, b[i].y);
        EXPECT_EQ(a[i].z, b[i].z);
    }
    double largest = 0.0;
    for (size_t i = 0; i < a.size(); ++i) largest = std::max(largest, double(glm::length(a[i] - c[i])));
    EXPECT_GT(largest, 0.1);
}

// Every second direction from `first` (0 or 1): one of the two replicates.
std::vector<glm::vec3> replicate(const std::vector<glm::vec3>& dirs, size_t first) {
    std::vector<glm::vec3> out;
    for (size_t i = first; i < dirs.size(); i += 2) out.push_back(dirs[i]);
    return out;
}

TEST(Directions, EachReplicateIsARotationOfOneOrderedSetAndTheTwoAreIndependent) {
    // a rotation keeps every dot product, and the order does not depend on the seed
    const std::vector<glm::vec3> a = makeDirections(128, 1);
    for (uint64_t seed : {2ull, 1000ull, 0xFFFFFFFFFFFFFFFFull}) {
        const std::vector<glm::vec3> b = makeDirections(128, seed);
        for (size_t r : {0u, 1u}) {
            const std::vector<glm::vec3> ra = replicate(a, r), rb = replicate(b, r);
            for (size_t i = 0; i < ra.size(); ++i)
                for (size_t j = 0; j < ra.size(); ++j)
                    ASSERT_NEAR(glm::dot(ra[i], ra[j]), glm::dot(rb[i], rb[j]), 2e-6f) << r << ": " << i << " " << j;
        }
    }
    // the two replicates are the same set under two different rotations
    const std::vector<glm::vec3> even = replicate(a, 0), odd = replicate(a, 1);
    double largest = 0.0;
    for (size_t i = 0; i < even.size(); ++i) {
        for (size_t j = 0; j < even.size(); ++j)
            ASSERT_NEAR(glm::dot(even[i], even[j]), glm::dot(odd[i], odd[j]), 2e-6f) << i << " " << j;
        largest = std::max(largest, double(glm::length(even[i] - odd[i])));
    }
    EXPECT_GT(largest, 0.1);
}

// RMS over many axes a of |mean of the run folded onto a's hemisphere - a/2|:
// how far the run's centroid is from a uniform set's (i.i.d.: sqrt(3/4 / n)).
double rmsFoldedMeanError(const std::vector<glm::vec3>& dirs, size_t begin, size_t end) {
    HashStream u{31};
    double sum2 = 0.0;
    const int axes = 200;
    for (int k = 0; k < axes; ++k) {
        const glm::dvec3 a = randomUnit(u);
        glm::dvec3 mean(0.0);
        for (size_t i = begin; i < end; ++i) {
            const glm::dvec3 d(dirs[i]);
            mean += glm::dot(d, a) >= 0.0 ? d : -d;
        }
        mean /= double(end - begin);
        sum2 += glm::dot(mean - 0.5 * a, mean - 0.5 * a);
    }
    return std::sqrt(sum2 / axes);
}

TEST(Directions, EveryAlignedRunIsStratified) {
    // Each aligned run of a 256-set (a prefix is one) must beat i.i.d. uniform
    // directions, whose RMS errors are sqrt(1/12 / n) (cosine) and sqrt(3/4 / n)
    // (folded mean). Measured worst ratios over 50 seeds: cosine 0.43, 0.53,
    // 0.35, 0.08 and folded mean 0.55, 0.65, 0.44, 0.26 for runs of 16, 32, 64,
    // 128; the van der Corput order stratifies z exactly, azimuth less so.
    // (each replicate: a 256-set of 512 directions)
    const std::vector<glm::vec3> all = makeDirections(512, 2024);
    for (size_t r : {0u, 1u}) {
        const std::vector<glm::vec3> dirs = replicate(all, r);
        for (size_t run : {16u, 32u, 64u, 128u}) {
            const double iidCosine = std::sqrt(1.0 / 12.0 / double(run));
            const double iidFolded = std::sqrt(0.75 / double(run));
            for (size_t begin = 0; begin < dirs.size(); begin += run) {
                EXPECT_LT(rmsCosineError(dirs, begin, begin + run), 0.65 * iidCosine)
                    << "run [" << begin << ", " << begin + run << ")";
                EXPECT_LT(rmsFoldedMeanError(dirs, begin, begin + run), 0.8 * iidFolded)
                    << "run [" << begin << ", " << begin + run << ")";
            }
        }
        // half the set is already nearly as good as the whole
        EXPECT_LT(rmsCosineError(dirs, 0, 128), 0.2 * std::sqrt(1.0 / 12.0 / 128.0));
        EXPECT_LT(rmsCosineError(dirs, 0, 256), 0.1 * std::sqrt(1.0 / 12.0 / 256.0));
    }
}

TEST(Directions, OrthonormalBasisIsRightHanded) {
    // the poles, the axes (one with z = -0), near-poles, random and bundle directions
    std::vector<glm::vec3> ds = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {1, 0, -0.0f}};
    ds.push_back(glm::normalize(glm::vec3(1e-4f, 0, -1)));
    ds.push_back(glm::normalize(glm::vec3(0, -1e-4f, 1)));
    ds.push_back(glm::normalize(glm::vec3(1e-7f, 1e-7f, -1)));
    HashStream u{8};
    for (int i = 0; i < 10000; ++i) ds.push_back(glm::vec3(randomUnit(u)));
    for (const glm::vec3& d : makeDirections(256, 5)) ds.push_back(d);
    for (const glm::vec3& d : ds) {
        glm::vec3 a, b;
        orthonormalBasis(d, a, b);
        EXPECT_NEAR(glm::length(a), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::length(b), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(a, b), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(a, d), 0.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(b, d), 0.0f, 1e-5f);
        EXPECT_LT(glm::length(glm::cross(a, b) - d), 1e-5f) << d.x << " " << d.y << " " << d.z;
    }
}

}  // namespace
}  // namespace bb
