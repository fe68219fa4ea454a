#pragma once
// Warping functions from the unit square to directions and points, with their densities.
// Each one has a chi-square test in tests/statistical/test_sampling.cpp.

#include <span>
#include <vector>

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::util {

/// Point on the unit disk, Shirley–Chiu concentric map (area-preserving, low distortion).
Vec2 sample_uniform_disk(Vec2 u);

/// Direction on the +z hemisphere with density cos θ / π (solid angle).
Vec3 sample_cosine_hemisphere(Vec2 u);
/// Density of sample_cosine_hemisphere per steradian.
inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0.0f ? cos_theta * kInvPi : 0.0f; }

/// Uniform direction on the unit sphere; density 1 / 4π.
Vec3 sample_uniform_sphere(Vec2 u);
inline float uniform_sphere_pdf() { return kInv4Pi; }

/// Uniform direction inside the cone around +z with cos θ ≥ cos_max; density 1 / (2π (1 − cos_max)).
Vec3 sample_uniform_cone(Vec2 u, float cos_max);
inline float uniform_cone_pdf(float cos_max) { return 1.0f / (2.0f * kPi * (1.0f - cos_max)); }

/// Uniformly distributed barycentrics (b1, b2) on a triangle; b0 = 1 − b1 − b2.
Vec2 sample_uniform_triangle(Vec2 u);

/// Veach's power heuristic (β = 2) for MIS weight of strategy f with nf samples against g.
inline float power_heuristic(float nf, float f_pdf, float ng, float g_pdf) {
  const float f = nf * f_pdf, g = ng * g_pdf;
  if (std::isinf(f * f)) return 1.0f;
  const float denom = f * f + g * g;
  return denom > 0.0f ? (f * f) / denom : 0.0f;
}

/// Discrete distribution proportional to non-negative weights, sampled by inversion of the CDF.
class Distribution1D {
 public:
  Distribution1D() = default;
  /// Builds from weights; all-zero weights give an empty distribution (size() == 0 samples nothing).
  explicit Distribution1D(std::span<const float> weights);

  /// Index drawn with probability pmf(index); `u` in [0, 1).
  uint32_t sample(float u) const;
  /// The same index, and in `remapped` where u fell inside its bin, stretched back to [0, 1): a
  /// second uniform for sampling within the bin.
  uint32_t sample(float u, float& remapped) const;
  /// Probability of drawing index i.
  float pmf(uint32_t i) const { return total_ > 0.0f ? weights_[i] / total_ : 0.0f; }
  /// Number of entries with any weight (0 for an empty or all-zero distribution).
  size_t size() const { return total_ > 0.0f ? weights_.size() : 0; }
  /// Sum of the weights.
  float total() const { return total_; }

 private:
  std::vector<float> weights_;
  std::vector<double> cdf_;  // cdf_[i] = sum of weights_[0..i], normalised to end at 1
  float total_ = 0.0f;
};

}  // namespace gilt::raytrace_core::util
