#pragma once
// The unbiased reference: unidirectional path tracing with next-event estimation, multiple
// importance sampling (power heuristic) and Russian roulette (Veach 1997; Pharr et al., PBRT).

#include "raytrace_core/render.h"

namespace gilt::raytrace_core {

/// Path tracer parameters.
struct PathSettings {
  int max_depth = 1 << 20;  ///< hang guard only: Russian roulette ends paths long before (ρ^(2^20) ≈ 0)
  int rr_depth = 3;      ///< bounces before Russian roulette starts
};

/// Radiance along `ray` estimated by one path.
Rgb path_radiance(const Scene& scene, const Ray& ray, SampleContext& ctx, const PathSettings& settings);

}  // namespace gilt::raytrace_core
