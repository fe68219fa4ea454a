// Solid-angle sampling of triangles (raytrace_core/util/spherical_triangle.h): the solid angle against
// the spherical excess (Girard's theorem), and every sampled direction inside the triangle. The
// distribution itself is chi-square tested through sample_light (tests/statistical/test_light_sampling.cpp).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/spherical_triangle.h"

namespace gilt::raytrace_core::util {
namespace {

/// The spherical excess α + β + γ − π of the triangle spanned by the directions a, b, c (Girard's
/// theorem): an independent route to the solid angle the class computes by Van Oosterom & Strackee.
double spherical_excess(const DVec3& a, const DVec3& b, const DVec3& c) {
  const auto angle = [](const DVec3& v, const DVec3& p, const DVec3& q) {
    const DVec3 n1 = glm::normalize(glm::cross(v, p)), n2 = glm::normalize(glm::cross(v, q));
    return std::acos(std::clamp(glm::dot(n1, n2), -1.0, 1.0));
  };
  const DVec3 ua = glm::normalize(a), ub = glm::normalize(b), uc = glm::normalize(c);
  return angle(ua, ub, uc) + angle(ub, uc, ua) + angle(uc, ua, ub) - 3.14159265358979323846;
}

TEST(SphericalTriangle, SolidAngleAndSamplesAgreeWithTheTriangle) {
  Rng rng(5);
  const auto point = [&](double scale) {
    return DVec3(scale * (2.0 * rng.uniform() - 1.0), scale * (2.0 * rng.uniform() - 1.0), scale * (2.0 * rng.uniform() - 1.0));
  };
  int tested = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const DVec3 p = point(1.0), a = point(2.0), b = point(2.0), c = point(2.0);
    const std::optional<SphericalTriangle> t = SphericalTriangle::from(p, a, b, c);
    if (!t) continue;
    const double omega = spherical_excess(a - p, b - p, c - p);
    // Both in double; the excess loses digits to the subtraction of π (about 1e-15 of it) and acos
    // near 0 or π loses half its digits (√ε ≈ 1e-8 of an angle): 1e-7 absolute bounds both.
    EXPECT_NEAR(t->solid_angle(), omega, 1e-7) << "trial " << trial;
    if (!samples_by_solid_angle(t->solid_angle())) continue;
    ++tested;
    // Every direction meets the triangle: barycentric coordinates of its hit on the plane within
    // [0, 1], to the rounding of a double solve (1e-9 with room).
    const DVec3 e1 = b - a, e2 = c - a;
    for (int k = 0; k < 64; ++k) {
      const DVec3 w = t->sample(rng.uniform2());
      ASSERT_NEAR(glm::length(w), 1.0, 1e-12);
      const DVec3 pv = glm::cross(w, e2), tv = p - a, qv = glm::cross(tv, e1);
      const double det = glm::dot(e1, pv);
      const double u = glm::dot(tv, pv) / det, v = glm::dot(w, qv) / det, t_hit = glm::dot(e2, qv) / det;
      EXPECT_GT(t_hit, 0.0);
      EXPECT_GE(u, -1e-9);
      EXPECT_GE(v, -1e-9);
      EXPECT_LE(u + v, 1.0 + 1e-9);
    }
  }
  EXPECT_GT(tested, 1000);  // most random triangles subtend more than the threshold
  // A point in the triangle's plane sees no solid angle.
  EXPECT_FALSE(SphericalTriangle::from(DVec3(0.0), DVec3(1, 0, 0), DVec3(0, 1, 0), DVec3(1, 1, 0)).has_value());
}

}  // namespace
}  // namespace gilt::raytrace_core::util
