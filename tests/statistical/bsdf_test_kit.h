#pragma once
// Pieces the BSDF test programs share: directions by angle, a named (material, wo) case for the
// parameterised lobe tests, and the mean of a Monte Carlo estimator with its standard error.

#include <algorithm>
#include <cmath>
#include <string>

#include "raytrace_core/scene/material.h"
#include "raytrace_core/util/math.h"

namespace gilt::test {

/// Unit direction at polar angle theta (radians) from +z, azimuth phi.
inline raytrace_core::Vec3 spherical(float theta, float phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

/// One lobe to test: a material seen from wo, named for the test's parameter.
struct LobeCase {
  std::string name;
  raytrace_core::scene::Material material;
  raytrace_core::Vec3 wo;
};

struct MeanEstimate {
  double mean = 0.0, standard_error = 0.0;
};

/// Mean of n draws of `draw` (returning double) and its standard error from their own spread.
template <class Draw>
MeanEstimate estimate_mean(int n, const Draw& draw) {
  double sum = 0.0, sum_sq = 0.0;
  for (int k = 0; k < n; ++k) {
    const double w = draw();
    sum += w;
    sum_sq += w * w;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, (sum_sq / n - mean * mean) / (n - 1)))};
}

}  // namespace gilt::test
