#pragma once
// The ambient term of a partial progressive solution, gathered where the unshot light lands.
//
// Progressive refinement stopped early leaves light unshot. Cohen, Chen, Wallace & Greenberg
// (1988) display it as one ambient radiosity for the whole scene, the area-weighted mean unshot
// radiosity over 1 − ρ̄: exact on average in a closed room, but in an open one it carries light
// that would leave the scene, and it carries it everywhere. Šibenik under its sun at `--time 20`
// kept most of its unshot light on the sunlit outside walls (lit on both sides, so given twins);
// spread over the nave it read 6.6 % bright, and 0.996 of the path tracer without it. Here each
// shooting patch instead gathers the unshot radiosity it sees, with cosine-weighted rays into the
// element scene: light that escapes, or lands outside, does not reach a patch that cannot see it.
// The later bounces of what lands are the same geometric series as Cohen's, over the reflectance
// of what is hit: 1 / (1 − ρ̄ (1 − ē)), ē the share of gather rays that met nothing. In a closed
// room ē = 0 and the area-weighted mean of the gathered term equals Cohen's (reciprocity).

#include <cstdint>
#include <span>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/scene/scene.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::radiosity::solver {

/// Gather rays per shooting patch, and the fewest a gather under a time limit may take.
inline constexpr int kAmbientRaysPerPatch = 64;
inline constexpr int kAmbientLeastRays = 8;

/// The gathered ambient irradiance and what it took.
struct AmbientGather {
  std::vector<rc::Rgb>
      element_ambient;  ///< W·m⁻² per element: its patch's gathered irradiance times the series
  std::vector<rc::Rgb> vertex_ambient;  ///< W·m⁻² per vertex: the area-weighted mean of its elements'
  rc::Rgb series{1.0f};                 ///< 1 / (1 − ρ̄ (1 − ē)), per channel
  double escaped = 0.0;                 ///< area-weighted share of gather rays that met no surface
  uint64_t rays = 0;
};

/// Gathers `unshot` (radiosity per element, W·m⁻²) at each patch: patch q holds elements
/// patch_elements[patch_offsets[q] .. patch_offsets[q + 1]). Rays are traced against `geometry`
/// (element_scene of `mesh`); an element is seen from its front, or a two-sided surface's from
/// the element facing the ray there; mirrors and glass are opaque, as in the solver. `albedo` is
/// per element; `rays_per_patch` rays leave each patch. Every process computes the whole (the rays are seeded
/// by patch, so all agree).
AmbientGather gather_ambient(const rc::scene::Scene& geometry, const mesh::RadiosityMesh& mesh,
                             std::span<const uint32_t> patch_offsets,
                             std::span<const uint32_t> patch_elements, std::span<const rc::Rgb> unshot,
                             std::span<const rc::Rgb> albedo, int rays_per_patch, uint64_t seed);

}  // namespace gilt::radiosity::solver
