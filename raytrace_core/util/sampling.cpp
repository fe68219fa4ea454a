// Warping functions from the unit square.
//   Concentric disk: Shirley & Chiu 1997, "A Low Distortion Map Between Disk and Square".
//   Cosine hemisphere: Malley's method (project the uniform disk up onto the hemisphere),
//     see Pharr, Jakob & Humphreys, "Physically Based Rendering", 4th ed., §A.5.3.
//   Triangle: Heitz 2019, "A Low-Distortion Map Between Triangle and Square".

#include "raytrace_core/util/sampling.h"

#include <algorithm>

namespace gilt::raytrace_core::util {

Vec2 sample_uniform_disk(Vec2 u) {
  // Map to [-1, 1]², then send each concentric square to the circle of the same "radius"; the
  // wedge between the diagonals maps linearly in angle, which keeps area ratios.
  const float a = 2.0f * u.x - 1.0f;
  const float b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r, phi;
  if (std::fabs(a) > std::fabs(b)) {
    r = a;
    phi = (0.25f * kPi) * (b / a);
  } else {
    r = b;
    phi = 0.5f * kPi - (0.25f * kPi) * (a / b);
  }
  return {r * std::cos(phi), r * std::sin(phi)};
}

Vec3 sample_cosine_hemisphere(Vec2 u) {
  const Vec2 d = sample_uniform_disk(u);
  return {d.x, d.y, safe_sqrt(1.0f - d.x * d.x - d.y * d.y)};
}

Vec3 sample_uniform_sphere(Vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = safe_sqrt(1.0f - z * z);
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

Vec3 sample_uniform_cone(Vec2 u, float cos_max) {
  // cos θ is uniform in [cos_max, 1]. Work with 1 − cos θ directly so that narrow cones keep
  // their precision: sin²θ = (1 − cos θ)(1 + cos θ).
  const float one_minus_cos = u.x * (1.0f - cos_max);
  const float cos_theta = 1.0f - one_minus_cos;
  const float sin_theta = safe_sqrt(one_minus_cos * (2.0f - one_minus_cos));
  const float phi = 2.0f * kPi * u.y;
  return {sin_theta * std::cos(phi), sin_theta * std::sin(phi), cos_theta};
}

Vec2 sample_uniform_triangle(Vec2 u) {
  // Heitz's map: the square's two halves (split by its diagonal) are sheared onto the two halves
  // of the triangle split by its median, each with constant Jacobian 1/2.
  float b1, b2;
  if (u.x < u.y) {
    b1 = 0.5f * u.x;
    b2 = u.y - b1;
  } else {
    b2 = 0.5f * u.y;
    b1 = u.x - b2;
  }
  return {b1, b2};
}

Distribution1D::Distribution1D(std::span<const float> weights) {
  weights_.resize(weights.size());
  cdf_.resize(weights.size());
  // Accumulate in double so that long lists of small weights keep their share of the CDF.
  // Negative and non-finite weights are treated as zero.
  double sum = 0.0;
  for (size_t i = 0; i < weights.size(); ++i) {
    const float w = weights[i];
    weights_[i] = (std::isfinite(w) && w > 0.0f) ? w : 0.0f;
    sum += weights_[i];
    cdf_[i] = sum;
  }
  total_ = static_cast<float>(sum);
  if (!(sum > 0.0) || !std::isfinite(total_)) {
    total_ = 0.0f;  // empty: size() == 0
    return;
  }
  for (double& c : cdf_) c /= sum;
  // The last non-zero entry ends at exactly 1 (same partial sum divided by itself), so that every
  // u < 1 lands on an entry with weight. Trailing zero entries share the value 1 and are skipped.
}

uint32_t Distribution1D::sample(float u) const {
  if (size() == 0) return 0;
  // First entry whose CDF exceeds u. Zero-weight entries repeat the previous CDF value, so they
  // are never the first to exceed it.
  const auto it = std::upper_bound(cdf_.begin(), cdf_.end(), static_cast<double>(u));
  if (it == cdf_.end()) {
    // u ≥ 1 (outside the contract): return the last entry with weight.
    size_t i = weights_.size();
    while (i > 0 && weights_[i - 1] == 0.0f) --i;
    return static_cast<uint32_t>(i - 1);
  }
  return static_cast<uint32_t>(it - cdf_.begin());
}

uint32_t Distribution1D::sample(float u, float& remapped) const {
  const uint32_t i = sample(u);
  remapped = 0.0f;
  if (size() == 0) return i;
  const double lo = i > 0 ? cdf_[i - 1] : 0.0, width = cdf_[i] - lo;
  remapped = width > 0.0 ? std::clamp(float((double(u) - lo) / width), 0.0f, kOneMinusEpsilon) : 0.0f;
  return i;
}

}  // namespace gilt::raytrace_core::util
