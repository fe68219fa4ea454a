#pragma once
// Owen-scrambled Sobol points by hashing (Burley 2020, "Practical Hash-based Owen Scrambling",
// JCGT 9(4)). Only the first two Sobol dimensions are used: every 2D request of a sampler takes
// them afresh, with the point index itself Owen-scrambled ("shuffled") by a seed of its own, so
// that each pair is a (0,2)-sequence and the pairs are independent of one another (Burley's
// padding, the same idea as pbrt-v4's PaddedSobolSampler, built here without its 1024-dimension
// table). Everything is 32-bit integer arithmetic; a scrambled point is a function of its index
// and seeds alone.

#include <cstdint>

namespace gilt::raytrace_core::util::sobol {

/// The bits of x in reverse order (a byte swap, then the bits within each byte).
constexpr uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}

/// A bijection of 32-bit words in which each output bit depends only on the input bits at or
/// below it (Laine & Karras 2011; the constants are Burley's). Applied to bit-reversed digits,
/// it permutes every digit by a function of the digits above it, as Owen scrambling does.
constexpr uint32_t laine_karras(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}

/// Owen scrambling of a 32-digit binary fraction x / 2³² (most significant digit first).
constexpr uint32_t owen_scramble(uint32_t x, uint32_t seed) { return reverse_bits(laine_karras(reverse_bits(x), seed)); }

/// Sobol dimension 0 (the van der Corput sequence) of point `index`, as a 32-digit fraction.
constexpr uint32_t dimension0(uint32_t index) { return reverse_bits(index); }

namespace detail {
/// Sobol dimension 1's generator matrix is Pascal's triangle mod 2: the column of index bit k is
/// the column before it XOR-ed with itself shifted one digit right, starting from digit 1.
/// table[b][v] is the XOR of the columns of the bits set in v, placed as byte b of the index.
struct Dimension1Table {
  uint32_t table[4][256] = {};
  constexpr Dimension1Table() {
    uint32_t column[32] = {};
    column[0] = 0x80000000u;
    for (int k = 1; k < 32; ++k) column[k] = column[k - 1] ^ (column[k - 1] >> 1);
    for (int b = 0; b < 4; ++b)
      for (uint32_t v = 0; v < 256; ++v)
        for (int k = 0; k < 8; ++k)
          if (v & (1u << k)) table[b][v] ^= column[8 * b + k];
  }
};
inline constexpr Dimension1Table kDimension1{};
}  // namespace detail

/// Sobol dimension 1 of point `index`, by a table per byte of the index.
constexpr uint32_t dimension1(uint32_t index) {
  const auto& t = detail::kDimension1.table;
  return t[0][index & 0xffu] ^ t[1][(index >> 8) & 0xffu] ^ t[2][(index >> 16) & 0xffu] ^ t[3][index >> 24];
}

/// 32-digit fraction to a float in [0, 1).
/// 24 digits: exact in a float, and never rounded up to 1.
inline float to_unit_float(uint32_t x) { return float(x >> 8) * 0x1p-24f; }

}  // namespace gilt::raytrace_core::util::sobol
