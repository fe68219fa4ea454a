#pragma once
// One image by any of gilt's methods, under a sample count or a time budget that covers the
// method's preparation (radiosity solve, photon tracing) as well as the image. Shared by
// `gilt render`, `gilt compare` and the Python module.

#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "photonmap/photon_mapper.h"
#include "photonmap/sppm.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/scene/camera.h"
#include "raytrace_core/render/film.h"
#include "raytrace_core/render/render.h"

namespace gilt::api {

/// The methods, in the order reports list them.
inline const std::vector<std::string> kMethods = {"path", "photon", "sppm", "radiosity", "whitted"};

/// Every method's own settings; `max_depth` 0 keeps each method's default.
struct MethodOptions {
  radiosity::solver::SolverSettings solver;
  radiosity::bake::ViewMode radiosity_view = radiosity::bake::ViewMode::two_pass;
  photonmap::PhotonMapperSettings photon;
  photonmap::SppmSettings sppm;
  int max_depth = 0;
};

/// The photon methods' options as `gilt render` and gilt.render() take them: --photons (the
/// photon method's global photons, SPPM's per iteration), --caustic-photons, --k, --radius (the
/// photon method's largest radius, SPPM's first), --gather-rays and --alpha. 0 or empty: the
/// default.
struct PhotonOptions {
  std::optional<uint64_t> photons, caustic_photons;
  int k = 50;
  float radius = 0.0f;
  int gather_rays = 1;
  float alpha = 2.0f / 3.0f;

  /// Sets them in the methods' own settings.
  void apply(MethodOptions& options) const;
};

/// What one run produced.
struct MethodResult {
  raytrace_core::render::Film film;
  raytrace_core::render::RenderStats stats;  ///< seconds: the whole run, preparation included
  std::optional<radiosity::solver::Solution> solution;
  std::optional<photonmap::PhotonMapperStats> photon;
  std::optional<photonmap::SppmStats> sppm;
  std::vector<std::string> notes;  ///< warnings and skipped passes
};

/// The image size for a requested width and height: both given, as given; one, the other from the
/// aspect ratio of the scene's render size (its camera's, if it has one); neither, the scene's.
/// Throws InputError for a size outside 1–65,536.
std::pair<int, int> image_size(const raytrace_core::scene::Scene& scene, std::optional<int> width, std::optional<int> height);

/// Renders with `method` ("path", "whitted", "radiosity", "photon" or "sppm"). With a time
/// limit, a radiosity solve may use 70 % of it (a partial solution is shown with its ambient
/// term) and photon tracing runs first; the image takes what is left, at least one pass. A scene
/// without lights gives its black image at once, with a note. Throws InputError for an unknown
/// method, Interrupted when raytrace_core::util::request_stop() stops it.
MethodResult run_method(const raytrace_core::scene::Scene& scene, const raytrace_core::scene::Camera& camera, const std::string& method,
                        const raytrace_core::render::RenderSettings& settings, const MethodOptions& options);

}  // namespace gilt::api
