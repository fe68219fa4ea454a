#pragma once
// The classic Whitted ray tracer (Whitted 1980): shadow rays to every light, recursive perfect
// reflection and refraction with Fresnel, local Phong-style shading, no indirect diffuse light.
// It is the no-global-illumination baseline.

#include "raytrace_core/render/render.h"

namespace gilt::raytrace_core::render {

/// Whitted parameters.
struct WhittedSettings {
  int max_depth = 16;         ///< recursion limit for mirror and glass
  int area_light_samples = 1; ///< shadow rays per area light per shading point
};

/// Radiance along `ray` by Whitted's method (area lights sampled with `area_light_samples` points).
Rgb whitted_radiance(const scene::Scene& scene, const scene::Ray& ray, SampleContext& ctx,
                     const WhittedSettings& settings);

}  // namespace gilt::raytrace_core::render
