#pragma once
// The random numbers of one camera sample. The independent sampler draws them from a PCG stream;
// the Sobol sampler (the default) draws the first dimensions of the path from an Owen-scrambled
// Sobol sequence over the pixel's samples, so that n samples of a pixel cover the film, lens,
// light and BSDF squares far more evenly than n independent points do (the error of a smooth
// 2D integrand falls as n^-1.5 rather than n^-0.5 in RMS; Owen 1997), with no structured
// artefacts, since every pixel has scrambles of its own.
//
// A camera sample asks for 1D or 2D values in order. Dimension k is the k-th request; methods
// call start_bounce(depth) at each vertex, so request j of bounce d always lands in dimension
// kCameraDimensions + d·kBounceDimensions + j whatever happened before it. Past kSobolBounces
// bounces, or past kBounceDimensions requests in a bounce, the values come from the PCG stream:
// by then the path's contribution is small and its integrand high-dimensional. On the Cornell
// box a sample's relMSE was the same with Sobol points for 3 or 4 vertices and about 7 % higher
// with 2, while each 2D request costs about 12 ns (bench/README.md, "The Sobol sampler").

#include <cstdint>
#include <string>

#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sobol.h"

namespace gilt::raytrace_core::render {

enum class SamplerKind : uint8_t { independent, sobol };

/// Sampler kind from its name ("independent", "sobol"); throws InputError otherwise.
SamplerKind parse_sampler(const std::string& name);
/// The name parse_sampler reads.
const char* sampler_name(SamplerKind kind);

class Sampler {
 public:
  static constexpr uint32_t kCameraDimensions = 2;   ///< film position, lens position
  static constexpr uint32_t kBounceDimensions = 6;   ///< requests per path vertex
  static constexpr uint32_t kSobolBounces = 3;       ///< vertices that get Sobol dimensions

  /// Independent values from `rng`.
  explicit Sampler(util::Rng rng) : rng_(rng) {}

  /// Sample `index` of pixel `pixel` under the global `seed`. The independent kind and the
  /// fallback past the Sobol dimensions use Rng::for_item(seed, pixel, index).
  static Sampler for_pixel_sample(SamplerKind kind, uint64_t seed, uint64_t pixel, uint64_t index) {
    Sampler s(util::Rng::for_item(seed, pixel, index));
    if (kind == SamplerKind::sobol && index <= UINT32_MAX) {
      s.sobol_ = true;
      s.reversed_index_ = util::sobol::reverse_bits(uint32_t(index));
      s.pixel_seed_ = util::mix64(seed ^ util::mix64(pixel ^ 0x5bd1e9955bd1e995ull));
    }
    return s;
  }

  /// Moves to the dimensions of path vertex `depth` (0: the first surface the camera ray hits).
  void start_bounce(int depth) {
    dimension_ = kCameraDimensions + uint32_t(depth) * kBounceDimensions;
    bounce_end_ = dimension_ + kBounceDimensions;
  }

  /// Uniform float in [0, 1).
  float uniform() { return use_sobol() ? sobol_1d() : rng_.uniform(); }
  /// Uniform point in [0, 1)²; with Sobol, the pixel's samples of it form a (0,2)-sequence.
  Vec2 uniform2() { return use_sobol() ? sobol_2d() : rng_.uniform2(); }

  /// The independent stream (used past the Sobol dimensions).
  util::Rng& rng() { return rng_; }

  /// `count` sub-samples taken at one point of the path, such as a final gather's rays.
  class SubSamples {
   public:
    /// Sub-sample j < count. With Sobol, its requests come from point index·count + j of
    /// dimensions of the set's own (kBounceDimensions of them, then its own PCG stream), so the
    /// rays of all of a pixel's samples are stratified together, and for a power-of-two count
    /// each sample's own rays form a net too.
    Sampler operator[](uint32_t j) const {
      Sampler s(util::Rng(util::mix64(key_ + j), key_));
      if (sobol_) {
        s.sobol_ = true;
        s.reversed_index_ = util::sobol::reverse_bits(first_ + j);
        s.pixel_seed_ = key_;
        s.bounce_end_ = kBounceDimensions;
      }
      return s;
    }

   private:
    friend class Sampler;
    uint64_t key_ = 0;
    uint32_t first_ = 0;
    bool sobol_ = false;
  };
  /// A set of `count` sub-samples; uses up one dimension of this sampler.
  SubSamples split(uint32_t count) {
    SubSamples set;
    const uint32_t index = util::sobol::reverse_bits(reversed_index_);
    if (use_sobol() && count > 0 && index <= (UINT32_MAX - count) / count) {
      set.sobol_ = true;
      set.key_ = dimension_seed();
      set.first_ = index * count;
    } else {
      set.key_ = util::mix64(uint64_t(rng_.next_u32()) << 32 | rng_.next_u32());
      if (sobol_) ++dimension_;
    }
    return set;
  }

 private:
  bool use_sobol() const {
    return sobol_ && dimension_ < bounce_end_ && dimension_ < kCameraDimensions + kSobolBounces * kBounceDimensions;
  }
  float sobol_1d();
  Vec2 sobol_2d();
  /// Seeds of the current dimension, which the call then uses up.
  uint64_t dimension_seed() { return util::mix64(pixel_seed_ + 0x9e3779b97f4a7c15ull * (dimension_++ + 1)); }
  /// The point index, Owen-scrambled as a base-2 integer (Burley's shuffle), from its reversal.
  uint32_t shuffled_index(uint32_t seed) const { return util::sobol::reverse_bits(util::sobol::laine_karras(reversed_index_, seed)); }
  /// owen_scramble(dimension0(i)): dimension 0 is the reversal of i, which the scramble undoes.
  static uint32_t scrambled_dimension0(uint32_t i, uint32_t seed) { return util::sobol::reverse_bits(util::sobol::laine_karras(i, seed)); }

  util::Rng rng_;
  bool sobol_ = false;
  uint32_t reversed_index_ = 0;  ///< the sample's index, bits reversed
  uint64_t pixel_seed_ = 0;
  uint32_t dimension_ = 0;
  uint32_t bounce_end_ = kCameraDimensions;  ///< the camera's dimensions until start_bounce
};

}  // namespace gilt::raytrace_core::render
