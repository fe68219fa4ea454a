#pragma once
// Shared by the stress tests: one small image by any of gilt's five methods, counting every
// non-finite value the method produced, and a watchdog that turns a hang into a failure.

#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "photonmap/photon_mapper.h"
#include "photonmap/sppm.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/scene/scene.h"
#include "raytrace_core/render/whitted.h"

namespace gilt::stress {

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
namespace pm = gilt::photonmap;

/// The methods under test.
enum class Method { path, whitted, radiosity, photon, sppm };

inline const char* method_name(Method m) {
  switch (m) {
    case Method::path:
      return "path";
    case Method::whitted:
      return "whitted";
    case Method::radiosity:
      return "radiosity";
    case Method::photon:
      return "photon";
    case Method::sppm:
      return "sppm";
  }
  return "?";
}

inline const std::vector<Method> kAllMethods = {Method::path, Method::whitted, Method::radiosity,
                                                Method::photon, Method::sppm};

/// A small budget for every method, so one image takes a fraction of a second.
struct Budget {
  int size = 24;  ///< image width and height
  int spp = 8;    ///< path, whitted, radiosity view, photon; sppm iterations
  int radiosity_elements = 300;
  uint64_t photons = 20'000;  ///< photon: global and caustic each; sppm: per iteration
  int gather_rays = 4;
};

/// An image and every count of non-finite values met on the way to it.
struct MethodResult {
  std::vector<rc::Rgb> image;
  uint64_t non_finite_samples = 0;   ///< samples render_image discarded as NaN or infinite
  size_t non_finite_pixels = 0;      ///< pixels of the final image that are NaN or infinite
  size_t non_finite_vertices = 0;    ///< radiosity: vertex radiosity or irradiance NaN or infinite
  bool non_finite_residual = false;  ///< radiosity: the residual is NaN or infinite
  std::optional<rad::solver::Solution> solution;

  /// Every count above, summed: zero when nothing non-finite appeared anywhere.
  uint64_t non_finite_total() const {
    return non_finite_samples + non_finite_pixels + non_finite_vertices + (non_finite_residual ? 1 : 0);
  }
};

inline size_t count_non_finite(const std::vector<rc::Rgb>& values) {
  size_t n = 0;
  for (const rc::Rgb& c : values) n += c.is_finite() ? 0 : 1;
  return n;
}

/// Mean of all pixels, channels averaged.
inline double image_mean(const std::vector<rc::Rgb>& image) {
  double sum = 0.0;
  for (const rc::Rgb& c : image) sum += c.average();
  return sum / double(image.size());
}

/// Renders the committed scene with its own camera by `method` at a fixed seed.
inline MethodResult render_method(const rc::scene::Scene& scene, Method method, const Budget& budget,
                                  uint64_t seed) {
  rc::render::RenderSettings s;
  s.width = s.height = budget.size;
  s.spp = budget.spp;
  s.seed = seed;
  s.progress = false;
  const rc::scene::Camera camera = scene.effective_camera();
  MethodResult r;
  rc::render::RenderStats stats;
  rc::render::Film film;
  switch (method) {
    case Method::path: {
      const rc::render::PathSettings path;
      film = rc::render::render_image(
          scene, camera, s,
          [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
            return rc::render::path_radiance(scene, ray, ctx, path);
          },
          &stats);
      break;
    }
    case Method::whitted: {
      const rc::render::WhittedSettings whitted;
      film = rc::render::render_image(
          scene, camera, s,
          [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
            return rc::render::whitted_radiance(scene, ray, ctx, whitted);
          },
          &stats);
      break;
    }
    case Method::radiosity: {
      rad::solver::SolverSettings solver;
      solver.mesh.elements = budget.radiosity_elements;
      solver.seed = seed;
      solver.progress = false;
      r.solution.emplace(rad::solver::solve(scene, solver));
      r.non_finite_vertices =
          count_non_finite(r.solution->vertex_radiosity) + count_non_finite(r.solution->vertex_irradiance);
      r.non_finite_residual = !std::isfinite(r.solution->residual);
      const rad::bake::RadiosityView view(scene, *r.solution);
      film = rc::render::render_image(
          scene, camera, s,
          [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return view.radiance(ray, ctx); },
          &stats);
      break;
    }
    case Method::photon: {
      pm::PhotonMapperSettings settings;
      settings.photons.global_photons = budget.photons;
      settings.photons.caustic_photons = budget.photons;
      settings.photons.seed = seed;
      settings.gather_rays = budget.gather_rays;
      const pm::PhotonMapper mapper(scene, settings);
      film = rc::render::render_image(
          scene, camera, s,
          [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
            return mapper.radiance(ray, ctx);
          },
          &stats);
      break;
    }
    case Method::sppm: {
      pm::SppmSettings sppm;
      sppm.photons_per_iteration = budget.photons;
      film = pm::render_sppm(scene, camera, s, sppm);
      break;
    }
  }
  r.image = film.pixels();
  r.non_finite_samples = stats.non_finite;
  r.non_finite_pixels = count_non_finite(r.image);
  return r;
}

/// Fails the test program when its scope lasts longer than `limit`: a hang then ends the test
/// run with a message naming the case instead of blocking CI. (A thread cannot be cancelled, so
/// the only way out is to end the process; CTest runs each test in its own process.)
class Watchdog {
 public:
  Watchdog(std::string what, std::chrono::seconds limit)
      : what_(std::move(what)), limit_(limit), start_(std::chrono::steady_clock::now()) {
    thread_ = std::thread([this] {
      std::unique_lock<std::mutex> lock(mutex_);
      if (!done_cv_.wait_for(lock, limit_, [this] { return done_; })) {
        std::fprintf(stderr, "\nwatchdog: '%s' still running after %lld s: treating it as a hang\n",
                     what_.c_str(), static_cast<long long>(limit_.count()));
        std::fflush(stderr);
        std::_Exit(EXIT_FAILURE);
      }
    });
  }
  ~Watchdog() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    done_cv_.notify_all();
    thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Seconds since the watchdog started.
  double seconds() const {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  }

 private:
  std::string what_;
  std::chrono::seconds limit_;
  std::chrono::steady_clock::time_point start_;
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace gilt::stress
