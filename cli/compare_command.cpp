// `gilt compare SCENE -o REPORT_DIR`: options for api::compare_methods (api/compare.h), which
// renders every method at every time budget on one camera and writes the report; this prints
// the table as it goes.

#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "api/compare.h"
#include "cli/commands.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::cli {
namespace rc = gilt::raytrace_core;
namespace fs = std::filesystem;
namespace {

struct CompareOptions {
  std::string scene, output;
  rc::io::ExtraLighting lighting;
  std::string methods = "path,photon,sppm,radiosity,whitted";
  std::string budgets = "1,2,4,8,16";
  std::string reference;
  std::string reference_method = "auto";  ///< path, sppm, or auto (sppm where caustics are)
  std::string camera;  ///< --camera N|NAME; empty: the scene's own
  double reference_time = 60.0;
  int width = 256, height = 256;
  uint64_t seed = 0;
  std::string sampler = "sobol";  ///< the methods' samplers; the reference always uses Sobol
  std::string light_sampler = "bvh";  ///< the methods' choice of light; the reference always uses the BVH
  int threads = 0;
  float exposure = 0.0f;
  bool quiet = false;
};

void run_compare(const CompareOptions& o) {
  api::CompareSettings s;
  s.methods = api::split_list(o.methods);
  s.budgets = api::parse_budgets(o.budgets);
  s.reference_file = o.reference, s.reference_method = o.reference_method, s.reference_time = o.reference_time;
  s.width = o.width, s.height = o.height, s.seed = o.seed, s.threads = o.threads, s.exposure = o.exposure;
  s.sampler = o.sampler, s.light_sampler = o.light_sampler;
  s.progress = !o.quiet;
  s.output = o.output;
  s.scene_name = o.scene;
  api::check_settings(s);  // before the scene is loaded

  rc::scene::Scene scene = rc::io::load_scene(o.scene, o.lighting);
  if (!o.camera.empty()) rc::io::select_camera(scene, o.camera);
  for (const std::string& w : scene.warnings) std::cerr << "gilt: warning: " << w << "\n";
  if (scene.lights().empty()) std::cerr << "gilt: warning: the scene has no lights: every image will be black\n";
  if (!o.quiet) std::printf("  method     budget s  actual s  relMSE      mean rel. error  mean / reference\n");
  api::compare_methods(scene, s, [&](const api::ReportEntry& e) {
    if (!o.quiet)
      std::printf("  %-9s  %8g  %8.2f  %-10.4g  %6.2f %%         %.4f\n", e.method.c_str(), e.budget, e.seconds,
                  e.relmse, 100 * e.mre, e.mean_ratio);
    std::fflush(stdout);
  });
  if (!o.quiet) std::printf("  report: %s\n", (fs::path(o.output) / "index.html").string().c_str());
}

}  // namespace

std::function<void()> add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareOptions>();
  CLI::App* cmd = app.add_subcommand("compare", "Render every method at every time budget and report error against time");
  cmd->add_option("scene", o->scene, "Scene file or built-in name")->required();
  add_lighting_options(*cmd, o->lighting);
  add_camera_option(*cmd, o->camera);
  cmd->add_option("-o,--output", o->output, "Report folder (index.html, metrics.json, metrics.csv, images/)")->required();
  cmd->add_option("--methods", o->methods, "Comma-separated methods (default path,photon,sppm,radiosity,whitted)");
  cmd->add_option("--budgets", o->budgets, "Comma-separated time budgets in seconds (default 1,2,4,8,16)");
  auto* ref = cmd->add_option("--reference", o->reference, "Reference image (.exr) instead of a path-traced one");
  cmd->add_option("--reference-time", o->reference_time,
                  "Seconds for the path-traced reference (default 60; cached by scene content and camera)")
      ->check(finite_number())
      ->check(CLI::Range(0.1, 1e6))
      ->excludes(ref);
  cmd->add_option("--reference-method", o->reference_method,
                  "How the reference is rendered: path, sppm, or auto (default: sppm when the scene has caustics)")
      ->check(CLI::IsMember({"auto", "path", "sppm"}))
      ->excludes(ref);
  cmd->add_option("--width", o->width, "Image width (default 256)")->check(CLI::Range(1, 16384));
  cmd->add_option("--height", o->height, "Image height (default 256)")->check(CLI::Range(1, 16384));
  cmd->add_option("--seed", o->seed, "Random seed")->check(unsigned_integer());
  cmd->add_option("--light-sampler", o->light_sampler,
                  "The methods' choice of light to sample: bvh (default) or power; the reference uses bvh")
      ->check(CLI::IsMember({"bvh", "power"}));
  cmd->add_option("--sampler", o->sampler, "The methods' camera samples: sobol (default) or independent")
      ->check(CLI::IsMember({"independent", "sobol"}));
  cmd->add_option("--threads", o->threads, "Worker threads (0 = all)")->check(CLI::Range(0, 4096));
  cmd->add_option("--exposure", o->exposure, "Exposure of the PNG images (EV)")
      ->check(finite_number())
      ->check(CLI::Range(-64.0f, 64.0f));
  cmd->add_flag("-q,--quiet", o->quiet, "No progress or table");
  return [o] { run_compare(*o); };
}

}  // namespace gilt::cli
