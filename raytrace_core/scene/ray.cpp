// Self-intersection policy: offset along the geometric normal by the rounding-error bound of the
// point (Pharr, Jakob & Humphreys, PBRT 3rd ed. §3.9.5).

#include "raytrace_core/scene/ray.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace gilt::raytrace_core::scene {

namespace {

/// Next float in direction `up`, skipping subnormals: Embree (and CPUs in flush-to-zero mode)
/// read a subnormal origin as zero, which would put the origin back on the surface.
float step_off(float x, bool up) {
  const float next = std::nextafter(x, up ? kInfinity : -kInfinity);
  if (std::fabs(next) < std::numeric_limits<float>::min()) return up ? std::numeric_limits<float>::min() : -std::numeric_limits<float>::min();
  return next;
}

}  // namespace

Vec3 offset_ray_origin(const SurfacePoint& sp, const Vec3& w) {
  // Distance along the normal: the point's error bound projected on the normal, but at least its
  // largest per-axis bound. On a plane x = 0 the x coordinate is exact and the projected bound is
  // zero, yet Embree's ray–triangle test mixes all three axes (shear and edge functions), and
  // with flush-to-zero arithmetic an origin a few ulps off such a plane reports a hit at t = −0.
  const float d = std::max(glm::dot(abs(sp.ng), sp.p_error),
                           std::max(sp.p_error.x, std::max(sp.p_error.y, sp.p_error.z)));
  const float side = glm::dot(w, sp.ng) < 0.0f ? -1.0f : 1.0f;
  const Vec3 normal = side * sp.ng;
  Vec3 po = sp.p + d * normal;
  // The sum above was rounded: step one more float along every component of the normal, so po
  // is strictly past the bound.
  for (int i = 0; i < 3; ++i)
    if (normal[i] != 0.0f) po[i] = step_off(po[i], normal[i] > 0.0f);
  return po;
}

Ray spawn_shadow_ray(const SurfacePoint& from, const SurfacePoint& to) {
  const Vec3 origin = offset_ray_origin(from, to.p - from.p);
  const Vec3 target = offset_ray_origin(to, origin - to.p);
  return {origin, target - origin, 1.0f - kShadowEpsilon};
}

Ray spawn_shadow_ray(const SurfacePoint& from, const Vec3& to) {
  const Vec3 origin = offset_ray_origin(from, to - from.p);
  return {origin, to - origin, 1.0f - kShadowEpsilon};
}

}  // namespace gilt::raytrace_core::scene
