#include "raytrace_core/util/spherical_triangle.h"

#include <algorithm>
#include <cmath>

namespace gilt::raytrace_core::util {
namespace {

/// The component of `v` orthogonal to unit `w`, normalised (zero when v is along w).
DVec3 orthogonal_unit(const DVec3& v, const DVec3& w) {
  const DVec3 o = v - glm::dot(v, w) * w;
  const double len = glm::length(o);
  return len > 0.0 ? o / len : DVec3(0.0);
}

}  // namespace

double triangle_solid_angle(const DVec3& a, const DVec3& b, const DVec3& c) {
  // Van Oosterom & Strackee (1983), for unit a, b, c: tan(Ω/2) = |a·(b×c)| / (1 + a·b + b·c + c·a).
  const double numerator = std::abs(glm::dot(a, glm::cross(b, c)));
  const double denominator = 1.0 + glm::dot(a, b) + glm::dot(b, c) + glm::dot(c, a);
  return 2.0 * std::atan2(numerator, denominator);
}

std::optional<SphericalTriangle> SphericalTriangle::from(const DVec3& p, const DVec3& a, const DVec3& b,
                                                         const DVec3& c) {
  const DVec3 da = a - p, db = b - p, dc = c - p;
  const double la = glm::length(da), lb = glm::length(db), lc = glm::length(dc);
  if (!(la > 0.0) || !(lb > 0.0) || !(lc > 0.0)) return std::nullopt;
  SphericalTriangle t;
  t.a_ = da / la, t.b_ = db / lb, t.c_ = dc / lc;
  // A point in the triangle's plane sees it as an arc, with no area.
  if (std::abs(glm::dot(t.a_, glm::cross(t.b_, t.c_))) < 1e-12) return std::nullopt;
  // The angle α at a, between the planes through the origin that hold the arcs to b and to c, by
  // its cosine and sine (no inverse trigonometry: the construction needs only these).
  const DVec3 n_ab = glm::cross(t.a_, t.b_), n_ac = glm::cross(t.a_, t.c_);
  const double l_ab = glm::length(n_ab), l_ac = glm::length(n_ac);
  if (!(l_ab > 0.0) || !(l_ac > 0.0)) return std::nullopt;
  t.cos_alpha_ = std::clamp(glm::dot(n_ab, n_ac) / (l_ab * l_ac), -1.0, 1.0);
  t.sin_alpha_ = std::min(1.0, glm::length(glm::cross(n_ab, n_ac)) / (l_ab * l_ac));
  // The area by Van Oosterom & Strackee rather than as the excess α + β + γ − π: one atan2 for two
  // acos, and no digits lost to the subtraction when the triangle is small.
  t.area_ = triangle_solid_angle(t.a_, t.b_, t.c_);
  if (!(t.area_ > 0.0) || !std::isfinite(t.area_)) return std::nullopt;
  t.cos_c_ = glm::dot(t.a_, t.b_);
  return t;
}

DVec3 SphericalTriangle::sample(Vec2 u) const {
  // Arvo's construction: the sub-triangle (a, b, ĉ) with ĉ on the arc from a to c has area
  // u.x·Ω; the direction is then uniform in that sub-triangle's edge from b to ĉ, as far along
  // the arc from b as u.y says (in 1 − cos of the arc length, which makes it uniform in area).
  const double sub_area = double(u.x) * area_;
  const double sin_sub = std::sin(sub_area), cos_sub = std::cos(sub_area);
  const double sin_alpha = sin_alpha_, cos_alpha = cos_alpha_;
  // sin and cos of (sub_area − α).
  const double s = sin_sub * cos_alpha - cos_sub * sin_alpha, t = cos_sub * cos_alpha + sin_sub * sin_alpha;
  const double uu = t - cos_alpha, vv = s + sin_alpha * cos_c_;
  const double denominator = (vv * s + uu * t) * sin_alpha;
  double q = denominator != 0.0 ? ((vv * t - uu * s) * cos_alpha - vv) / denominator : 1.0;
  q = std::clamp(q, -1.0, 1.0);
  // ĉ: at cosine q from a, on the great circle through a and c.
  const DVec3 c_hat = q * a_ + std::sqrt(std::max(0.0, 1.0 - q * q)) * orthogonal_unit(c_, a_);
  // Along the arc from b towards ĉ.
  const double z = 1.0 - double(u.y) * (1.0 - glm::dot(c_hat, b_));
  const DVec3 w = z * b_ + std::sqrt(std::max(0.0, 1.0 - z * z)) * orthogonal_unit(c_hat, b_);
  return glm::normalize(w);
}

}  // namespace gilt::raytrace_core::util
