// `gilt render SCENE -o OUT`: options → RenderSettings, then the library does the work.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "photonmap/photon_mapper.h"
#include "photonmap/sppm.h"
#include "radiosity/solver.h"
#include "radiosity/view.h"
#include "raytrace_core/error.h"
#include "raytrace_core/image_io.h"
#include "raytrace_core/parallel.h"
#include "raytrace_core/path_tracer.h"
#include "raytrace_core/render.h"
#include "raytrace_core/scene_io.h"
#include "raytrace_core/whitted.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
namespace {

struct RenderOptions {
  std::string scene;
  std::string output;
  std::string method = "path";
  std::optional<int> spp, width, height;
  double time_limit = 0.0;
  int threads = 0;
  uint64_t seed = 0;
  std::string look_from, look_at, up;
  std::optional<float> fov, aperture, focus_distance;
  std::string filter = "gaussian";
  float filter_radius = 1.5f;
  float exposure = 0.0f;
  int max_depth = 0;
  bool json = false;
  bool quiet = false;
  radiosity::SolverSettings solver;
  // Photon mapping (photon, sppm).
  std::optional<uint64_t> photons, caustic_photons;
  int k = 50;
  float radius = 0.0f;
  int gather_rays = 16;
  float alpha = 2.0f / 3.0f;
};

/// Parses "x,y,z" into a vector; `flag` names the option in the error.
rc::Vec3 parse_vec3(const std::string& text, const std::string& flag) {
  rc::Vec3 v;
  std::istringstream in(text);
  char comma1 = 0, comma2 = 0;
  if (!(in >> v.x >> comma1 >> v.y >> comma2 >> v.z) || comma1 != ',' || comma2 != ',' || !(in >> std::ws).eof())
    throw rc::InputError(flag + ": expected three numbers x,y,z, got '" + text + "'");
  if (!rc::is_finite(v)) throw rc::InputError(flag + ": coordinates must be finite, got '" + text + "'");
  return v;
}

/// The camera: the scene's (or a default view), overridden by any camera flag.
rc::Camera make_camera(const rc::Scene& scene, const RenderOptions& o) {
  rc::Camera c = scene.effective_camera();
  if (!o.look_from.empty()) c.look_from = parse_vec3(o.look_from, "--lookfrom");
  if (!o.look_at.empty()) c.look_at = parse_vec3(o.look_at, "--lookat");
  if (!o.up.empty()) c.up = parse_vec3(o.up, "--up");
  if (o.fov) c.vfov_degrees = *o.fov;
  if (o.aperture) c.aperture_radius = *o.aperture;
  if (o.focus_distance) c.focus_distance = *o.focus_distance;
  c.validate();
  return c;
}

/// Checks the output path before any work, so a long render cannot fail at its end.
void check_output(const std::string& path) {
  if (!rc::is_supported_image_path(path))
    throw rc::InputError("-o " + path + ": unsupported image type (use .exr, .hdr or .png)");
  const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw rc::InputError("-o " + path + ": folder " + parent.string() + " does not exist");
  if (std::filesystem::is_directory(path)) throw rc::InputError("-o " + path + ": is a folder");
}

void run_render(const RenderOptions& o) {
  if (o.method != "path" && o.method != "whitted" && o.method != "radiosity" && o.method != "photon" &&
      o.method != "sppm")
    throw rc::InputError("--method " + o.method + ": expected path, whitted, radiosity, photon or sppm");
  check_output(o.output);
  rc::Scene scene = rc::load_scene(o.scene);
  for (const std::string& w : scene.warnings) std::cerr << "gilt: warning: " << w << "\n";
  if (scene.lights().empty()) std::cerr << "gilt: warning: the scene has no lights: the image will be black\n";

  rc::RenderSettings settings;
  settings.width = o.width.value_or(scene.render.width);
  settings.height = o.height.value_or(scene.render.height);
  settings.spp = o.spp.value_or(scene.render.spp);
  settings.time_limit = o.time_limit;
  settings.seed = o.seed;
  settings.threads = o.threads;
  settings.filter.kind = rc::Filter::parse(o.filter);
  settings.filter.radius = o.filter_radius;
  settings.progress = !o.quiet && !o.json;
  const rc::Camera camera = make_camera(scene, o);

  rc::RadianceFunction radiance;
  std::optional<radiosity::Solution> solution;
  std::optional<radiosity::RadiosityView> view;
  std::optional<photonmap::PhotonMapper> mapper;
  std::optional<photonmap::SppmStats> sppm_stats;
  const auto start = std::chrono::steady_clock::now();
  if (o.method == "photon") {
    photonmap::PhotonMapperSettings pm;
    if (o.photons) pm.photons.global_photons = *o.photons;
    if (o.caustic_photons) pm.photons.caustic_photons = *o.caustic_photons;
    pm.photons.seed = o.seed;
    pm.k = o.k;
    pm.max_radius = o.radius;
    pm.gather_rays = o.gather_rays;
    if (o.max_depth > 0) pm.max_depth = pm.photons.max_depth = o.max_depth;
    {
      const rc::ThreadLimit limit(o.threads);
      mapper.emplace(scene, pm);
    }
    for (const std::string& s : mapper->stats().skipped)
      if (!o.json && !o.quiet) std::cerr << "gilt: " << s << "\n";
    radiance = [&mapper](const rc::Ray& ray, rc::SampleContext& ctx) { return mapper->radiance(ray, ctx); };
    // A time budget covers the photon pass too.
    if (settings.time_limit > 0.0)
      settings.time_limit = std::max(1e-3, settings.time_limit - std::chrono::duration<double>(
                                                                     std::chrono::steady_clock::now() - start)
                                                                     .count());
  } else if (o.method == "radiosity") {
    radiosity::SolverSettings solver = o.solver;
    solver.seed = o.seed;
    solver.threads = o.threads;
    solver.progress = settings.progress;
    solution.emplace(radiosity::solve(scene, solver));
    for (const std::string& w : solution->mesh_report.warnings) std::cerr << "gilt: warning: " << w << "\n";
    view.emplace(scene, *solution);
    radiance = [&view](const rc::Ray& ray, rc::SampleContext& ctx) { return view->radiance(ray, ctx); };
  } else if (o.method == "path") {
    rc::PathSettings ps;
    if (o.max_depth > 0) ps.max_depth = o.max_depth;
    radiance = [&scene, ps](const rc::Ray& ray, rc::SampleContext& ctx) { return rc::path_radiance(scene, ray, ctx, ps); };
  } else {
    rc::WhittedSettings ws;
    if (o.max_depth > 0) ws.max_depth = o.max_depth;
    radiance = [&scene, ws](const rc::Ray& ray, rc::SampleContext& ctx) { return rc::whitted_radiance(scene, ray, ctx, ws); };
  }

  rc::RenderStats stats;
  rc::Film film;
  if (o.method == "sppm") {
    photonmap::SppmSettings sp;
    if (o.photons) sp.photons_per_iteration = *o.photons;
    sp.initial_radius = o.radius;
    sp.alpha = o.alpha;
    if (o.max_depth > 0) sp.max_depth = o.max_depth;
    sppm_stats.emplace();
    film = photonmap::render_sppm(scene, camera, settings, sp, &*sppm_stats);
    stats.spp = sppm_stats->iterations;
    stats.samples = uint64_t(sppm_stats->iterations) * settings.width * settings.height;
    stats.rays = sppm_stats->rays;
    stats.seconds = sppm_stats->seconds;
  } else {
    film = rc::render_image(scene, camera, settings, radiance, &stats);
  }
  // The method's preparation (a radiosity solve, photon tracing) counts in the time.
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  rc::write_image(o.output, rc::Image{film.width(), film.height(), film.pixels()}, o.exposure);
  if (stats.non_finite > 0)
    std::cerr << "gilt: warning: " << stats.non_finite << " sample(s) were NaN or infinite and were discarded\n";

  const int threads = o.threads > 0 ? o.threads : rc::hardware_threads();
  const double secs = std::max(stats.seconds, 1e-9);
  if (o.json) {
    nlohmann::json j = {{"command", "render"},
                        {"scene", o.scene},
                        {"method", o.method},
                        {"width", settings.width},
                        {"height", settings.height},
                        {"spp", stats.spp},
                        {"seed", settings.seed},
                        {"threads", threads},
                        {"triangles", scene.triangle_count()},
                        {"spheres", scene.spheres.size()},
                        {"lights", scene.lights().size()},
                        {"rays", stats.rays},
                        {"rays_per_second", double(stats.rays) / secs},
                        {"samples", stats.samples},
                        {"samples_per_second", double(stats.samples) / secs},
                        {"seconds", stats.seconds},
                        {"non_finite_samples", stats.non_finite},
                        {"output", o.output}};
    if (solution) {
      j["radiosity"] = {{"elements", solution->mesh.element_count()}, {"shots", solution->shots},
                        {"residual", solution->residual}, {"seconds", solution->seconds}};
    }
    if (mapper) {
      const photonmap::PhotonMapperStats& ps = mapper->stats();
      j["photon"] = {{"global_photons", ps.global_photons},       {"caustic_photons", ps.caustic_photons},
                     {"paths", ps.paths},                         {"irradiance_points", ps.irradiance_points},
                     {"trace_seconds", ps.trace_seconds},         {"precompute_seconds", ps.precompute_seconds},
                     {"max_radius", ps.max_radius},               {"skipped", ps.skipped}};
    }
    if (sppm_stats) {
      j["sppm"] = {{"iterations", sppm_stats->iterations},
                   {"photons", sppm_stats->photons},
                   {"initial_radius", sppm_stats->initial_radius},
                   {"mean_final_radius", sppm_stats->mean_final_radius}};
    }
    std::cout << j.dump() << std::endl;
  } else {
    std::printf("gilt render: %s, method %s, %dx%d, %d spp, seed %llu, %d thread(s)\n", o.scene.c_str(),
                o.method.c_str(), settings.width, settings.height, stats.spp,
                static_cast<unsigned long long>(settings.seed), threads);
    std::printf("  scene:   %zu triangles, %zu spheres, %zu lights\n", scene.triangle_count(), scene.spheres.size(),
                scene.lights().size());
    std::printf("  rays:    %llu traced, %.2f Mrays/s\n", static_cast<unsigned long long>(stats.rays),
                double(stats.rays) / secs * 1e-6);
    std::printf("  samples: %llu, %.3f Msamples/s\n", static_cast<unsigned long long>(stats.samples),
                double(stats.samples) / secs * 1e-6);
    if (solution)
      std::printf("  solve:   %zu elements, %llu shots, residual %.3g, %.3f s\n", solution->mesh.element_count(),
                  static_cast<unsigned long long>(solution->shots), solution->residual, solution->seconds);
    if (mapper)
      std::printf("  photons: %zu global, %zu caustic stored from %llu paths in %.3f s; %zu irradiance points in %.3f s\n",
                  mapper->stats().global_photons, mapper->stats().caustic_photons,
                  static_cast<unsigned long long>(mapper->stats().paths), mapper->stats().trace_seconds,
                  mapper->stats().irradiance_points, mapper->stats().precompute_seconds);
    if (sppm_stats)
      std::printf("  sppm:    %d iterations, %llu photons, radius %.4g -> %.4g (mean)\n", sppm_stats->iterations,
                  static_cast<unsigned long long>(sppm_stats->photons), sppm_stats->initial_radius,
                  sppm_stats->mean_final_radius);
    std::printf("  time:    %.3f s (all passes)\n", stats.seconds);
    std::printf("  wrote %s\n", o.output.c_str());
  }
}

}  // namespace

std::function<void()> add_render_command(CLI::App& app) {
  auto o = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand("render", "Render an image of a scene file or built-in scene");
  cmd->add_option("scene", o->scene, "Scene file (.obj, .gltf, .glb, .ply, .json) or built-in name "
                                     "(cornell, cornell-caustics, furnace, smallpt)")
      ->required();
  cmd->add_option("-o,--output", o->output, "Output image (.exr, .hdr linear; .png sRGB)")->required();
  cmd->add_option("--method", o->method, "Rendering method: path (reference), whitted, radiosity, photon or sppm")
      ->check(CLI::IsMember({"path", "whitted", "radiosity", "photon", "sppm"}));
  cmd->add_option("--photons", o->photons,
                  "Photon: global photons emitted (default 200000); sppm: photons per iteration (default 100000)")
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 34));
  cmd->add_option("--caustic-photons", o->caustic_photons, "Photon: caustic photons emitted (default 200000; 0 = none)")
      ->check(CLI::Range(uint64_t(0), uint64_t(1) << 34));
  cmd->add_option("--k", o->k, "Photon: photons per density estimate (default 50)")->check(CLI::Range(1, 100000));
  cmd->add_option("--radius", o->radius,
                  "Photon: largest estimate radius; sppm: initial radius (scene units; default 5 % / 1 % of the "
                  "scene's bounding radius)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--gather-rays", o->gather_rays, "Photon: final-gather rays per sample (default 16; 0 = none)")
      ->check(CLI::Range(0, 65536));
  cmd->add_option("--alpha", o->alpha, "Sppm: fraction of new photons kept per iteration (default 2/3)")
      ->check(CLI::Range(1e-3f, 0.999f));
  add_solver_options(*cmd, o->solver);
  auto* spp = cmd->add_option("--spp", o->spp, "Samples per pixel (default: the scene's, 64)")
                  ->check(CLI::PositiveNumber);
  cmd->add_option("--time", o->time_limit, "Render whole passes until this many seconds are spent")
      ->check(CLI::PositiveNumber)
      ->excludes(spp);
  cmd->add_option("--width", o->width, "Image width in pixels")->check(CLI::Range(1, 65536));
  cmd->add_option("--height", o->height, "Image height in pixels")->check(CLI::Range(1, 65536));
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--seed", o->seed, "Random seed; the image is a function of the seed, not of --threads");
  cmd->add_option("--lookfrom", o->look_from, "Camera position x,y,z");
  cmd->add_option("--lookat", o->look_at, "Point the camera looks at x,y,z");
  cmd->add_option("--up", o->up, "Camera up vector x,y,z");
  cmd->add_option("--fov", o->fov, "Vertical field of view in degrees");
  cmd->add_option("--aperture", o->aperture, "Thin-lens aperture radius in scene units (0 = pinhole)");
  cmd->add_option("--focus-distance", o->focus_distance, "Distance to the plane in focus (default: to --lookat)");
  cmd->add_option("--filter", o->filter, "Pixel filter: box, tent or gaussian")
      ->check(CLI::IsMember({"box", "tent", "gaussian"}));
  cmd->add_option("--filter-radius", o->filter_radius, "Pixel filter radius in pixels")->check(CLI::Range(0.5f, 8.0f));
  cmd->add_option("--exposure", o->exposure, "PNG only: scale by 2^exposure before sRGB encoding")
      ->check(CLI::Range(-64.0f, 64.0f));
  cmd->add_option("--max-depth", o->max_depth, "Bounce limit (path: default unlimited with Russian roulette; "
                                               "whitted: 16)")
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_flag("--json", o->json, "Print the statistics as one JSON object");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bar");
  return [o] { run_render(*o); };
}

}  // namespace gilt::cli
