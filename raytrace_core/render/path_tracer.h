#pragma once
// The unbiased reference: unidirectional path tracing with next-event estimation, multiple
// importance sampling (power heuristic) and Russian roulette (Veach 1997; Pharr et al., PBRT).

#include "raytrace_core/render/render.h"

namespace gilt::raytrace_core::render {

/// Path tracer parameters.
struct PathSettings {
  int max_depth = 1 << 20;  ///< hang guard only: Russian roulette ends paths long before (ρ^(2^20) ≈ 0)
  int rr_depth = 3;      ///< bounces before Russian roulette starts
  /// When set, stands in for the material of the first surface hit, emission included: with a
  /// white, unlit Lambertian stand-in the estimate is E/π, E the irradiance there, whatever the
  /// surface really is (the radiosity checks). The rest of the path sees the real materials.
  const scene::Material* first_surface = nullptr;
};

/// Radiance along `ray` estimated by one path.
Rgb path_radiance(const scene::Scene& scene, const scene::Ray& ray, SampleContext& ctx,
                  const PathSettings& settings);

}  // namespace gilt::raytrace_core::render
