// Photon-mapping benchmarks, in two parts (both when none is named):
//
//   --trace   photons traced per second on `cornell-caustics` (global and caustic maps, all
//             threads), after checking that the emitted power adds up to the lights' power.
//   --race    error against time on `cornell-caustics` for `photon`, `sppm` and `path`, each given
//             time budgets of 1, 2, 4 and 8 s at 64 × 64, against a long path-traced reference
//             (two halves of --reference-spp/2 samples, cached in --out-dir). The error is the mean
//             relative error |I − R| / (R + 0.01) over pixels and channels, as everywhere in gilt's
//             benchmarks; the reference's own noise is printed with it. For each method the time
//             to reach the error `path` reaches in 8 s is interpolated (log-log) from its curve.
//
//   --index   the kd-tree against the hash grid inside the two-pass mapper and SPPM.
//
// Other options: --out-dir=DIR (default out/bench), --reference-spp=N (default 8192),
// --fresh-reference. Results: photon_race.csv in the output folder.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>
#include <vector>

#include "photonmap/photon_mapper.h"
#include "photonmap/sppm.h"
#include "raytrace_core/util/image_error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace pm = gilt::photonmap;
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_photon: %s\n", message.c_str());
  std::exit(EXIT_FAILURE);
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

constexpr int kSize = 64;
constexpr double kBudgets[] = {1, 2, 4, 8};

rc::render::RenderSettings settings(int spp, uint64_t seed, double time_limit = 0.0) {
  rc::render::RenderSettings s;
  s.width = s.height = kSize;
  s.spp = spp;
  s.seed = seed;
  s.time_limit = time_limit;
  s.progress = false;
  return s;
}

std::vector<rc::Rgb> path_half(const rc::scene::Scene& scene, int spp, uint64_t seed, const fs::path& dir, bool fresh) {
  const fs::path file = dir / ("reference_" + scene.name + "_" + std::to_string(kSize) + "x" + std::to_string(kSize) +
                               "_" + std::to_string(spp) + "spp_seed" + std::to_string(seed) + ".exr");
  if (!fresh && fs::exists(file)) {
    const rc::util::Image image = rc::util::read_image(file.string());
    if (image.width == kSize && image.height == kSize) return image.pixels;
  }
  const rc::render::PathSettings path;
  rc::render::RenderStats stats;
  const rc::render::Film film = rc::render::render_image(
      scene, scene.effective_camera(), settings(spp, seed),
      [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); }, &stats);
  if (stats.non_finite != 0) fail("the reference has non-finite samples");
  rc::util::write_image(file.string(), rc::util::Image{kSize, kSize, film.pixels()});
  return film.pixels();
}

void run_trace() {
  const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
  // Correctness first: every emission sample of this scene's lights carries the light's power.
  for (const rc::scene::Light& light : scene.lights()) {
    rc::Rgb sum(0.0f);
    for (int i = 0; i < 1000; ++i) {
      rc::util::Rng rng = rc::util::Rng::for_item(1, uint64_t(i), 0);
      sum += rc::scene::sample_emission(scene, light, rng.uniform2(), rng.uniform2()).power;
    }
    const rc::Rgb expected = rc::scene::light_power(scene, light);
    if (std::abs(sum.average() / 1000.0f - expected.average()) > 1e-3f * expected.average())
      fail("emitted power does not add up to the light's power");
  }
  pm::PhotonSettings s;
  s.global_photons = 1'000'000;
  s.caustic_photons = 1'000'000;
  std::vector<double> times;
  pm::PhotonMaps maps;
  for (int r = 0; r < 5; ++r) {
    const auto start = std::chrono::steady_clock::now();
    maps = pm::trace_photons(scene, s);
    times.push_back(seconds_since(start));
  }
  std::sort(times.begin(), times.end());
  std::printf("photon tracing on cornell-caustics, 2 x 1M paths emitted (index build included), median of 5:\n");
  std::printf("  %.3f s, %.2f M paths/s; stored %zu global and %zu caustic photons\n", times[2],
              double(maps.paths) / times[2] * 1e-6, maps.global.photons.size(), maps.caustic.photons.size());
}

/// The index for each use: the two-pass mapper (k-nearest queries over both maps and the
/// irradiance points) and SPPM (radius queries), each run with the kd-tree and the hash grid on
/// the same photons, alternating, five times; medians of the render times. The images must be
/// identical, since both indexes return exactly the brute-force neighbours.
void run_index() {
  const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
  const rc::scene::Camera camera = scene.effective_camera();
  std::vector<double> times[2][2];
  std::vector<rc::Rgb> images[2][2];
  for (int r = 0; r < 5; ++r)
    for (int kind = 0; kind < 2; ++kind) {
      const pm::IndexKind index = kind == 0 ? pm::IndexKind::kd_tree : pm::IndexKind::hash_grid;
      pm::PhotonMapperSettings s;
      s.photons.index = index;
      s.index = index;
      const pm::PhotonMapper mapper(scene, s);
      auto start = std::chrono::steady_clock::now();
      images[kind][0] = rc::render::render_image(scene, camera, settings(2, 3),
                                         [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return mapper.radiance(ray, ctx); })
                            .pixels();
      times[kind][0].push_back(seconds_since(start));
      pm::SppmSettings sp;
      sp.index = index;
      start = std::chrono::steady_clock::now();
      images[kind][1] = pm::render_sppm(scene, camera, settings(8, 3), sp).pixels();
      times[kind][1].push_back(seconds_since(start));
    }
  // The two-pass mapper sums neighbours in the same (sorted) order: identical images. SPPM's
  // radius query visits them in each index's own order, so its float sums may differ in the
  // last bits: 1e-5 relative.
  if (images[0][0] != images[1][0]) fail("kd-tree and hash grid give different photon-mapped images");
  for (size_t i = 0; i < images[0][1].size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (std::abs(images[0][1][i][c] - images[1][1][i][c]) > 1e-5f * std::abs(images[0][1][i][c]) + 1e-12f)
        fail("kd-tree and hash grid give different SPPM images at pixel " + std::to_string(i));
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::printf("index on cornell-caustics at %dx%d, medians of 5 (same images checked):\n", kSize, kSize);
  std::printf("  photon render (2 spp, k-nearest): kd-tree %.3f s, hash grid %.3f s\n", median(times[0][0]), median(times[1][0]));
  std::printf("  sppm (8 iterations, radius):      kd-tree %.3f s, hash grid %.3f s\n", median(times[0][1]), median(times[1][1]));
}

struct Point {
  std::string method;
  double budget, seconds, error;
  int spp;
};

void run_race(const fs::path& out_dir, int half_spp, bool fresh) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
  const auto ref_start = std::chrono::steady_clock::now();
  const std::vector<rc::Rgb> a = path_half(scene, half_spp, 1001, out_dir, fresh);
  const std::vector<rc::Rgb> b = path_half(scene, half_spp, 1002, out_dir, fresh);
  std::vector<rc::Rgb> reference(a.size());
  for (size_t i = 0; i < a.size(); ++i) reference[i] = (a[i] + b[i]) * 0.5f;
  const double noise = 0.5 * rc::util::mean_relative_error(a, b);
  std::printf("reference: path tracer, 2 x %d spp at %dx%d (%.1f s, cached when fast); its noise: %.2f %%\n", half_spp,
              kSize, kSize, seconds_since(ref_start), 100 * noise);

  const rc::scene::Camera camera = scene.effective_camera();
  std::vector<Point> points;
  std::printf("\n  method  budget s  actual s   spp   error %%\n");
  for (double budget : kBudgets) {
    for (const char* method : {"path", "photon", "sppm"}) {
      const auto start = std::chrono::steady_clock::now();
      rc::render::Film film;
      int spp = 0;
      const std::string m = method;
      if (m == "path") {
        const rc::render::PathSettings path;
        rc::render::RenderStats stats;
        film = rc::render::render_image(
            scene, camera, settings(1, 7, budget),
            [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); }, &stats);
        spp = stats.spp;
      } else if (m == "photon") {
        const pm::PhotonMapper mapper(scene, pm::PhotonMapperSettings{});
        rc::render::RenderStats stats;
        film = rc::render::render_image(
            scene, camera, settings(1, 7, std::max(0.05, budget - seconds_since(start))),
            [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
              return mapper.radiance(ray, ctx);
            },
            &stats);
        spp = stats.spp;
      } else {
        pm::SppmStats stats;
        film = pm::render_sppm(scene, camera, settings(1, 7, budget), pm::SppmSettings{}, &stats);
        spp = stats.iterations;
      }
      const double seconds = seconds_since(start);
      if (film.non_finite_count() != 0) fail(m + " produced non-finite pixels");
      const Point p{m, budget, seconds, rc::util::mean_relative_error(film.pixels(), reference), spp};
      points.push_back(p);
      std::printf("  %-6s  %8.0f  %8.2f  %4d  %8.2f\n", method, budget, seconds, spp, 100 * p.error);
      std::fflush(stdout);
    }
  }
  // Time to reach path's 8-second error, by log-log interpolation along each method's curve.
  double target = 0.0;
  for (const Point& p : points)
    if (p.method == "path" && p.budget == kBudgets[3]) target = p.error;
  std::printf("\n  time to reach %.2f %% (path's error at 8 s):\n", 100 * target);
  for (const char* method : {"path", "photon", "sppm"}) {
    std::vector<Point> curve;
    for (const Point& p : points)
      if (p.method == method) curve.push_back(p);
    double reached = -1.0;
    for (size_t i = 0; i < curve.size(); ++i) {
      if (curve[i].error > target) continue;
      if (i == 0) {
        reached = curve[0].seconds;  // at or before the first budget
      } else {
        const double t = std::log(target / curve[i - 1].error) / std::log(curve[i].error / curve[i - 1].error);
        reached = std::exp(std::log(curve[i - 1].seconds) + t * std::log(curve[i].seconds / curve[i - 1].seconds));
      }
      break;
    }
    if (reached < 0.0) std::printf("    %-6s not within 8 s (%.2f %% at 8 s)\n", method, 100 * curve.back().error);
    else std::printf("    %-6s %.2f s%s\n", method, reached, reached <= curve[0].seconds ? " (at or before the first budget)" : "");
  }
  const fs::path csv = out_dir / "photon_race.csv";
  std::ofstream out(csv);
  out << "method,budget_seconds,seconds,spp_or_iterations,error,reference_noise\n";
  for (const Point& p : points)
    out << p.method << ',' << p.budget << ',' << p.seconds << ',' << p.spp << ',' << p.error << ',' << noise << '\n';
  if (!out) fail("cannot write " + csv.string());
  std::printf("  written to %s\n", csv.string().c_str());
}

}  // namespace

int main(int argc, char** argv) {
  bool trace = false, race = false, index = false, fresh = false;
  int half_spp = 4096;
  fs::path out_dir = "out/bench";
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--trace") trace = true;
    else if (arg == "--race") race = true;
    else if (arg == "--index") index = true;
    else if (arg == "--fresh-reference") fresh = true;
    else if (arg.starts_with("--out-dir=")) out_dir = std::string(arg.substr(10));
    else if (arg.starts_with("--reference-spp=")) half_spp = std::max(1, std::atoi(argv[i] + 16) / 2);
    else fail("unknown option '" + std::string(arg) + "' (parts: --trace --race)");
  }
  if (!trace && !race && !index) trace = race = index = true;
  fs::create_directories(out_dir);
  if (trace) run_trace();
  if (index) run_index();
  if (race) run_race(out_dir, half_spp, fresh);
  return 0;
}
