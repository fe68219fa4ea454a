// Path-tracer throughput: camera samples per second (and the rays they trace) on the built-in
// Cornell box at 256 × 256, 4 samples per pixel per iteration, with one and with two worker
// threads.
//
// Before anything is timed, one render is checked: no NaN or infinite sample, a plausible mean
// radiance, and the very same image with one thread as with two (gilt's determinism promise).

#include <benchmark/benchmark.h>

#include <bit>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;

namespace {

constexpr int kImageSize = 256;
constexpr int kSpp = 4;  // samples per pixel in each timed render

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_path: %s\n", message.c_str());
  std::exit(EXIT_FAILURE);
}

/// One render of the scene with `threads` worker threads, no progress bar.
rc::render::Film render(const rc::scene::Scene& scene, const rc::scene::Camera& camera, int threads,
                        rc::render::RenderStats* stats) {
  rc::render::RenderSettings settings;
  settings.width = kImageSize;
  settings.height = kImageSize;
  settings.spp = kSpp;
  settings.threads = threads;
  settings.progress = false;
  const rc::render::PathSettings path;
  return rc::render::render_image(
      scene, camera, settings,
      [&scene, &path](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
        return rc::render::path_radiance(scene, ray, ctx, path);
      },
      stats);
}

/// Mean luminance of the image, in W·sr⁻¹·m⁻².
double mean_luminance(const rc::render::Film& film) {
  double sum = 0.0;
  for (const rc::Rgb& p : film.pixels()) sum += p.luminance();
  return sum / (double(film.width()) * film.height());
}

/// Renders once with one and once with two threads and stops the program unless the images are
/// finite, identical to the bit, and of a plausible brightness. Returns the mean luminance.
double check_render(const rc::scene::Scene& scene, const rc::scene::Camera& camera) {
  rc::render::RenderStats one_stats, two_stats;
  const rc::render::Film one = render(scene, camera, 1, &one_stats);
  const rc::render::Film two = render(scene, camera, 2, &two_stats);
  if (one_stats.non_finite != 0 || two_stats.non_finite != 0 || one.non_finite_count() != 0)
    fail("the path tracer returned NaN or infinite samples");
  if (one_stats.rays != two_stats.rays) fail("one and two threads traced different numbers of rays");
  const std::vector<rc::Rgb> a = one.pixels(), b = two.pixels();
  for (size_t i = 0; i < a.size(); ++i)
    for (int c = 0; c < 3; ++c)
      if (std::bit_cast<uint32_t>(a[i][c]) != std::bit_cast<uint32_t>(b[i][c]))
        fail("pixel " + std::to_string(i) + " differs between one and two threads");
  // A coarse band, not a statistical test: this render (fixed seed) has a mean of 0.114 today, and
  // a factor of three either way still catches a black image, a missing light or runaway paths.
  const double mean = mean_luminance(one);
  if (!(mean > 0.038 && mean < 0.34))
    fail("implausible mean luminance " + std::to_string(mean) + " (expected about 0.114)");
  return mean;
}

void BM_PathTracer_Cornell(benchmark::State& state, const rc::scene::Scene& scene,
                           const rc::scene::Camera& camera) {
  const int threads = int(state.range(0));
  uint64_t samples = 0, rays = 0;
  for (auto _ : state) {
    rc::render::RenderStats stats;
    rc::render::Film film = render(scene, camera, threads, &stats);
    benchmark::DoNotOptimize(film);
    samples += stats.samples;
    rays += stats.rays;
  }
  // Per second of wall time, shown as "samples=…k/s" and "rays=…M/s".
  state.counters["samples"] = benchmark::Counter(double(samples), benchmark::Counter::kIsRate);
  state.counters["rays"] = benchmark::Counter(double(rays), benchmark::Counter::kIsRate);
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return EXIT_FAILURE;

  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  const rc::scene::Camera camera = scene.effective_camera();
  const double mean = check_render(scene, camera);
  std::fprintf(
      stderr, "bench_path: cornell at %d x %d, %d spp: mean luminance %.4f, identical with 1 and 2 threads\n",
      kImageSize, kImageSize, kSpp, mean);
  benchmark::AddCustomContext("scene", "cornell");
  benchmark::AddCustomContext("image", std::to_string(kImageSize) + "x" + std::to_string(kImageSize));
  benchmark::AddCustomContext("spp_per_iteration", std::to_string(kSpp));

  benchmark::RegisterBenchmark("BM_PathTracer_Cornell", BM_PathTracer_Cornell, std::cref(scene),
                               std::cref(camera))
      ->ArgName("threads")
      ->Arg(1)
      ->Arg(2)
      ->UseRealTime()
      ->Unit(benchmark::kMillisecond);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return EXIT_SUCCESS;
}
