#pragma once
// Next-event estimation: light arriving at a surface point straight from one light, chosen by
// power, through one shadow ray. One routine for every method; each caller applies its own
// multiple-importance weight (Veach 1997), as Tungsten's TraceBase::estimateDirect is shared by
// its path and photon tracers.

#include <cstdint>

#include "raytrace_core/rng.h"
#include "raytrace_core/scene.h"

namespace gilt::raytrace_core {

/// One next-event estimate.
struct DirectSample {
  /// f · Li · |cos θi| / (light pdf · selection probability), in W·sr⁻¹·m⁻² towards wo, not yet
  /// weighted by MIS; black when nothing arrives, the light is behind the lit side, or the shadow
  /// ray is blocked.
  Rgb value{0.0f};
  float pdf = 0.0f;    ///< solid-angle density of wi, the light's selection probability included
  Vec3 wi{0.0f};       ///< direction towards the light, in the shading frame (cos θi = wi.z)
  bool delta = false;  ///< point, spot or directional light: BSDF sampling cannot reach it
};

/// Samples the scene's lights once from `si` (material m, shading frame `frame`, outgoing
/// direction wo in that frame, wo_above: wo lies on the ng side). Draws one uniform for the light
/// and two for the point on it, nothing when the scene has no lights; adds the shadow ray to `rays`.
/// Only reflection is estimated: a light on the other side of the geometric surface adds nothing.
DirectSample sample_direct(const Scene& scene, const SurfaceInteraction& si, const Material& m, const Frame& frame,
                           const Vec3& wo, bool wo_above, Rng& rng, uint64_t& rays);

}  // namespace gilt::raytrace_core
