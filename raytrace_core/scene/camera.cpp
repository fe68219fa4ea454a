// Pinhole, thin-lens and orthographic cameras.

#include "raytrace_core/scene/camera.h"

#include <algorithm>
#include <cmath>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::raytrace_core::scene {

void Camera::validate() const {
  if (!is_finite(look_from) || !is_finite(look_at) || !is_finite(up))
    throw InputError("camera: look_from, look_at and up must be finite");
  const Vec3 forward = look_at - look_from;
  if (!(glm::dot(forward, forward) > 0.0f)) throw InputError("camera: look_from and look_at coincide");
  const Vec3 side = glm::cross(forward, up);
  if (!(glm::dot(side, side) > 1e-12f * glm::dot(forward, forward) * glm::dot(up, up)))
    throw InputError("camera: up is zero or parallel to the view direction");
  if (orthographic) {
    if (!(ortho_height > 0.0f) || !std::isfinite(ortho_height))
      throw InputError("camera: an orthographic camera's height must be a finite number > 0");
    return;
  }
  if (!(vfov_degrees > 0.0f && vfov_degrees < 180.0f))
    throw InputError("camera: vertical field of view must lie in (0, 180) degrees");
  if (!(aperture_radius >= 0.0f) || !std::isfinite(aperture_radius))
    throw InputError("camera: aperture radius must be a finite number ≥ 0");
  if (!(focus_distance >= 0.0f) || !std::isfinite(focus_distance))
    throw InputError("camera: focus distance must be a finite number ≥ 0");
}

Ray Camera::generate_ray(Vec2 film, Vec2 lens, float aspect) const {
  const Vec3 w = glm::normalize(look_at - look_from);  // forward
  const Vec3 u = glm::normalize(glm::cross(w, up));     // right
  const Vec3 v = glm::cross(u, w);                      // up on the image
  if (orthographic) {
    const float half_h = 0.5f * ortho_height, half_w = half_h * aspect;
    return {look_from + (2.0f * film.x - 1.0f) * half_w * u + (1.0f - 2.0f * film.y) * half_h * v, w, kInfinity};
  }
  const float half_h = std::tan(0.5f * vfov_degrees * kPi / 180.0f);
  const float half_w = half_h * aspect;
  // Direction through the film point at unit distance in front of the pinhole.
  const Vec3 d = w + (2.0f * film.x - 1.0f) * half_w * u + (1.0f - 2.0f * film.y) * half_h * v;
  if (aperture_radius <= 0.0f) return {look_from, glm::normalize(d), kInfinity};
  const float focus = focus_distance > 0.0f ? focus_distance : glm::length(look_at - look_from);
  const Vec3 target = look_from + focus * d;  // the point on the plane of focus
  const Vec2 disk = aperture_radius * util::sample_uniform_disk(lens);
  const Vec3 origin = look_from + disk.x * u + disk.y * v;
  return {origin, glm::normalize(target - origin), kInfinity};
}

float Camera::pixel_spread(int height) const {
  if (orthographic) return 0.0f;
  return 2.0f * std::tan(0.5f * vfov_degrees * kPi / 180.0f) / float(std::max(height, 1));
}

Camera default_camera(const Bounds3& bounds, float aspect) {
  Camera c;
  if (bounds.empty()) return c;
  if (!(aspect > 0.0f) || !std::isfinite(aspect)) aspect = 1.0f;
  c.vfov_degrees = 40.0f;
  // The nearest distance along +z at which every corner of the box lies inside the frustum: a
  // corner at (±hx, ±hy, ±hz) from the centre needs (d − hz)·tan(vfov/2) ≥ hy vertically and
  // (d − hz)·tan(vfov/2)·aspect ≥ hx across; the front corners (+hz) decide. The 8 % margin
  // keeps the model off the image's edge. Framing the bounding sphere instead leaves a flat or
  // long model small in the middle of the picture.
  const Vec3 half = 0.5f * (bounds.hi - bounds.lo);
  const float tan_half = std::tan(0.5f * c.vfov_degrees * kPi / 180.0f);
  const float reach = std::max(half.y, half.x / aspect) / tan_half;
  // A box with no extent across the view (a point, a line along z) still gets a camera apart from
  // it, far enough that the two are distinct floats.
  const Vec3 centre = bounds.center();
  const float floor = std::max(1e-4f * std::max({std::abs(centre.x), std::abs(centre.y), std::abs(centre.z)}), 1e-20f);
  const float distance = half.z + 1.08f * std::max(reach, floor);
  c.look_at = centre;
  c.look_from = c.look_at + Vec3(0.0f, 0.0f, distance);
  c.up = Vec3(0.0f, 1.0f, 0.0f);
  return c;
}

}  // namespace gilt::raytrace_core::scene
