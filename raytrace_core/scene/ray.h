#pragma once
// Rays and the single self-intersection policy shared by every algorithm in gilt.
//
// Hit points are reconstructed from barycentrics (triangles) or reprojected onto the surface in
// double precision (spheres), together with a conservative bound on their rounding error. A new
// ray starts at the point pushed along the geometric normal just past that error bound, then one
// float further (Pharr, Jakob & Humphreys, "Physically Based Rendering", 3rd/4th ed., §3.9 / §6.8).
// The bound scales with the coordinates, so the policy holds at any scene scale or offset,
// unlike a fixed epsilon.

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::scene {

/// A ray origin + t·direction for t in (0, tmax]. The direction need not be normalised.
struct Ray {
  Vec3 origin{0.0f};
  Vec3 direction{0.0f, 0.0f, 1.0f};
  float tmax = kInfinity;
  /// Angle by which a cone around the ray widens per unit distance: a camera ray carries its
  /// pixel's, so that a hit knows the pixel's footprint there (ray cones, Akenine-Möller et al.
  /// 2019, "Texture Level of Detail Strategies for Real-Time Ray Tracing"), and a ray that
  /// continues a camera path carries it on (continue_ray, scene.h). 0 for other rays.
  float spread = 0.0f;
  /// The cone's width at the origin: 0 at the camera's pinhole, the width the cone had reached
  /// at the surface a continued ray leaves.
  float width = 0.0f;
};

/// A point on a surface with the bound on its rounding error and its geometric normal.
struct SurfacePoint {
  Vec3 p{0.0f};
  Vec3 p_error{0.0f};  ///< per-axis absolute error bound of p
  Vec3 ng{0.0f, 0.0f, 1.0f};  ///< unit geometric normal (front side = counter-clockwise winding)
};

/// p moved off its surface to the side of the geometric normal that w points into.
Vec3 offset_ray_origin(const SurfacePoint& sp, const Vec3& w);

/// Ray leaving the surface point in direction `direction`, free of self-intersection.
inline Ray spawn_ray(const SurfacePoint& from, const Vec3& direction) {
  return {offset_ray_origin(from, direction), direction, kInfinity};
}

/// Relative shortening of shadow rays that end on a surface (pbrt-v4's ShadowEpsilon).
inline constexpr float kShadowEpsilon = 1e-4f;

/// Shadow ray between two surface points, offset at both ends; occluded() on it tests visibility.
Ray spawn_shadow_ray(const SurfacePoint& from, const SurfacePoint& to);
/// Shadow ray from a surface point to a point not on a surface (a point or spot light).
Ray spawn_shadow_ray(const SurfacePoint& from, const Vec3& to);
/// Shadow ray from a surface point towards a light at infinity in direction `direction`.
inline Ray spawn_shadow_ray_to_infinity(const SurfacePoint& from, const Vec3& direction) {
  return spawn_ray(from, direction);
}

}  // namespace gilt::raytrace_core::scene
