#pragma once
// Stochastic progressive photon mapping (Hachisuka & Jensen 2009, "Stochastic Progressive Photon
// Mapping"). Each iteration traces one camera path per pixel through mirrors and glass to a
// visible point (direct light there by light sampling), then a batch of photons; the photons
// within a pixel's radius add to its flux, and the radius shrinks so that the estimate converges
// to the path-traced answer: N ← N + αM, R ← R √(N_new / (N + M)).

#include <cstdint>

#include "photonmap/photon_index.h"
#include "raytrace_core/scene/camera.h"
#include "raytrace_core/render/film.h"
#include "raytrace_core/render/render.h"

namespace gilt::photonmap {

namespace rc = gilt::raytrace_core;

/// SPPM parameters beyond the image's (which come from rc::render::RenderSettings: size, spp = the
/// iteration count, time limit, seed, threads, filter). Defaults are the documented ones.
struct SppmSettings {
  uint64_t photons_per_iteration = 100'000;
  float initial_radius = 0.0f;  ///< scene units; 0: 1 % of the scene's bounding radius
  float alpha = 2.0f / 3.0f;    ///< fraction of new photons kept per iteration, in (0, 1)
  int max_depth = 1 << 16;      ///< bounces per camera or photon path at most; Russian roulette ends
                                ///< photon paths; camera paths follow at most 64 mirror/glass bounces
  IndexKind index = IndexKind::hash_grid;  ///< over each iteration's photons (bench_photon --index)
};

/// What an SPPM render did.
struct SppmStats {
  int iterations = 0;
  uint64_t photons = 0;       ///< photon paths emitted in all
  uint64_t rays = 0;
  double seconds = 0.0;
  float initial_radius = 0.0f;
  float mean_final_radius = 0.0f;  ///< over pixels with a visible point
};

/// Renders the scene by SPPM: settings.spp iterations, or whole iterations until
/// settings.time_limit when it is positive. Iteration i draws pixel samples from
/// Sampler::for_pixel_sample(settings.sampler, seed, pixel, i) and photon j from Rng::for_item(seed, j, i + stream), so the
/// image does not depend on the thread count.
rc::render::Film render_sppm(const rc::scene::Scene& scene, const rc::scene::Camera& camera,
                             const rc::render::RenderSettings& settings, const SppmSettings& sppm,
                             SppmStats* stats = nullptr);

}  // namespace gilt::photonmap
