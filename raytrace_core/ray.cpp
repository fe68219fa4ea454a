// Self-intersection policy: offset along the geometric normal by the rounding-error bound of the
// point (Pharr, Jakob & Humphreys, PBRT 3rd ed. §3.9.5).

#include "raytrace_core/ray.h"

#include <cmath>

namespace gilt::raytrace_core {

Vec3 offset_ray_origin(const SurfacePoint& sp, const Vec3& w) {
  const float d = glm::dot(abs(sp.ng), sp.p_error);
  Vec3 offset = d * sp.ng;
  if (glm::dot(w, sp.ng) < 0.0f) offset = -offset;
  Vec3 po = sp.p + offset;
  // The sum above was rounded; step one more float away so po is strictly past the error bound.
  for (int i = 0; i < 3; ++i) {
    if (offset[i] > 0.0f) po[i] = std::nextafter(po[i], kInfinity);
    else if (offset[i] < 0.0f) po[i] = std::nextafter(po[i], -kInfinity);
  }
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

}  // namespace gilt::raytrace_core
