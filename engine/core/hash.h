// 64-bit integer hashing for seeded, order-independent random numbers on the
// CPU: the splitmix64 finalizer (Steele, Lea, Flood 2014) and its chaining.
#pragma once

#include <cstdint>

namespace bb {

inline uint64_t mix64(uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}
inline uint64_t hash(uint64_t a, uint64_t b) { return mix64(a ^ mix64(b)); }
inline uint64_t hash(uint64_t a, uint64_t b, uint64_t c) { return hash(hash(a, b), c); }
// [0, 1) with 53 bits from a hash's high bits
inline double unitFromHash(uint64_t h) { return double(h >> 11) * 0x1.0p-53; }

// splitmix64 (Steele, Lea, Flood 2014): a small seeded stream.
struct SplitMix64 {
    uint64_t state;
    uint64_t next() {
        const uint64_t z = mix64(state);  // the finalizer of state + the golden gamma
        state += 0x9E3779B97F4A7C15ull;
        return z;
    }
    // [0, 1) with 53 bits
    double uniform() { return unitFromHash(next()); }
    // [0, 1) with 24 bits (a float's, never rounded up to 1)
    float uniformFloat() { return float(next() >> 40) * 0x1.0p-24f; }
};

}  // namespace bb
