// Radiosity benchmarks, in three parts (all three when no part is named):
//
//   --sweep         error against time on `cornell`: the element count is swept, each mesh is
//                   solved and rendered, and the render is compared with a path-traced reference
//                   (mean relative error, as in tests/statistical/test_radiosity_vs_path.cpp),
//                   once as a 16-spp render with the usual pixel filter and once through the pixel
//                   centres, where the radiosity render is exact and only the reference's noise
//                   remains. Prints the curve, the floor each measure cannot go below, and the
//                   time it takes to reach 1 % (target: 0.5 s on two cores).
//   --form-factors  point_to_triangle_form_factor per second, a Google Benchmark on one thread.
//   --scaling       progressive refinement's cost at 1k, 10k and 100k elements on `cornell`, each
//                   run given about 20 s of shooting: shots, form factors and shadow rays per
//                   second, residual.
//   --hierarchical  the hierarchical solver's whole run at 10k, 100k and 1M elements on `cornell`
//                   (--largest=N stops after N): nodes, links, iterations, time, the growth exponent
//                   of the time and the peak memory.
//
// Other options: --out-dir=DIR (default out/bench) for the CSV files and the cached references,
// --reference-spp=N (default 32768) for the references' samples per pixel, --fresh-reference to
// render them again, --repeats=N (default 3) timed runs of each sweep point, of which the median
// time is reported, --subdivision-levels=N to override the solver's adaptive subdivision (0:
// none), --solver=progressive|hierarchical for the sweep (default: auto), --view=mesh|two-pass for
// how the sweep shows each solution (default mesh, the exported vertex colours; two-pass is what
// `gilt render --method radiosity` shows, its centre render timed at --view-spp=N samples, default
// 16). The sweep also writes radiosity_error_<elements>.png (radiosity_two_pass_error_…): per-pixel
// relative error against the centre reference, 10 % white. Google Benchmark flags apply to the form-factor part. Every part checks its
// results before it reports a time, and stops with a message when they are wrong.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sys/resource.h>
#include <fstream>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "radiosity/solver/form_factor.h"
#include "radiosity/mesh/mesh.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/util/image_error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
namespace fs = std::filesystem;
using gilt::raytrace_core::DVec3;

namespace {

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "bench_radiosity: %s\n", message.c_str());
  std::exit(EXIT_FAILURE);
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

bool all_finite(const std::vector<rc::Rgb>& pixels) {
  return std::all_of(pixels.begin(), pixels.end(), [](const rc::Rgb& p) { return p.is_finite(); });
}

// ================================================================================================
// Part 1: error against time.

constexpr int kImageSize = 64;          // reference and radiosity renders: 64 × 64 pixels
constexpr int kHalfSpp = 16384;         // default spp of each of the reference's two halves
constexpr uint64_t kSeeds[2] = {1, 2};  // seeds of the two halves; radiosity renders use the first
constexpr int kRadiositySpp = 16;
constexpr int kDisplaySpp = 1024;  // for the display-noise floor (below)
constexpr double kTolerance = 1e-3;
constexpr double kTargetError = 0.01;
constexpr double kTargetSeconds = 0.5;  // issue 10: cornell at 1 % in at most 0.5 s on 2 cores
constexpr int kSweepElements[] = {250, 500, 1000, 2000, 4000, 8000};
constexpr double kPointBudget = 60.0;  // a sweep point predicted to take longer is skipped

/// Where a pixel looks. `filtered`: as `gilt render` does, positions drawn from the default
/// Gaussian pixel filter (radius 1.5 px), so a 16-spp radiosity render is itself noisy wherever
/// the image varies within a pixel's footprint. `centres`: every sample through the pixel centre,
/// which makes a radiosity render exact at one sample and leaves the reference's noise only.
enum class Pixels { filtered, centres };

/// Short name, for file names.
const char* name_of(Pixels pixels) { return pixels == Pixels::filtered ? "filtered" : "centres"; }
/// For the printed report.
const char* label_of(Pixels pixels) {
  return pixels == Pixels::filtered ? "filtered pixels" : "pixel centres";
}

rc::render::RenderSettings render_settings(Pixels pixels, int spp, uint64_t seed) {
  rc::render::RenderSettings s;
  s.width = s.height = kImageSize;
  s.spp = spp;
  s.seed = seed;
  s.threads = 0;
  s.progress = false;
  if (pixels == Pixels::centres) s.filter.radius = 0.0f;
  return s;
}

/// The path-traced reference: the mean of two independent halves, and its own noise, measured as
/// half the error between the halves (the mean of two halves carries half the noise of their
/// difference): the error a perfect image would show against this reference.
struct Reference {
  std::vector<rc::Rgb> image;
  double noise = 0.0;
  int half_spp = 0;
  bool cached = true;  ///< both halves were read from the cache
  double seconds = 0.0;
};

/// One half of the reference, from the cache in `dir` when it holds one made with the same
/// settings, else rendered now and cached. The cache is keyed by the settings, not by the code:
/// after changing the path tracer, run with --fresh-reference.
std::vector<rc::Rgb> reference_half(const rc::scene::Scene& scene, Pixels pixels, int spp, uint64_t seed,
                                    const fs::path& dir, bool fresh, bool& cached) {
  const fs::path file = dir / ("reference_" + scene.name + "_" + name_of(pixels) + "_" +
                               std::to_string(kImageSize) + "x" + std::to_string(kImageSize) + "_" +
                               std::to_string(spp) + "spp_seed" + std::to_string(seed) + ".exr");
  if (!fresh && fs::exists(file)) {
    const rc::util::Image image = rc::util::read_image(file.string());
    if (image.width == kImageSize && image.height == kImageSize && all_finite(image.pixels))
      return image.pixels;
  }
  const rc::render::PathSettings path;
  rc::render::RenderStats stats;
  const rc::render::Film film = rc::render::render_image(
      scene, scene.effective_camera(), render_settings(pixels, spp, seed),
      [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
        return rc::render::path_radiance(scene, ray, ctx, path);
      },
      &stats);
  if (stats.non_finite != 0 || film.non_finite_count() != 0)
    fail("the path-traced reference has non-finite samples");
  rc::util::write_image(file.string(), rc::util::Image{kImageSize, kImageSize, film.pixels()});
  cached = false;
  return film.pixels();
}

Reference make_reference(const rc::scene::Scene& scene, Pixels pixels, int half_spp, const fs::path& dir,
                         bool fresh) {
  const auto start = std::chrono::steady_clock::now();
  Reference ref;
  ref.half_spp = half_spp;
  const std::vector<rc::Rgb> a = reference_half(scene, pixels, half_spp, kSeeds[0], dir, fresh, ref.cached);
  const std::vector<rc::Rgb> b = reference_half(scene, pixels, half_spp, kSeeds[1], dir, fresh, ref.cached);
  ref.image.resize(a.size());
  double luminance = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    ref.image[i] = (a[i] + b[i]) * 0.5f;
    luminance += ref.image[i].luminance();
  }
  luminance /= double(a.size());
  // A coarse band, like bench_path's: catches a black image, a missing light or runaway paths.
  if (!(luminance > 0.045 && luminance < 0.4))
    fail("implausible mean luminance " + std::to_string(luminance) +
         " of the reference (expected about 0.135)");
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) ref.noise += std::abs(a[i][k] - b[i][k]) / (ref.image[i][k] + 0.01);
  ref.noise = 0.5 * ref.noise / (3.0 * double(a.size()));
  ref.seconds = seconds_since(start);
  std::printf("reference (%s): path tracer, 2 x %d spp, %s in %.1f s; mean luminance %.4f, noise %.3f %%\n",
              label_of(pixels), half_spp, ref.cached ? "read from the cache" : "rendered", ref.seconds,
              luminance, 100 * ref.noise);
  return ref;
}

/// A radiosity render of a solution with the reference's camera, size and first seed.
std::vector<rc::Rgb> radiosity_render(const rc::scene::Scene& scene, const rad::bake::RadiosityView& view, Pixels pixels,
                                      int spp) {
  rc::render::RenderStats stats;
  const rc::render::Film film = rc::render::render_image(
      scene, scene.effective_camera(), render_settings(pixels, spp, kSeeds[0]),
      [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return view.radiance(ray, ctx); },
      &stats);
  if (stats.non_finite != 0 || film.non_finite_count() != 0) fail("a radiosity render has non-finite pixels");
  return film.pixels();
}

/// Where the error is: each pixel's relative error (channel mean, as in mean_relative_error),
/// scaled so that 10 % shows white, written as a greyscale PNG.
void write_error_image(const fs::path& file, const std::vector<rc::Rgb>& image, const std::vector<rc::Rgb>& reference) {
  std::vector<rc::Rgb> error(image.size());
  for (size_t i = 0; i < image.size(); ++i) {
    float e = 0.0f;
    for (int k = 0; k < 3; ++k) e += std::abs(image[i][k] - reference[i][k]) / (reference[i][k] + 0.01f);
    error[i] = rc::Rgb(e / 3.0f * 10.0f);
  }
  rc::util::write_image(file.string(), rc::util::Image{kImageSize, kImageSize, error});
}

/// Timed repeats of each sweep point (--repeats=N); the median time is reported.
int g_repeats = 3;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const size_t n = values.size();
  return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

/// Adaptive subdivision levels for every solve (--subdivision-levels=N; default: the solver's).
int g_subdivision_levels = rad::solver::SolverSettings{}.subdivision_levels;
rad::solver::SolverKind g_solver = rad::solver::SolverKind::automatic;

/// How the sweep shows each solution (--view=mesh|two-pass). The mesh view is exact at a pixel
/// centre with one sample; the two-pass view takes the direct light per sample by shadow rays, so
/// its centre render needs g_view_spp samples (--view-spp=N) and their time is counted.
rad::bake::ViewMode g_view = rad::bake::ViewMode::mesh;
int g_view_spp = 16;

rad::solver::SolverSettings solver_settings(int elements) {
  rad::solver::SolverSettings s;
  s.subdivision_levels = g_subdivision_levels;
  s.solver = g_solver;
  s.mesh.elements = elements;
  s.tolerance = kTolerance;
  s.threads = 0;
  s.progress = false;
  return s;
}

/// The error figures of a sweep point. `denoised` is the centre error with the reference's
/// noise taken out in quadrature, √(e² − noise²): an estimate of the error against an exact
/// reference, resting on the noise being independent of the discretisation error.
enum Measure { kFiltered, kCentres, kDenoised, kMeasures };
constexpr const char* kMeasureNames[kMeasures] = {"16-spp error", "centre error", "centre error less noise"};

struct SweepPoint {
  int requested = 0;
  size_t elements = 0, vertices = 0;
  uint64_t shots = 0, form_factors = 0, shadow_rays = 0;
  double residual = 0.0, solve_seconds = 0.0, render_seconds = 0.0;
  double error[kMeasures] = {};
  double seconds() const { return solve_seconds + render_seconds; }
};

/// Least-squares slope of log(error) against log(seconds).
double log_log_slope(const std::vector<SweepPoint>& points, Measure m) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(points.size());
  for (const SweepPoint& p : points) {
    const double x = std::log(p.seconds()), y = std::log(p.error[m]);
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/// Prints the time to reach the target error: interpolated in log-log between the first pair of
/// points that brackets it, else extrapolated (and labelled so) along the slope of the last three.
/// `floor` is the error a perfect solution would show by this measure.
void report_time_to_target(const std::vector<SweepPoint>& points, Measure m, double floor) {
  std::printf("  %s: ", kMeasureNames[m]);
  if (points.front().error[m] <= kTargetError) {
    std::printf("%.0f %% reached already by the coarsest mesh, in %.2f s\n", 100 * kTargetError,
                points.front().seconds());
    return;
  }
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const SweepPoint &a = points[i], &b = points[i + 1];
    if (a.error[m] > kTargetError && b.error[m] <= kTargetError) {
      const double s =
          (std::log(kTargetError) - std::log(a.error[m])) / (std::log(b.error[m]) - std::log(a.error[m]));
      const double t = std::exp(std::log(a.seconds()) + s * (std::log(b.seconds()) - std::log(a.seconds())));
      std::printf("%.0f %% after %.1f s (log-log interpolation between %d and %d elements); target %.1f s\n",
                  100 * kTargetError, t, a.requested, b.requested, kTargetSeconds);
      return;
    }
  }
  const SweepPoint& best = points.back();
  std::printf("%.0f %% not reached within the sweep (%.2f %% at %d elements, %.1f s)\n", 100 * kTargetError,
              100 * best.error[m], best.requested, best.seconds());
  if (floor >= kTargetError) {
    std::printf("    no extrapolation: the floor of this measure (%.2f %%) is above the target\n",
                100 * floor);
    return;
  }
  const std::vector<SweepPoint> last(points.end() - std::min<size_t>(3, points.size()), points.end());
  const double slope = last.size() >= 2 ? log_log_slope(last, m) : 0.0;
  if (!(slope < 0.0)) {
    std::printf("    no extrapolation: the error does not fall with time over the last points\n");
    return;
  }
  const double t = best.seconds() * std::exp((std::log(kTargetError) - std::log(best.error[m])) / slope);
  std::printf(
      "    EXTRAPOLATED, not measured: along error ~ time^%.2f (fit to the last %zu points), %.0f %%\n"
      "    would take about %.0f s; target %.1f s.",
      slope, last.size(), 100 * kTargetError, t, kTargetSeconds);
  if (floor > 0.0)
    std::printf(
        " Rough: the error cannot fall below this measure's floor\n"
        "    (%.2f %%) and flattens as it nears it.",
        100 * floor);
  std::printf("\n");
}

void run_sweep(const fs::path& out_dir, int half_spp, bool fresh_reference) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  const bool two_pass = g_view == rad::bake::ViewMode::two_pass;
  std::printf("\n== Error against time on cornell, %d x %d: solver tolerance %g, %s view ==\n", kImageSize,
              kImageSize, kTolerance, two_pass ? "two-pass" : "mesh");
  const Reference refs[2] = {make_reference(scene, Pixels::filtered, half_spp, out_dir, fresh_reference),
                             make_reference(scene, Pixels::centres, half_spp, out_dir, fresh_reference)};

  // Untimed warm-up (thread pool, Embree), and the noise of a 16-spp display: the same solution
  // at 16 and at 1024 filtered spp differs only by where the pixel filter was sampled.
  const rad::solver::Solution warm = rad::solver::solve(scene, solver_settings(1000));
  const rad::bake::RadiosityView warm_view(scene, warm, rad::bake::ViewMode::mesh);
  const double display_noise =
      rc::util::mean_relative_error(radiosity_render(scene, warm_view, Pixels::filtered, kRadiositySpp),
                          radiosity_render(scene, warm_view, Pixels::filtered, kDisplaySpp));
  std::printf(
      "display noise of a %d-spp filtered radiosity render: %.3f %% (1000 elements, against %d spp)\n",
      kRadiositySpp, 100 * display_noise, kDisplaySpp);
  if (two_pass)
    std::printf(
        "\n  time = solve (two-pass settings: no adaptive subdivision) + view + a %d-spp render through\n"
        "  the pixel centres, whose direct light is sampled per pixel. centre: that render against the\n"
        "  pixel-centre reference; it holds the render's own noise. filtered: a %d-spp render with the\n"
        "  pixel filter (untimed) against the filtered reference. less noise: sqrt(centre^2 - reference\n"
        "  noise^2).\n",
        g_view_spp, g_view_spp);
  else
    std::printf(
        "\n  time = solve (meshing included) + view + %d-spp render. 16-spp: that render against the\n"
        "  filtered reference. centre: the same solution rendered through pixel centres (1 spp, exact)\n"
        "  against the pixel-centre reference. less noise: sqrt(centre^2 - reference noise^2), an estimate\n"
        "  of the centre error against an exact reference.\n",
        kRadiositySpp);

  std::vector<SweepPoint> points;
  std::printf("\n  %9s %8s %8s %7s %9s %8s %8s %8s %9s %9s %12s\n", "requested", "elements", "vertices",
              "shots", "residual", "solve s", "render s", "total s", two_pass ? "filtered %" : "16-spp %", "centre %",
              "less noise %");
  for (int requested : kSweepElements) {
    if (!points.empty()) {
      // Progressive refinement costs shots × vertices, both about proportional to the elements:
      // predict this point quadratically from the last and skip it when over budget.
      const SweepPoint& last = points.back();
      const double predicted = last.seconds() * std::pow(double(requested) / last.requested, 2.0);
      if (predicted > kPointBudget) {
        std::printf(
            "  %9d skipped: predicted %.0f s (time ~ elements^2 from the last point), budget %.0f s\n",
            requested, predicted, kPointBudget);
        continue;
      }
    }
    SweepPoint p;
    p.requested = requested;
    // The solve and render are deterministic, so the repeats give the same solution and image;
    // only their times differ, and the median of each is reported.
    std::vector<double> solve_times, render_times;
    std::optional<rad::solver::Solution> sol;
    std::optional<rad::bake::RadiosityView> view;
    std::vector<rc::Rgb> image, centres;
    for (int r = 0; r < g_repeats; ++r) {
      view.reset();
      const auto start = std::chrono::steady_clock::now();
      sol = rad::solver::solve(scene, rad::bake::solver_settings_for(g_view, solver_settings(requested)));
      solve_times.push_back(seconds_since(start));
      const auto render_start = std::chrono::steady_clock::now();
      view.emplace(scene, *sol, g_view);
      if (two_pass)
        centres = radiosity_render(scene, *view, Pixels::centres, g_view_spp);
      else
        image = radiosity_render(scene, *view, Pixels::filtered, kRadiositySpp);
      render_times.push_back(seconds_since(render_start));
    }
    p.solve_seconds = median(solve_times);
    p.render_seconds = median(render_times);
    if (!(sol->residual < kTolerance))
      fail("the solve of " + std::to_string(requested) + " elements did not converge");
    p.elements = sol->mesh.element_count();
    p.vertices = sol->mesh.vertex_count();
    p.shots = sol->shots;
    p.form_factors = sol->form_factors;
    p.shadow_rays = sol->shadow_rays;
    p.residual = sol->residual;
    // The timed render is the one the view needs to be measured: the mesh view's 16-spp display
    // (its centre render is exact at one sample), the two-pass view's centre render.
    if (two_pass)
      image = radiosity_render(scene, *view, Pixels::filtered, g_view_spp);
    else
      centres = radiosity_render(scene, *view, Pixels::centres, 1);
    p.error[kFiltered] = rc::util::mean_relative_error(image, refs[int(Pixels::filtered)].image);
    p.error[kCentres] = rc::util::mean_relative_error(centres, refs[int(Pixels::centres)].image);
    write_error_image(out_dir / (std::string(two_pass ? "radiosity_two_pass_error_" : "radiosity_error_") +
                                 std::to_string(requested) + ".png"),
                      centres,
                      refs[int(Pixels::centres)].image);
    const double noise = refs[int(Pixels::centres)].noise;
    p.error[kDenoised] = std::sqrt(std::max(1e-12, p.error[kCentres] * p.error[kCentres] - noise * noise));
    points.push_back(p);
    std::printf("  %9d %8zu %8zu %7llu %9.2e %8.2f %8.2f %8.2f %9.3f %9.3f %12.3f\n", p.requested, p.elements,
                p.vertices, (unsigned long long)p.shots, p.residual, p.solve_seconds, p.render_seconds,
                p.seconds(), 100 * p.error[kFiltered], 100 * p.error[kCentres], 100 * p.error[kDenoised]);
    std::fflush(stdout);
  }
  std::printf(
      "\n  floors (error of a perfect solution): 16-spp about %.2f %% (display %.2f %% and reference %.2f "
      "%%\n"
      "  noise together), centre %.2f %% (reference noise)\n",
      100 * std::hypot(display_noise, refs[0].noise), 100 * display_noise, 100 * refs[0].noise,
      100 * refs[1].noise);
  // The two-pass view's filtered render is not the timed one: only its centre figures have a time.
  if (!two_pass) report_time_to_target(points, kFiltered, std::hypot(display_noise, refs[0].noise));
  report_time_to_target(points, kCentres, refs[1].noise);
  report_time_to_target(points, kDenoised, 0.0);

  const fs::path csv = out_dir / (two_pass ? "radiosity_sweep_two_pass.csv" : "radiosity_sweep.csv");
  std::ofstream out(csv);
  out << "requested_elements,elements,vertices,shots,form_factors,shadow_rays,residual,solve_seconds,"
         "render_seconds,seconds,error_16spp,error_centres,error_centres_less_noise,reference_spp,"
         "reference_noise_filtered,reference_noise_centres,display_noise_16spp\n";
  for (const SweepPoint& p : points) {
    char line[400];
    std::snprintf(line, sizeof line,
                  "%d,%zu,%zu,%llu,%llu,%llu,%.6e,%.4f,%.4f,%.4f,%.8f,%.8f,%.8f,%d,%.8f,%.8f,%.8f\n",
                  p.requested, p.elements, p.vertices, (unsigned long long)p.shots,
                  (unsigned long long)p.form_factors, (unsigned long long)p.shadow_rays, p.residual,
                  p.solve_seconds, p.render_seconds, p.seconds(), p.error[kFiltered], p.error[kCentres],
                  p.error[kDenoised], 2 * half_spp, refs[0].noise, refs[1].noise, display_noise);
    out << line;
  }
  if (!out) fail("cannot write " + csv.string());
  std::printf("  written to %s\n", csv.string().c_str());
}

// ================================================================================================
// Part 2: form factors per second.

constexpr size_t kConfigurations = size_t(1) << 16;

/// A receiving point with its unit normal and a source triangle.
struct Configuration {
  DVec3 p, n, a, b, c;
};

DVec3 uniform_in_cube(rc::util::Rng& rng) { return DVec3(rng.uniform(), rng.uniform(), rng.uniform()); }

/// Random triangles in the unit cube, each seen by a random point in front of it (the solver
/// only asks for those) whose normal is uniform on the sphere: some sources lie wholly in front
/// of the receiver's tangent plane, some are clipped by it and some wholly behind it.
std::vector<Configuration> random_configurations() {
  std::vector<Configuration> configs;
  configs.reserve(kConfigurations);
  for (size_t i = 0; configs.size() < kConfigurations; ++i) {
    rc::util::Rng rng = rc::util::Rng::for_item(7, i, 0);
    Configuration c{uniform_in_cube(rng), DVec3(0.0), uniform_in_cube(rng), uniform_in_cube(rng),
                    uniform_in_cube(rng)};
    const DVec3 normal = glm::cross(c.b - c.a, c.c - c.a);
    const double side = glm::dot(normal, c.p - c.a);
    if (!(std::abs(side) > 1e-6)) continue;  // receiver (nearly) in the source's plane
    if (side < 0.0) std::swap(c.b, c.c);     // let the source face the receiver
    const double z = 2.0 * rng.uniform() - 1.0, phi = 2.0 * 3.14159265358979 * rng.uniform();
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    c.n = DVec3(r * std::cos(phi), r * std::sin(phi), z);
    configs.push_back(c);
  }
  return configs;
}

/// Vertex–element pairs of the cornell mesh at 1000 elements, the vertex in front of the element,
/// as the solver meets them.
std::vector<Configuration> cornell_configurations() {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  rad::mesh::MeshSettings settings;
  settings.elements = 1000;
  const rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, settings);
  std::vector<Configuration> configs;
  configs.reserve(kConfigurations);
  for (size_t i = 0; configs.size() < kConfigurations; ++i) {
    rc::util::Rng rng = rc::util::Rng::for_item(8, i, 0);
    const size_t v = std::min(mesh.vertex_count() - 1, size_t(rng.uniform() * float(mesh.vertex_count())));
    const size_t e = std::min(mesh.element_count() - 1, size_t(rng.uniform() * float(mesh.element_count())));
    const auto& el = mesh.elements[e];
    if (!(glm::dot(mesh.element_normal[e], mesh.positions[v] - mesh.positions[el[0]]) > 0.0f)) continue;
    configs.push_back({DVec3(mesh.positions[v]), DVec3(mesh.normals[v]), DVec3(mesh.positions[el[0]]),
                       DVec3(mesh.positions[el[1]]), DVec3(mesh.positions[el[2]])});
  }
  return configs;
}

/// Stops the program unless every factor is finite and in [0, 1]; returns how many are zero.
size_t check_configurations(const char* name, const std::vector<Configuration>& configs) {
  size_t zero = 0;
  for (size_t i = 0; i < configs.size(); ++i) {
    const Configuration& c = configs[i];
    const double f = rad::solver::point_to_triangle_form_factor(c.p, c.n, c.a, c.b, c.c);
    if (!std::isfinite(f) || f < 0.0 || f > 1.0)
      fail(std::string(name) + " configuration " + std::to_string(i) + ": form factor " + std::to_string(f));
    zero += f == 0.0;
  }
  return zero;
}

/// Howell's differential element under a parallel unit square at height 1, its normal through a
/// corner: 0.138532. The square is split into two triangles, whose factors must add up.
void check_howell() {
  const DVec3 p(0.0), n(0.0, 0.0, 1.0);
  const DVec3 a(0, 0, 1), b(0, 1, 1), c(1, 1, 1), d(1, 0, 1);  // counter-clockwise seen from below
  const double f =
      rad::solver::point_to_triangle_form_factor(p, n, a, b, c) + rad::solver::point_to_triangle_form_factor(p, n, a, c, d);
  if (!(std::abs(f - 0.138532) <= 1e-6))
    fail("Howell's corner case gives " + std::to_string(f) + ", not 0.138532");
}

void BM_FormFactor(benchmark::State& state, const std::vector<Configuration>& configs) {
  for (auto _ : state)
    for (const Configuration& c : configs) {
      double f = rad::solver::point_to_triangle_form_factor(c.p, c.n, c.a, c.b, c.c);
      benchmark::DoNotOptimize(f);
    }
  // Shown as "form_factors=…M/s".
  state.counters["form_factors"] =
      benchmark::Counter(double(state.iterations()) * double(configs.size()), benchmark::Counter::kIsRate);
}

void run_form_factors() {
  check_howell();
  static const std::vector<Configuration> random = random_configurations();
  static const std::vector<Configuration> cornell = cornell_configurations();
  const size_t random_zero = check_configurations("random", random);
  const size_t cornell_zero = check_configurations("cornell", cornell);
  std::printf(
      "\n== Form factors per second (one thread, CPU time) ==\n"
      "checked: Howell's corner case 0.138532 within 1e-6; all %zu + %zu factors finite and in [0, 1]\n"
      "  random: triangles in the unit cube, receiver in front, normal uniform on the sphere (%.1f %% zero)\n"
      "  cornell: vertex-element pairs of the 1000-element cornell mesh, vertex in front (%.1f %% zero)\n",
      random.size(), cornell.size(), 100.0 * double(random_zero) / double(random.size()),
      100.0 * double(cornell_zero) / double(cornell.size()));
  std::fflush(stdout);
  benchmark::AddCustomContext("form_factor_configurations", std::to_string(kConfigurations));
  benchmark::RegisterBenchmark("BM_FormFactor_Random", BM_FormFactor, std::cref(random))
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_FormFactor_Cornell", BM_FormFactor, std::cref(cornell))
      ->Unit(benchmark::kMillisecond);
  benchmark::RunSpecifiedBenchmarks();
}

// ================================================================================================
// Part 3: how the solve cost grows with the element count.

constexpr int kScalingElements[] = {1000, 10000, 100000};
constexpr double kShootingBudget = 20.0;  // seconds of shooting per size

void run_scaling(const fs::path& out_dir) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  std::printf(
      "\n== Solve cost against element count on cornell: tolerance %g, at most about %.0f s of shooting ==\n",
      kTolerance, kShootingBudget);
  std::printf("  %9s %8s %8s %7s %7s %8s %8s %10s %10s %9s %9s %s\n", "requested", "elements", "vertices",
              "mesh s", "shots", "shoot s", "shots/s", "FF/s", "rays/s", "no rays %", "residual",
              "stopped by");
  std::ofstream csv(out_dir / "radiosity_scaling.csv");
  csv << "requested_elements,elements,vertices,mesh_seconds,shots,shooting_seconds,shots_per_second,"
         "form_factors_per_second,shadow_rays_per_second,pairs_without_rays,residual,hit_time_limit\n";
  struct Limited {
    size_t elements;
    double shots_per_second;
  };
  std::vector<Limited> limited_runs;
  double shots_per_element = 0.0;  // of the largest run that converged
  for (int requested : kScalingElements) {
    rad::solver::SolverSettings settings = solver_settings(requested);
    settings.solver = rad::solver::SolverKind::progressive;  // this part measures shooting
    // The element count is the variable here: no adaptive subdivision, which would add elements.
    settings.subdivision_levels = 0;
    // solve() meshes too, and its time limit counts from its start: meshing is timed on its own
    // first, and the limit leaves about the same time to shoot at every size.
    const auto mesh_start = std::chrono::steady_clock::now();
    const rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, settings.mesh);
    const double mesh_seconds = seconds_since(mesh_start);
    settings.time_limit = mesh_seconds + kShootingBudget;
    const auto solve_start = std::chrono::steady_clock::now();
    const rad::solver::Solution sol = rad::solver::solve(scene, settings);
    const double shooting = std::max(1e-9, seconds_since(solve_start) - mesh_seconds);
    if (sol.mesh.element_count() != mesh.element_count() || sol.mesh.vertex_count() != mesh.vertex_count())
      fail("build_mesh and solve meshed " + std::to_string(requested) + " elements differently");
    for (const rc::Rgb& b : sol.vertex_radiosity)
      if (!(b.r >= 0.0f && b.g >= 0.0f && b.b >= 0.0f && std::isfinite(b.r + b.g + b.b)))
        fail("negative or non-finite radiosity at " + std::to_string(requested) + " elements");
    const bool limited = !(sol.residual < kTolerance);
    if (limited)
      limited_runs.push_back({mesh.element_count(), double(sol.shots) / shooting});
    else
      shots_per_element = double(sol.shots) / double(mesh.element_count());
    const double without_rays = double(sol.skipped_pairs) / double(std::max<uint64_t>(1, sol.form_factors));
    std::printf("  %9d %8zu %8zu %7.2f %7llu %8.2f %8.1f %10.3e %10.3e %9.1f %9.2e %s\n", requested,
                mesh.element_count(), mesh.vertex_count(), mesh_seconds, (unsigned long long)sol.shots,
                shooting, double(sol.shots) / shooting, double(sol.form_factors) / shooting,
                double(sol.shadow_rays) / shooting, 100 * without_rays, sol.residual,
                limited ? "TIME LIMIT" : "tolerance");
    std::fflush(stdout);
    char line[320];
    std::snprintf(line, sizeof line, "%d,%zu,%zu,%.4f,%llu,%.4f,%.4f,%.6e,%.6e,%.6f,%.6e,%d\n", requested,
                  mesh.element_count(), mesh.vertex_count(), mesh_seconds, (unsigned long long)sol.shots,
                  shooting, double(sol.shots) / shooting, double(sol.form_factors) / shooting,
                  double(sol.shadow_rays) / shooting, without_rays, sol.residual, limited ? 1 : 0);
    csv << line;
  }
  if (!csv) fail("cannot write " + (out_dir / "radiosity_scaling.csv").string());
  std::printf(
      "  shoot s: solve time after meshing; FF/s and rays/s: form factors and shadow rays per second of\n"
      "  it; no rays %%: pairs with a non-zero form factor proven visible without shadow rays, per form "
      "factor\n");
  if (shots_per_element > 0.0)
    for (const Limited& run : limited_runs)
      std::printf(
          "  ESTIMATE, not measured: at %.1f shots per element (the largest converged run) and this run's\n"
          "  shots/s, a full solve of %zu elements would take about %.0f s\n",
          shots_per_element, run.elements, shots_per_element * double(run.elements) / run.shots_per_second);
}

// ================================================================================================
// Part 4: the hierarchical solver's whole run (meshing, direct light, linking, iteration, final
// gather) against the element count, with its growth exponent and peak memory.

constexpr int kHierarchicalElements[] = {10000, 100000, 1000000};

/// Peak resident memory of this process so far, in GiB.
double peak_gib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / (1024.0 * 1024.0);  // ru_maxrss is in KiB on Linux
}

void run_hierarchical(const fs::path& out_dir, int largest) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  std::printf("\n== Hierarchical solve against element count on cornell (tolerance %g, no subdivision) ==\n",
              kTolerance);
  std::printf("  %9s %8s %8s %9s %10s %5s %9s %8s %8s %8s %9s\n", "requested", "elements", "vertices", "nodes",
              "links", "iter", "residual", "total s", "exponent", "peak GiB", "rays/s");
  std::ofstream csv(out_dir / "radiosity_hierarchical.csv");
  csv << "requested_elements,elements,vertices,nodes,links,iterations,residual,seconds,peak_gib,shadow_rays\n";
  double last_elements = 0.0, last_seconds = 0.0;
  for (int requested : kHierarchicalElements) {
    if (requested > largest) break;
    rad::solver::SolverSettings settings = solver_settings(requested);
    settings.solver = rad::solver::SolverKind::hierarchical;
    settings.subdivision_levels = 0;
    const auto start = std::chrono::steady_clock::now();
    const rad::solver::Solution sol = rad::solver::solve(scene, settings);
    const double seconds = seconds_since(start);
    for (const rc::Rgb& b : sol.vertex_radiosity)
      if (!(b.r >= 0.0f && b.g >= 0.0f && b.b >= 0.0f && std::isfinite(b.r + b.g + b.b)))
        fail("negative or non-finite radiosity at " + std::to_string(requested) + " elements");
    // `auto` may skip the vertex final gather where it costs more than the links (the row says
    // so); one stopped part-way would mean the solve did not run to its end.
    const bool gather_skipped = sol.final_gather_note.rfind("skipped", 0) == 0;
    if (!(sol.residual < kTolerance) || !(sol.final_gather || gather_skipped))
      fail("the hierarchical solve of " + std::to_string(requested) + " elements did not converge");
    const double elements = double(sol.mesh.element_count());
    const double exponent =
        last_elements > 0.0 ? std::log(seconds / last_seconds) / std::log(elements / last_elements) : 0.0;
    std::printf("  %9d %8zu %8zu %9zu %10zu %5d %9.2e %8.2f %8s %8.2f %9.3e\n", requested, sol.mesh.element_count(),
                sol.mesh.vertex_count(), sol.nodes, sol.links, sol.iterations, sol.residual, seconds,
                last_elements > 0.0 ? std::to_string(exponent).substr(0, 5).c_str() : "-", peak_gib(),
                double(sol.shadow_rays) / seconds);
    if (gather_skipped) std::printf("  %9s final gather %s\n", "", sol.final_gather_note.c_str());
    std::fflush(stdout);
    char line[320];
    std::snprintf(line, sizeof line, "%d,%zu,%zu,%zu,%zu,%d,%.6e,%.4f,%.4f,%llu\n", requested,
                  sol.mesh.element_count(), sol.mesh.vertex_count(), sol.nodes, sol.links, sol.iterations,
                  sol.residual, seconds, peak_gib(), (unsigned long long)sol.shadow_rays);
    csv << line;
    last_elements = elements, last_seconds = seconds;
  }
  if (!csv) fail("cannot write " + (out_dir / "radiosity_hierarchical.csv").string());
  std::printf("  total s: meshing, direct light, linking, iteration and the vertex final gather; exponent: of\n"
              "  the time against the element count since the previous row\n");
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  bool sweep = false, form_factors = false, scaling = false, hierarchical = false, fresh_reference = false;
  int largest = 1000000;
  int half_spp = kHalfSpp;
  fs::path out_dir = "out/bench";
  for (int i = 1; i < argc; ++i) {
    const std::string_view arg = argv[i];
    if (arg == "--sweep")
      sweep = true;
    else if (arg == "--form-factors")
      form_factors = true;
    else if (arg == "--scaling")
      scaling = true;
    else if (arg == "--hierarchical")
      hierarchical = true;
    else if (arg.starts_with("--largest="))
      largest = std::max(1, std::atoi(argv[i] + 10));
    else if (arg == "--solver=progressive")
      g_solver = rad::solver::SolverKind::progressive;
    else if (arg == "--solver=hierarchical")
      g_solver = rad::solver::SolverKind::hierarchical;
    else if (arg == "--view=two-pass")
      g_view = rad::bake::ViewMode::two_pass;
    else if (arg == "--view=mesh")
      g_view = rad::bake::ViewMode::mesh;
    else if (arg.starts_with("--view-spp="))
      g_view_spp = std::max(1, std::atoi(argv[i] + 11));
    else if (arg.starts_with("--subdivision-levels="))
      g_subdivision_levels = std::max(0, std::atoi(argv[i] + 21));
    else if (arg.starts_with("--repeats="))
      g_repeats = std::max(1, std::atoi(argv[i] + 10));
    else if (arg == "--fresh-reference")
      fresh_reference = true;
    else if (arg.starts_with("--out-dir="))
      out_dir = std::string(arg.substr(10));
    else if (arg.starts_with("--reference-spp="))
      half_spp = std::max(1, std::atoi(argv[i] + 16) / 2);
    else
      fail("unknown option '" + std::string(arg) + "' (parts: --sweep --form-factors --scaling --hierarchical)");
  }
  if (!sweep && !form_factors && !scaling && !hierarchical) sweep = form_factors = scaling = hierarchical = true;
  fs::create_directories(out_dir);

  const auto start = std::chrono::steady_clock::now();
  std::printf("bench_radiosity: %d hardware threads, all used (threads = 0)\n", rc::util::hardware_threads());
  if (form_factors) run_form_factors();
  if (sweep) run_sweep(out_dir, half_spp, fresh_reference);
  if (scaling) run_scaling(out_dir);
  if (hierarchical) run_hierarchical(out_dir, largest);
  std::printf("\nbench_radiosity: done in %.0f s\n", seconds_since(start));
  benchmark::Shutdown();
  return EXIT_SUCCESS;
}
