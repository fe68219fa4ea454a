// GGX distribution and visible-normal sampling; see microfacet.h for the formulas and sources.

#include "raytrace_core/scene/microfacet.h"

namespace gilt::raytrace_core::scene {

GgxDistribution::GgxDistribution(float alpha)
    : alpha_(alpha >= kMinGgxAlpha ? std::min(alpha, 1.0f) : (alpha < kMinGgxAlpha ? kMinGgxAlpha : 1.0f)) {}

float GgxDistribution::d(const Vec3& h) const {
  if (!(h.z > 0.0f)) return 0.0f;
  // D = α² / (π (α² cos²θ + sin²θ)²): the same function as in the header, without tan θ, so
  // finite at every cos θ > 0. sin²θ is taken from x and y rather than as 1 − cos²θ, which near
  // the pole (where a smooth lobe peaks) would cancel to a few bits.
  const float a2 = alpha_ * alpha_;
  const float denom = a2 * h.z * h.z + (h.x * h.x + h.y * h.y);
  return a2 / (kPi * denom * denom);
}

float GgxDistribution::lambda(const Vec3& w) const {
  const float cos2 = w.z * w.z;
  if (cos2 == 0.0f) return kInfinity;
  const float sin2 = std::max(0.0f, w.x * w.x + w.y * w.y);
  const float alpha2_tan2 = alpha_ * alpha_ * sin2 / cos2;
  return 0.5f * (std::sqrt(1.0f + alpha2_tan2) - 1.0f);
}

float GgxDistribution::visible_d(const Vec3& wo, const Vec3& h) const {
  if (!(wo.z > 0.0f)) return 0.0f;
  const float cos_oh = glm::dot(wo, h);
  if (!(cos_oh > 0.0f)) return 0.0f;
  return g1(wo) * cos_oh * d(h) / wo.z;
}

Vec3 GgxDistribution::sample_visible(const Vec3& wo, Vec2 u) const {
  // Stretch: in the α = 1 configuration the visible normals are those of a hemisphere.
  const Vec3 v = glm::normalize(Vec3(alpha_ * wo.x, alpha_ * wo.y, wo.z));
  // An orthonormal basis (t1, t2, v); any t1 ⊥ v serves when v is the pole.
  const float len2 = v.x * v.x + v.y * v.y;
  const Vec3 t1 = len2 > 0.0f ? Vec3(-v.y, v.x, 0.0f) / std::sqrt(len2) : Vec3(1.0f, 0.0f, 0.0f);
  const Vec3 t2 = glm::cross(v, t1);
  // A uniform point on the unit disk, its t2 coordinate squeezed into the part of the disk that
  // is the projection of the visible half of the hemisphere.
  const float r = std::sqrt(u.x);
  const float phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + v.z);
  p2 = (1.0f - s) * safe_sqrt(1.0f - p1 * p1) + s * p2;
  // Lift onto the hemisphere, then unstretch back to roughness α.
  const Vec3 n_h = p1 * t1 + p2 * t2 + safe_sqrt(1.0f - p1 * p1 - p2 * p2) * v;
  return glm::normalize(Vec3(alpha_ * n_h.x, alpha_ * n_h.y, std::max(1e-6f, n_h.z)));
}

}  // namespace gilt::raytrace_core::scene
