#pragma once
// Random numbers seeded per pixel sample (or per photon, per patch) from one global seed, so
// that every result is identical for any thread count and any scheduling of the work.

#include <algorithm>
#include <cstdint>

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::util {

/// SplitMix64 finaliser: a bijective 64-bit hash used to derive independent seeds.
constexpr uint64_t mix64(uint64_t x) {
  x += 0x9e3779b97f4a7c15ull;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
  return x ^ (x >> 31);
}

/// PCG32 generator (O'Neill 2014): 64-bit state, 32-bit output, selectable stream.
class Rng {
 public:
  /// Generator for one unit of work: `seed` is the user's global seed, `key` identifies the work
  /// item (e.g. pixel index), `index` its repetition (e.g. sample number).
  static Rng for_item(uint64_t seed, uint64_t key, uint64_t index) {
    return Rng(mix64(seed ^ mix64(key)), mix64(index + 0x632be59bd9b4e019ull * (seed + 1)));
  }

  Rng(uint64_t state_seed = 0x853c49e6748fea9bull, uint64_t stream = 0xda3e39cb94b95bdbull) {
    inc_ = (stream << 1u) | 1u;
    state_ = 0;
    next_u32();
    state_ += state_seed;
    next_u32();
  }

  /// Uniform 32-bit integer.
  uint32_t next_u32() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31u));
  }
  /// Uniform float in [0, 1).
  float uniform() { return std::min(kOneMinusEpsilon, static_cast<float>(next_u32()) * 0x1p-32f); }
  /// Two uniform floats in [0, 1)².
  Vec2 uniform2() {
    const float a = uniform();
    return {a, uniform()};
  }

 private:
  uint64_t state_ = 0, inc_ = 0;
};

}  // namespace gilt::raytrace_core::util
