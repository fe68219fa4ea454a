#pragma once
// A radiosity solution seen through a camera: Gouraud-interpolated radiance over each element,
// mirrors and glass ray traced against the solution (the classic two-pass method).

#include "radiosity/solver.h"
#include "raytrace_core/render.h"

namespace gilt::radiosity {

/// Display of a solution; radiance() is a RadianceFunction for raytrace_core::render_image.
class RadiosityView {
 public:
  /// Builds a scene of the solution's elements plus the specular primitives of `scene`. Both
  /// arguments must outlive the view. With `ambient`, a partial solution is shown with each
  /// vertex's reflectance times the solution's ambient term added (display only).
  RadiosityView(const rc::Scene& scene, const Solution& solution, bool ambient = true);

  /// Radiance along a camera ray: the interpolated vertex radiance where it meets an element's
  /// front, through any chain of mirror and glass bounces (at most 64).
  Rgb radiance(const rc::Ray& ray, rc::SampleContext& ctx) const;

 private:
  const rc::Scene& scene_;
  rc::Scene display_;
  std::vector<Rgb> vertex_radiance_;
  std::vector<std::array<uint32_t, 3>> elements_;
  Rgb environment_{0.0f};
};

}  // namespace gilt::radiosity
