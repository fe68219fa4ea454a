#include "api/methods.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "radiosity/solver/budget.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/whitted.h"

namespace gilt::api {
namespace rc = gilt::raytrace_core;

void PhotonOptions::apply(MethodOptions& mo) const {
  if (photons) mo.photon.photons.global_photons = mo.sppm.photons_per_iteration = *photons;
  if (caustic_photons) mo.photon.photons.caustic_photons = *caustic_photons;
  mo.photon.k = k;
  mo.photon.max_radius = mo.sppm.initial_radius = radius;
  mo.photon.gather_rays = gather_rays;
  mo.sppm.alpha = alpha;
}

std::pair<int, int> image_size(const rc::scene::Scene& scene, std::optional<int> width,
                               std::optional<int> height) {
  for (const std::optional<int>& v : {width, height})
    if (v && (*v < 1 || *v > 65536)) throw rc::InputError("image width and height: from 1 to 65536 pixels");
  const double aspect = double(scene.render.width) / double(std::max(scene.render.height, 1));
  const int w = width.value_or(height ? std::max(1, int(std::lround(*height * aspect))) : scene.render.width);
  const int h = height.value_or(width ? std::max(1, int(std::lround(*width / aspect))) : scene.render.height);
  return {std::clamp(w, 1, 65536), std::clamp(h, 1, 65536)};
}

MethodResult run_method(const rc::scene::Scene& scene, const rc::scene::Camera& camera,
                        const std::string& method, const rc::render::RenderSettings& base,
                        const MethodOptions& options) {
  if (std::find(kMethods.begin(), kMethods.end(), method) == kMethods.end())
    throw rc::InputError("--method " + method + ": expected path, whitted, radiosity, photon or sppm");
  if (base.width <= 0 || base.height <= 0) throw rc::InputError("image size must be positive");
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  rc::render::RenderSettings settings = base;
  MethodResult result;
  rc::render::RadianceFunction radiance;
  std::optional<radiosity::bake::RadiosityView> view;
  std::optional<photonmap::PhotonMapper> mapper;
  // What is left of a time budget after the preparation: at least one pass gets rendered.
  auto remaining = [&] { return std::max(1e-3, base.time_limit - elapsed()); };

  // A scene that emits nothing is black whatever the method: the image is made at once rather
  // than after the samples or the time budget have been spent tracing it.
  if (scene.lights().empty()) {
    result.film = rc::render::Film(base.width, base.height);
    result.notes.push_back("nothing traced: without lights the image is black in every method");
    return result;
  }

  if (method == "sppm") {
    photonmap::SppmSettings sp = options.sppm;
    if (options.max_depth > 0) sp.max_depth = options.max_depth;
    result.sppm.emplace();
    result.film = photonmap::render_sppm(scene, camera, settings, sp, &*result.sppm);
    result.stats.spp = result.sppm->iterations;
    result.stats.samples = uint64_t(result.sppm->iterations) * settings.width * settings.height;
    result.stats.rays = result.sppm->rays;
    result.stats.seconds = elapsed();
    return result;
  }
  if (method == "photon") {
    photonmap::PhotonMapperSettings pm = options.photon;
    pm.photons.seed = settings.seed;
    // Under a budget a tenth of it may go to a denser global map of an open scene (on Šibenik
    // at 30 s: about 5 M paths instead of 1 M, relMSE 0.0091 against 0.0126; bench/README.md).
    if (base.time_limit > 0.0) pm.photons.global_seconds = 0.1 * base.time_limit;
    if (options.max_depth > 0) pm.max_depth = pm.photons.max_depth = options.max_depth;
    {
      const rc::util::ThreadLimit limit(settings.threads);
      mapper.emplace(scene, pm);
    }
    result.photon = mapper->stats();
    result.notes = mapper->stats().skipped;
    radiance = [&mapper](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
      return mapper->radiance(ray, ctx);
    };
    if (base.time_limit > 0.0) settings.time_limit = remaining();
  } else if (method == "radiosity") {
    radiosity::solver::SolverSettings solver = radiosity::bake::solver_settings_for(options.radiosity_view, options.solver);
    solver.seed = settings.seed;
    solver.threads = settings.threads;
    solver.progress = settings.progress;
    // Under a budget the solve has 70 % of it, and a mesh left to gilt is sized to fit it.
    radiosity::solver::BudgetFit fit;
    result.solution.emplace(base.time_limit > 0.0 ? radiosity::solver::solve_within(scene, solver, 0.7 * base.time_limit, &fit)
                                                  : radiosity::solver::solve(scene, solver));
    result.notes = result.solution->mesh_report.warnings;
    if (!fit.note.empty()) result.notes.push_back(fit.note);
    view.emplace(scene, *result.solution, options.radiosity_view);
    radiance = [&view](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
      return view->radiance(ray, ctx);
    };
    if (base.time_limit > 0.0) settings.time_limit = remaining();
  } else if (method == "path") {
    rc::render::PathSettings ps;
    if (options.max_depth > 0) ps.max_depth = options.max_depth;
    radiance = [&scene, ps](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, ps); };
  } else {
    rc::render::WhittedSettings ws;
    if (options.max_depth > 0) ws.max_depth = options.max_depth;
    radiance = [&scene, ws](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::whitted_radiance(scene, ray, ctx, ws); };
  }
  result.film = rc::render::render_image(scene, camera, settings, radiance, &result.stats);
  result.stats.seconds = elapsed();
  return result;
}

}  // namespace gilt::api
