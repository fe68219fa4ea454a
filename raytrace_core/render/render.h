#pragma once
// The image loop shared by every method: tiles in parallel, per-sample random streams, a sample
// or time budget, and progress. A method supplies only the radiance along one camera ray.

#include <cstdint>
#include <functional>

#include "raytrace_core/scene/camera.h"
#include "raytrace_core/render/film.h"
#include "raytrace_core/render/sampler.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::render {

/// How to render an image.
struct RenderSettings {
  int width = 512;
  int height = 512;
  int spp = 64;               ///< samples per pixel (the budget unless time_limit > 0)
  double time_limit = 0.0;    ///< seconds; > 0 renders whole passes until the time is spent
  uint64_t seed = 0;          ///< global seed; the image is a function of (scene, settings, seed)
  int threads = 0;            ///< 0 = all hardware threads
  Filter filter;              ///< pixel filter
  bool progress = true;       ///< progress bar on stderr (only drawn on a terminal)
  int tile_size = 16;         ///< tile edge in pixels
  SamplerKind sampler = SamplerKind::sobol;  ///< how each camera sample draws its numbers
};

/// What a render did.
struct RenderStats {
  int spp = 0;              ///< samples per pixel completed
  uint64_t samples = 0;     ///< camera samples taken
  uint64_t rays = 0;        ///< rays traced, primary and shadow rays included
  double seconds = 0.0;     ///< wall time
  uint64_t non_finite = 0;  ///< samples discarded because the method returned NaN or infinity
};

/// State of one camera sample: its sampler and a ray counter.
struct SampleContext {
  Sampler sampler;
  uint64_t rays = 0;
};

/// Radiance arriving at the camera along a primary ray (W·sr⁻¹·m⁻²).
using RadianceFunction = std::function<Rgb(const scene::Ray& ray, SampleContext& ctx)>;

/// The camera ray of a sample of pixel (x, y): its position in the pixel drawn by the settings'
/// filter, then a point on the lens when the camera has one, both from `sampler`'s camera
/// dimensions; its spread set for texture filtering. render_image and SPPM's camera pass use it.
scene::Ray camera_ray(const scene::Camera& camera, const RenderSettings& settings, int x, int y,
                      Sampler& sampler);

/// Renders with the given radiance function. Sample s of pixel (x, y) draws from
/// Sampler::for_pixel_sample(sampler, seed, y·width + x, s) only, so the result is independent of threads and tiles.
Film render_image(const scene::Scene& scene, const scene::Camera& camera, const RenderSettings& settings,
                  const RadianceFunction& radiance, RenderStats* stats = nullptr);

}  // namespace gilt::raytrace_core::render
