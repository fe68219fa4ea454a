// `gilt render SCENE -o OUT`: options → RenderSettings, then the library does the work.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <tuple>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
#include "api/methods.h"
#include "api/statistics.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/render/whitted.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
using api::MethodOptions;
using api::MethodResult;
namespace {

struct RenderOptions {
  std::string scene;
  rc::io::ExtraLighting lighting;
  std::string output;
  std::string method = "path";
  std::optional<int> spp, width, height;
  double time_limit = 0.0;
  int threads = 0;
  uint64_t seed = 0;
  std::string camera;  ///< --camera N|NAME; empty: the scene's own
  std::string look_from, look_at, up;
  std::optional<float> fov, aperture, focus_distance;
  std::string filter = "gaussian";
  std::string sampler = "sobol";
  std::string light_sampler = "bvh";
  float filter_radius = 1.5f;
  float exposure = 0.0f;
  int max_depth = 0;
  bool json = false;
  bool quiet = false;
  radiosity::solver::SolverSettings solver;
  radiosity::bake::ViewMode radiosity_view = radiosity::bake::ViewMode::two_pass;
  api::PhotonOptions photon;  ///< photon mapping (photon, sppm)
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

/// The camera: the scene's (or a default view framed for an image of `aspect`), overridden by any
/// camera flag.
rc::scene::Camera make_camera(const rc::scene::Scene& scene, const RenderOptions& o, float aspect) {
  rc::scene::Camera c = scene.effective_camera(aspect);
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
  if (!rc::util::is_supported_image_path(path))
    throw rc::InputError("-o " + path + ": unsupported image type (use .exr, .hdr or .png)");
  const std::filesystem::path parent = std::filesystem::absolute(path).parent_path();
  if (!std::filesystem::is_directory(parent))
    throw rc::InputError("-o " + path + ": folder " + parent.string() + " does not exist");
  if (std::filesystem::is_directory(path)) throw rc::InputError("-o " + path + ": is a folder");
}

void run_render(const RenderOptions& o) {
  check_output(o.output);
  rc::scene::Scene scene = rc::io::load_scene(o.scene, o.lighting);
  if (!o.camera.empty()) rc::io::select_camera(scene, o.camera);
  scene.set_light_sampling(rc::scene::parse_light_sampling(o.light_sampler));
  for (const std::string& w : scene.warnings) std::cerr << "gilt: warning: " << w << "\n";
  if (scene.lights().empty()) std::cerr << "gilt: warning: the scene has no lights: the image will be black\n";

  rc::render::RenderSettings settings;
  // One of --width and --height alone keeps the scene's aspect ratio (its camera's, if it has one).
  std::tie(settings.width, settings.height) = api::image_size(scene, o.width, o.height);
  settings.spp = o.spp.value_or(scene.render.spp);
  settings.time_limit = o.time_limit;
  settings.seed = o.seed;
  settings.threads = o.threads;
  settings.filter.kind = rc::render::Filter::parse(o.filter);
  settings.filter.radius = o.filter_radius;
  settings.sampler = rc::render::parse_sampler(o.sampler);
  settings.progress = !o.quiet && !o.json;
  const rc::scene::Camera camera = make_camera(scene, o, float(settings.width) / float(settings.height));

  MethodOptions mo;
  mo.solver = o.solver;
  mo.radiosity_view = o.radiosity_view;
  o.photon.apply(mo);
  mo.max_depth = o.max_depth;
  const MethodResult result = api::run_method(scene, camera, o.method, settings, mo);
  const rc::render::Film& film = result.film;
  const rc::render::RenderStats& stats = result.stats;
  const std::optional<radiosity::solver::Solution>& solution = result.solution;
  const std::optional<photonmap::PhotonMapperStats>& photon = result.photon;
  const std::optional<photonmap::SppmStats>& sppm_stats = result.sppm;
  for (const std::string& n : result.notes)
    if (!o.json) std::cerr << "gilt: " << n << "\n";
  if (rc::util::processes().rank() == 0)  // under mpirun, rank 0 alone writes
    rc::util::write_image(o.output, rc::util::Image{film.width(), film.height(), film.pixels()}, o.exposure);
  if (stats.non_finite > 0)
    std::cerr << "gilt: warning: " << stats.non_finite << " sample(s) were NaN or infinite and were discarded\n";

  const int threads = o.threads > 0 ? o.threads : rc::util::hardware_threads();
  const double secs = std::max(stats.seconds, 1e-9);
  if (o.json) {
    nlohmann::json j = api::run_statistics(scene, o.method, settings, result);
    j["command"] = "render", j["scene"] = o.scene, j["output"] = o.output;
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
    if (solution) {
      std::printf("  solve:   %zu elements, %llu shots, residual %.3g, %.3f s\n", solution->mesh.element_count(),
                  static_cast<unsigned long long>(solution->shots), solution->residual, solution->seconds);
      if (!solution->vertex_ambient.empty())
        std::printf(
            "  ambient: the unshot light gathered where it lands (%.0f %% of its rays left the scene)\n",
            100.0 * solution->ambient_escaped);
    }
    if (photon)
      std::printf("  photons: %zu global, %zu caustic stored from %llu paths in %.3f s; %zu irradiance points in %.3f s\n",
                  photon->global_photons, photon->caustic_photons, static_cast<unsigned long long>(photon->paths),
                  photon->trace_seconds, photon->irradiance_points, photon->precompute_seconds);
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
  cmd->add_option("--photons", o->photon.photons,
                  "Photon: global photons emitted (default 200000); sppm: photons per iteration (default 100000)")
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 34));
  cmd->add_option("--caustic-photons", o->photon.caustic_photons, "Photon: caustic photons emitted (default 200000; 0 = none)")
      ->check(CLI::Range(uint64_t(0), uint64_t(1) << 34));
  cmd->add_option("--k", o->photon.k, "Photon: photons per density estimate (default 50)")->check(CLI::Range(1, 100000));
  cmd->add_option("--radius", o->photon.radius,
                  "Photon: largest estimate radius; sppm: initial radius (scene units; default 5 % / 1 % of the "
                  "scene's bounding radius)")
      ->check(CLI::PositiveNumber)
      ->check(finite_number());
  cmd->add_option("--gather-rays", o->photon.gather_rays, "Photon: final-gather rays per sample (default 1; 0 = none)")
      ->check(CLI::Range(0, 65536));
  cmd->add_option("--alpha", o->photon.alpha, "Sppm: fraction of new photons kept per iteration (default 2/3)")
      ->check(CLI::Range(1e-3f, 0.999f))
      ->check(finite_number());
  add_solver_options(*cmd, o->solver);
  add_lighting_options(*cmd, o->lighting);
  add_camera_option(*cmd, o->camera);
  cmd->add_option_function<std::string>(
         "--radiosity-view",
         [o](const std::string& name) {
           o->radiosity_view = name == "mesh" ? radiosity::bake::ViewMode::mesh : radiosity::bake::ViewMode::two_pass;
         },
         "Radiosity: two-pass (the input's surfaces, direct light per pixel, reflected light from the solution; "
         "default) or mesh (the elements' radiance, as exported)")
      ->check(CLI::IsMember({"two-pass", "mesh"}));
  auto* spp = cmd->add_option("--spp", o->spp, "Samples per pixel (default: the scene's, 64)")
                  ->check(CLI::PositiveNumber);
  cmd->add_option("--time", o->time_limit, "Render whole passes until this many seconds are spent")
      ->check(CLI::PositiveNumber)
      ->check(finite_number())
      ->excludes(spp);
  cmd->add_option("--width", o->width, "Image width in pixels (given alone, the height keeps the camera's aspect ratio)")->check(CLI::Range(1, 65536));
  cmd->add_option("--height", o->height, "Image height in pixels (given alone, the width keeps the camera's aspect ratio)")->check(CLI::Range(1, 65536));
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--seed", o->seed, "Random seed; the image is a function of the seed, not of --threads")
      ->check(unsigned_integer());
  cmd->add_option("--lookfrom", o->look_from, "Camera position x,y,z");
  cmd->add_option("--lookat", o->look_at, "Point the camera looks at x,y,z");
  cmd->add_option("--up", o->up, "Camera up vector x,y,z");
  cmd->add_option("--fov", o->fov, "Vertical field of view in degrees")->check(finite_number());
  cmd->add_option("--aperture", o->aperture, "Thin-lens aperture radius in scene units (0 = pinhole)")
      ->check(finite_number());
  cmd->add_option("--focus-distance", o->focus_distance, "Distance to the plane in focus (default: to --lookat)")
      ->check(finite_number());
  cmd->add_option("--sampler", o->sampler,
                  "Camera-sample numbers: sobol (Owen-scrambled Sobol, the default) or independent")
      ->check(CLI::IsMember({"independent", "sobol"}));
  cmd->add_option("--light-sampler", o->light_sampler,
                  "Next-event estimation's choice of light: bvh (by power, distance and orientation, the "
                  "default) or power (by power alone)")
      ->check(CLI::IsMember({"bvh", "power"}));
  cmd->add_option("--filter", o->filter, "Pixel filter: box, tent or gaussian")
      ->check(CLI::IsMember({"box", "tent", "gaussian"}));
  cmd->add_option("--filter-radius", o->filter_radius, "Pixel filter radius in pixels")
      ->check(CLI::Range(0.5f, 8.0f))
      ->check(finite_number());
  cmd->add_option("--exposure", o->exposure, "PNG only: scale by 2^exposure before sRGB encoding")
      ->check(CLI::Range(-64.0f, 64.0f))
      ->check(finite_number());
  cmd->add_option("--max-depth", o->max_depth, "Bounce limit (path: default unlimited with Russian roulette; "
                                               "whitted: 16)")
      ->check(CLI::Range(1, 1 << 20));
  cmd->add_flag("--json", o->json, "Print the statistics as one JSON object");
  cmd->add_flag("-q,--quiet", o->quiet, "No progress bar");
  return [o] { run_render(*o); };
}

}  // namespace gilt::cli
