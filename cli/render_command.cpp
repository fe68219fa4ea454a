// `gilt render SCENE -o OUT`: options → RenderSettings, then the library does the work.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli/commands.h"
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
  if (o.method != "path" && o.method != "whitted" && o.method != "radiosity")
    throw rc::InputError("--method " + o.method + ": expected path, whitted or radiosity");
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
  if (o.method == "radiosity") {
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
  const rc::Film film = rc::render_image(scene, camera, settings, radiance, &stats);
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
    std::printf("  time:    %.3f s%s\n", stats.seconds, solution ? " (render, after the solve)" : "");
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
  cmd->add_option("--method", o->method, "Rendering method: path (reference), whitted or radiosity")
      ->check(CLI::IsMember({"path", "whitted", "radiosity"}));
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
