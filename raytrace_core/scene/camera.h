#pragma once
// Pinhole, thin-lens and orthographic cameras.

#include <string>

#include "raytrace_core/util/math.h"
#include "raytrace_core/scene/ray.h"

namespace gilt::raytrace_core::scene {

/// A perspective camera. With aperture_radius = 0 it is a pinhole; otherwise a thin lens focused
/// at focus_distance (0 means at the distance to look_at). An orthographic camera sends parallel
/// rays along the view direction from a film ortho_height high, centred on look_from.
struct Camera {
  Vec3 look_from{0.0f, 0.0f, 1.0f};
  Vec3 look_at{0.0f, 0.0f, 0.0f};
  Vec3 up{0.0f, 1.0f, 0.0f};
  float vfov_degrees = 40.0f;    ///< vertical field of view
  float aperture_radius = 0.0f;  ///< lens radius in scene units
  float focus_distance = 0.0f;   ///< distance of the plane in focus, scene units
  bool orthographic = false;     ///< parallel projection (vfov, aperture and focus unused)
  float ortho_height = 0.0f;     ///< orthographic: the film's height in scene units

  /// Primary ray through film position `film` ∈ [0,1]² (x right, y down) for an image of the
  /// given aspect ratio (width / height); `lens` ∈ [0,1)² picks the point on the lens.
  Ray generate_ray(Vec2 film, Vec2 lens, float aspect) const;
  /// Whether generate_ray reads `lens` (a thin lens; pinholes and orthographic cameras do not).
  bool has_lens() const { return !orthographic && aperture_radius > 0.0f; }
  /// Angle one pixel of an image `height` pixels high subtends at the image centre (Ray::spread);
  /// 0 for an orthographic camera, whose rays do not widen.
  float pixel_spread(int height) const;

  /// Throws InputError when the camera cannot form an image (coincident points, up parallel to
  /// the view direction, field of view outside (0, 180), negative aperture, an orthographic
  /// height that is not positive).
  void validate() const;
};

/// One of the cameras a scene file defines, as `--camera N|NAME` chooses it.
struct NamedCamera {
  std::string name;    ///< the file's name for it (a glTF camera's, else its node's), or "camera N"
  Camera camera;
  float aspect = 0.0f;  ///< width / height the file asks for; 0: none
};

/// A camera that frames the bounding box for an image of the given aspect ratio (width /
/// height), looking down −z from in front of it: the box's front face fills the view's height or
/// width, whichever binds, with an 8 % margin.
Camera default_camera(const Bounds3& bounds, float aspect);

}  // namespace gilt::raytrace_core::scene
