// The CPU reference's own random numbers: PCG32 (O'Neill 2014), one stream per pixel and frame.
// Deliberately not the GPU's counter-based generator (shaders/shared/rng.h): the reference
// shares no sampling code with the GPU path beyond phase functions and light math (DESIGN §1).
#pragma once

#include <cstdint>

namespace plume::ref {

class Pcg32 {
 public:
  Pcg32(uint64_t seed, uint64_t stream) : state_(0), inc_((stream << 1u) | 1u) {
    nextUint();
    state_ += seed;
    nextUint();
  }
  uint32_t nextUint() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform in [0, 1).
  float uniform() { return float(nextUint() >> 8) * (1.0f / 16777216.0f); }

 private:
  uint64_t state_;
  uint64_t inc_;
};

// SplitMix64 finaliser, to derive independent seeds from (seed, frame, pixel).
inline uint64_t mix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ULL;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
  return x ^ (x >> 31);
}

}  // namespace plume::ref
