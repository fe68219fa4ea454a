// Point-to-polygon form factor (Lambert 1760; in this form, Baum, Rushmeier & Winget 1989,
// "Improving Radiosity Solutions Through the Use of Analytically Determined Form-Factors"),
// with the source clipped against the receiver's tangent plane first.

#include "radiosity/solver/form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace gilt::radiosity::solver {
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

double SourceTriangle::form_factor_from(const SourceTriangle& receiver, const Vec3& n) const {
  // Dunavant's degree-4 rule: barycentric (α, α, 1 − 2α) and permutations, two orbits.
  constexpr double kAlpha[2] = {0.445948490915965, 0.091576213509771};
  constexpr double kWeight[2] = {0.223381589678011, 0.109951743655322};
  double sum = 0.0;
  for (int orbit = 0; orbit < 2; ++orbit) {
    const float x = float(kAlpha[orbit]), y = float(1.0 - 2.0 * kAlpha[orbit]);
    const Vec3 points[3] = {x * receiver.a_ + x * receiver.b_ + y * receiver.c_,
                            x * receiver.a_ + y * receiver.b_ + x * receiver.c_,
                            y * receiver.a_ + x * receiver.b_ + x * receiver.c_};
    for (const Vec3& p : points) sum += kWeight[orbit] * form_factor(p, n);
  }
  return sum;
}

void SourceBatch::assign(std::span<const SourceTriangle> triangles) {
  if (triangles.size() > kMaxBatch) throw std::length_error("SourceBatch: more than kMaxBatch triangles");
  triangles_.assign(triangles.begin(), triangles.end());
  const size_t m = triangles.size();
  for (auto* v : {&tx_, &ty_, &tz_, &cx_, &cy_, &cz_, &far2_, &radius_, &nx_, &ny_, &nz_, &offset_}) v->resize(m);
  for (int j = 0; j < 3; ++j) {
    qx_[j].resize(m), qy_[j].resize(m), qz_[j].resize(m);
    vx_[j].resize(m), vy_[j].resize(m), vz_[j].resize(m);
  }
  for (size_t k = 0; k < m; ++k) {
    const SourceTriangle& t = triangles[k];
    for (int j = 0; j < 3; ++j) qx_[j][k] = t.rule_points_[j].x, qy_[j][k] = t.rule_points_[j].y, qz_[j][k] = t.rule_points_[j].z;
    const Vec3* corners[3] = {&t.a_, &t.b_, &t.c_};
    for (int j = 0; j < 3; ++j) vx_[j][k] = corners[j]->x, vy_[j][k] = corners[j]->y, vz_[j][k] = corners[j]->z;
    tx_[k] = t.twice_area_normal_.x, ty_[k] = t.twice_area_normal_.y, tz_[k] = t.twice_area_normal_.z;
    cx_[k] = t.centroid_.x, cy_[k] = t.centroid_.y, cz_[k] = t.centroid_.z;
    far2_[k] = t.far_distance2_, radius_[k] = t.radius_;
    nx_[k] = t.normal_.x, ny_[k] = t.normal_.y, nz_[k] = t.normal_.z, offset_[k] = t.plane_offset_;
  }
}

void SourceBatch::form_factors(const Vec3& p, const Vec3& n, float* out) const {
  const size_t m = triangles_.size();
  // Local copies of the array pointers and results on the stack: nothing aliases, so the loop
  // below vectorises. kind: 0 far rule applies, 1 near or straddling (exact formula), 2 the
  // receiver is behind the source.
  const float* __restrict q[9] = {qx_[0].data(), qy_[0].data(), qz_[0].data(), qx_[1].data(), qy_[1].data(),
                                  qz_[1].data(), qx_[2].data(), qy_[2].data(), qz_[2].data()};
  const float *__restrict tx = tx_.data(), *__restrict ty = ty_.data(), *__restrict tz = tz_.data();
  const float *__restrict cx = cx_.data(), *__restrict cy = cy_.data(), *__restrict cz = cz_.data();
  const float *__restrict far2 = far2_.data(), *__restrict radius = radius_.data();
  const float *__restrict snx = nx_.data(), *__restrict sny = ny_.data(), *__restrict snz = nz_.data();
  const float* __restrict offset = offset_.data();
  const float* __restrict v[9] = {vx_[0].data(), vy_[0].data(), vz_[0].data(), vx_[1].data(), vy_[1].data(),
                                  vz_[1].data(), vx_[2].data(), vy_[2].data(), vz_[2].data()};
  float value[kMaxBatch];
  int kind[kMaxBatch];
  const float px = p.x, py = p.y, pz = p.z, nx = n.x, ny = n.y, nz = n.z;
  constexpr float kScale = float(1.0 / (6.0 * 3.14159265358979323846));
  for (size_t k = 0; k < m; ++k) {
    float sum = 0.0f;
    for (int j = 0; j < 3; ++j) {
      const float dx = q[3 * j][k] - px, dy = q[3 * j + 1][k] - py, dz = q[3 * j + 2][k] - pz;
      const float r2 = dx * dx + dy * dy + dz * dz;
      const float cos_receiver = nx * dx + ny * dy + nz * dz;
      const float cos_source_scaled = -(tx[k] * dx + ty[k] * dy + tz[k] * dz);
      sum += std::max(cos_receiver, 0.0f) * std::max(cos_source_scaled, 0.0f) / (r2 * r2);
    }
    value[k] = std::min(sum * kScale, 1.0f);
    const float ex = cx[k] - px, ey = cy[k] - py, ez = cz[k] - pz;
    const int near = int(ex * ex + ey * ey + ez * ez < far2[k]) | int(nx * ex + ny * ey + nz * ez <= radius[k]);
    // Behind the source, or the source in or behind the receiver's tangent plane (as
    // in_or_behind_tangent_plane, corner by corner).
    int flat = 1;
    for (int j = 0; j < 3; ++j) {
      const float dx = v[3 * j][k] - px, dy = v[3 * j + 1][k] - py, dz = v[3 * j + 2][k] - pz;
      const float s = nx * dx + ny * dy + nz * dz;
      flat &= int(s <= 0.0f) | int(s * s <= kTangentSlope * kTangentSlope * (dx * dx + dy * dy + dz * dz));
    }
    const int behind = int(snx[k] * px + sny[k] * py + snz[k] * pz <= offset[k]) | flat;
    kind[k] = near | (behind << 1);
  }
  for (size_t k = 0; k < m; ++k)
    out[k] = kind[k] == 0 ? value[k] : (kind[k] & 2) ? 0.0f : float(triangles_[k].form_factor(p, n));
}

}  // namespace gilt::radiosity::solver
