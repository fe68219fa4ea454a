#pragma once
// Light carried along a shadow ray through glass, as if the glass did not bend it.
//
// A pane of glass (two parallel interfaces) shifts a ray sideways by a fraction of its thickness
// and sends it on in its own direction, so a straight line through it is the path the light
// takes, weighted by what each interface lets through (1 − F, Fresnel) and by what the glass
// absorbs on the way. The radiosity solver uses this for its direct light from the sky, which is
// not traced as paths: the sky seen through a window lights the room behind it (a room whose
// glazing was opaque to its solver read 0.76 of the path tracer's mean, 0.35 near its windows).
// For curved glass (a bottle, a lens) the straight line keeps the light's total but not its
// caustic. Each call that meets something scans the scene's materials for glass once.

#include "raytrace_core/scene/ray.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core::scene {

class Scene;

/// Fraction of the light from the far end of `ray` (tmax, or infinity) that reaches its origin
/// when every smooth dielectric surface it meets is crossed in a straight line: the product of
/// 1 − F at each crossing (Fresnel at the ray's angle to the surface, the same from either side
/// of a pane) and of Beer–Lambert attenuation inside absorbing glass. Black when the ray meets
/// anything else (frosted glass too, which spreads what it lets through into a lobe), or
/// crosses more than 16 surfaces.
Rgb straight_transmittance(const Scene& scene, Ray ray);

}  // namespace gilt::raytrace_core::scene
