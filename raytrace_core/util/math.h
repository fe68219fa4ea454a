#pragma once
// Vector types, constants and the orthonormal frame used for all local-frame BSDF math.

#include <cmath>
#include <cstdint>
#include <limits>

#include <glm/glm.hpp>

namespace gilt::raytrace_core::util {

using Vec2 = glm::vec2;
using Vec3 = glm::vec3;
using DVec3 = glm::dvec3;

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kInvPi = 0.31830988618379067154f;
inline constexpr float kInv2Pi = 0.15915494309189533577f;
inline constexpr float kInv4Pi = 0.07957747154594766788f;
inline constexpr float kInfinity = std::numeric_limits<float>::infinity();
/// Largest float strictly below one: the upper end of every uniform sample.
inline constexpr float kOneMinusEpsilon = 0x1.fffffep-1f;

inline float sqr(float x) { return x * x; }
/// sqrt that treats tiny negative rounding errors as zero.
inline float safe_sqrt(float x) { return std::sqrt(std::max(0.0f, x)); }
/// Component-wise absolute value.
inline Vec3 abs(const Vec3& v) { return {std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}; }
/// True when no component is NaN or infinite.
inline bool is_finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
/// Mirror reflection of wo about the normal n (both unit, pointing away from the surface).
inline Vec3 reflect(const Vec3& wo, const Vec3& n) { return -wo + 2.0f * glm::dot(wo, n) * n; }

/// Orthonormal basis (s, t, n). Local coordinates have the normal along +z, so cos θ = w.z.
struct Frame {
  Vec3 s{1, 0, 0}, t{0, 1, 0}, n{0, 0, 1};

  /// Frame around a unit normal (Duff et al. 2017, "Building an Orthonormal Basis, Revisited").
  static Frame from_normal(const Vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    return {Vec3(1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x), Vec3(b, sign + n.y * n.y * a, -n.y), n};
  }
  /// World direction to local coordinates.
  Vec3 to_local(const Vec3& v) const { return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)}; }
  /// Local direction to world coordinates.
  Vec3 to_world(const Vec3& v) const { return v.x * s + v.y * t + v.z * n; }
};

/// Axis-aligned bounding box.
struct Bounds3 {
  Vec3 lo{kInfinity}, hi{-kInfinity};
  void extend(const Vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
  void extend(const Bounds3& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
  bool empty() const { return lo.x > hi.x; }
  /// True when the two boxes share at least a point.
  bool overlaps(const Bounds3& b) const {
    return lo.x <= b.hi.x && b.lo.x <= hi.x && lo.y <= b.hi.y && b.lo.y <= hi.y && lo.z <= b.hi.z && b.lo.z <= hi.z;
  }
  Vec3 center() const { return 0.5f * (lo + hi); }
  Vec3 diagonal() const { return hi - lo; }
  /// Radius of the bounding sphere centred on center().
  float radius() const { return empty() ? 0.0f : 0.5f * glm::length(diagonal()); }
};

}  // namespace gilt::raytrace_core::util

// The parent namespace re-exports these names (rc::Vec3, rc::Rgb, rc::InputError ...).
#include "raytrace_core/util/vocabulary.h"
