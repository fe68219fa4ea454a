// Point-to-polygon form factor (Lambert 1760; in this form, Baum, Rushmeier & Winget 1989,
// "Improving Radiosity Solutions Through the Use of Analytically Determined Form-Factors"),
// with the source clipped against the receiver's tangent plane first.

#include "radiosity/form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace gilt::radiosity {
namespace {

/// γ n·(a × b)/|a × b| for the edge from a to b (both relative to the receiver): the edge's
/// signed contribution to Lambert's sum. An edge whose line passes through the receiver
/// subtends no angle and contributes nothing.
double edge_term(const DVec3& n, const DVec3& a, const DVec3& b) {
  const DVec3 c = glm::cross(a, b);
  const double len = glm::length(c);
  if (!(len > 0.0)) return 0.0;
  return std::atan2(len, glm::dot(a, b)) * glm::dot(n, c) / len;
}

}  // namespace

double point_to_polygon_form_factor(const DVec3& p, const DVec3& n, std::span<const DVec3> polygon) {
  if (polygon.size() < 3) return 0.0;
  // Sutherland–Hodgman clip against the half-space in front of the receiver, n·(x − p) ≥ 0,
  // summing Lambert's terms over the clipped polygon's edges as its vertices come out: no
  // buffer, so any polygon, convex or not, of any size. For a polygon whose front faces p,
  // counter-clockwise seen from that front, the sum is negative.
  double sum = 0.0;
  size_t emitted = 0;
  DVec3 first(0.0), previous(0.0);
  auto emit = [&](const DVec3& x) {
    if (emitted++ == 0) first = x;
    else sum += edge_term(n, previous, x);
    previous = x;
  };
  for (size_t i = 0; i < polygon.size(); ++i) {
    const DVec3 a = polygon[i] - p, b = polygon[(i + 1) % polygon.size()] - p;
    const double da = glm::dot(n, a), db = glm::dot(n, b);
    if (da >= 0.0) emit(a);
    if ((da > 0.0 && db < 0.0) || (da < 0.0 && db > 0.0)) emit(a + (da / (da - db)) * (b - a));
  }
  if (emitted < 3) return 0.0;
  sum += edge_term(n, previous, first);
  const double f = -sum / (2.0 * 3.14159265358979323846);
  return std::clamp(f, 0.0, 1.0);
}

double point_to_triangle_form_factor(const DVec3& p, const DVec3& n, const DVec3& a, const DVec3& b, const DVec3& c) {
  const std::array<DVec3, 3> tri{a, b, c};
  return point_to_polygon_form_factor(p, n, tri);
}

SourceTriangle::SourceTriangle(const Vec3& a, const Vec3& b, const Vec3& c)
    : a_(a), b_(b), c_(c), centroid_((a + b + c) / 3.0f), twice_area_normal_(glm::cross(b - a, c - a)) {
  const float twice_area = glm::length(twice_area_normal_);
  normal_ = twice_area > 0.0f ? twice_area_normal_ / twice_area : Vec3(0.0f);
  plane_offset_ = glm::dot(normal_, a);
  for (const Vec3& v : {a, b, c}) radius_ = std::max(radius_, glm::length(v - centroid_));
  far_distance2_ = kFarFieldRatio * kFarFieldRatio * radius_ * radius_;
  const Vec3 m = (a + b + c) * (1.0f / 6.0f);
  rule_points_[0] = m + 0.5f * a;
  rule_points_[1] = m + 0.5f * b;
  rule_points_[2] = m + 0.5f * c;
}

}  // namespace gilt::radiosity
