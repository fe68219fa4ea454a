// Stochastic progressive photon mapping: Hachisuka & Jensen 2009. Per-pixel statistics as in
// their paper (and pbrt-v3's SPPMIntegrator); photons of each iteration are indexed with the
// photon index's hash grid, cell size about the largest current radius. One departure: each
// pixel's density is divided by the share of its gather disk that holds surface, measured by a
// probe per iteration (probe_coverage), which takes away the darkening at edges and in corners.

#include "photonmap/sppm.h"

#include <atomic>
#include <chrono>
#include <cmath>

#include "photonmap/photon_index.h"
#include "photonmap/photon_map.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/render/direct_light.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/sobol.h"
#include "raytrace_core/util/progress.h"

namespace gilt::photonmap {
namespace {

/// One pixel's statistics and this iteration's visible point.
struct PixelState {
  rc::Rgb direct_sum{0.0f};  ///< emitted + direct light found by the camera paths, summed over iterations
  rc::Rgb tau{0.0f};         ///< flux, unnormalised (divide by π R² · photons emitted)
  float radius = 0.0f;
  float n = 0.0f;            ///< accumulated photon count N
  // Visible point of the current iteration.
  bool visible = false;
  rc::Vec3 position{0.0f}, lit_side{0.0f}, wo{0.0f};  ///< wo in the shading frame
  rc::Frame frame;
  uint32_t material = 0;
  rc::Vec2 uv{0.0f};  ///< where the material's textures are read
  rc::Rgb beta{0.0f};
  // Gathered this iteration.
  rc::Rgb phi{0.0f};
  uint32_t m = 0;
  // Coverage probes over the iterations with a visible point: how many fell on surface that
  // can hold the disk's photons (see probe_coverage).
  uint32_t probes = 0;
  float covered = 0.0f;
};

constexpr uint64_t kPhotonStream = 0xe000000000ull;

constexpr uint64_t kCoverageStream = 0xe100000000ull;

/// One probe of how much of the gather disk (radius r about p, in the plane facing `lit`) is
/// surface whose photons the gather would take. The density estimate divides the disk's photons
/// by its area πr²; past an edge or into a corner part of the ball holds no such surface, and
/// Šibenik's SPPM image came out 4 % dark for it. A point drawn uniformly on the disk is dropped
/// from r above it, straight down; where it meets a photon-holding surface within the ball,
/// turned within kSameSurfaceCosine of `lit`, the probe counts 1 / |cos| of the turn (the
/// surface's area over its projection on the disk), else 0. Its mean over the iterations is the
/// share of πr² the ball's surfaces hold, which the estimate divides by as well.
float probe_coverage(const rc::scene::Scene& scene, const rc::Vec3& p, const rc::Vec3& lit, float r,
                     rc::Vec2 u) {
  const rc::Frame frame = rc::Frame::from_normal(lit);
  const float rho = r * std::sqrt(u.x), phi = 2.0f * rc::kPi * u.y;
  const rc::Vec3 on_disk = p + rho * (std::cos(phi) * frame.s + std::sin(phi) * frame.t);
  rc::scene::Ray probe{on_disk + r * lit, -lit, 2.0f * r};
  const std::optional<rc::scene::Hit> hit = scene.intersect(probe);
  if (!hit) return 0.0f;
  const rc::scene::SurfaceInteraction si = scene.surface(probe, *hit);
  if (glm::length(si.p - p) > r || scene.materials[si.material].is_traced_through()) return 0.0f;
  const float cosine = std::fabs(glm::dot(si.ng, lit));
  return cosine >= kSameSurfaceCosine ? 1.0f / cosine : 0.0f;
}

/// The settings render_sppm cannot run with, as InputError (and an uncommitted scene, a
/// logic_error). Reads the scene's state and the settings; writes nothing.
void check_sppm_settings(const rc::scene::Scene& scene, const rc::render::RenderSettings& settings, const SppmSettings& sppm) {
  if (!scene.committed()) throw std::logic_error("render_sppm: the scene was not committed");
  if (settings.width <= 0 || settings.height <= 0) throw rc::InputError("image size must be positive");
  if (settings.time_limit <= 0.0 && settings.spp <= 0) throw rc::InputError("iterations (--spp) must be positive");
  if (!(sppm.alpha > 0.0f && sppm.alpha < 1.0f)) throw rc::InputError("--alpha must lie in (0, 1)");
  if (sppm.photons_per_iteration == 0) throw rc::InputError("--photons must be positive");
  if (!(sppm.initial_radius >= 0.0f) || !std::isfinite(sppm.initial_radius))
    throw rc::InputError("--radius must be a positive number");
}

/// One SPPM render over its iterations: the inputs, every pixel's statistics, this iteration's
/// photons, and what the image and the statistics are made from. The passes below read and write it.
struct SppmRun {
  /// Reads the settings and the scene's bounds; every pixel starts at radius r0. Under several
  /// processes each owns the rows y mod N (their camera pass and gather) and the photon chunks
  /// c mod N; the photons are joined in chunk order, so every process builds the index one
  /// process would.
  SppmRun(const rc::scene::Scene& scene, const rc::scene::Camera& camera,
          const rc::render::RenderSettings& settings, const SppmSettings& sppm)
      : scene(scene),
        camera(camera),
        settings(settings),
        sppm(sppm),
        start(std::chrono::steady_clock::now()),
        width(settings.width),
        height(settings.height),
        r0(sppm.initial_radius > 0.0f ? sppm.initial_radius : 0.01f * scene.bounds().radius()),
        state(size_t(width) * height),
        lights(scene.lights()),
        choice(scene.light_distribution()),
        timed(settings.time_limit > 0.0),
        group(rc::util::processes()) {
    for (PixelState& p : state) p.radius = r0;
    for (size_t y = 0; y < size_t(height); ++y)
      if (group.owns(y)) rows.push_back(y);
  }

  const rc::scene::Scene& scene;
  const rc::scene::Camera& camera;
  const rc::render::RenderSettings& settings;
  const SppmSettings& sppm;
  const std::chrono::steady_clock::time_point start;
  const int width, height;
  const float r0;
  std::vector<PixelState> state;
  const std::vector<rc::scene::Light>& lights;
  const rc::util::Distribution1D& choice;
  std::atomic<uint64_t> rays{0};
  const bool timed;
  const rc::util::Processes& group;
  std::vector<size_t> rows;  ///< the rows this process owns
  int iteration = 0;
  std::vector<Photon> photons;      ///< this iteration's, stored by the photon pass
  std::vector<rc::Vec3> positions;  ///< their positions, which the index is built over
  double emitted = 0.0;             ///< photon paths emitted over all iterations (develop_image)
  double radius_sum = 0.0;          ///< over pixels some photon reached (develop_image)
  size_t radius_count = 0;

  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); }
};

/// 1. Camera pass, one row: a visible point per pixel and the emitted and direct light on the way
/// to it. Reads the scene, camera, settings and run.iteration; writes each pixel's visible point,
/// its direct_sum, and run.rays.
void trace_visible_row(SppmRun& run, size_t y) {
  const rc::scene::Scene& scene = run.scene;
  const rc::render::RenderSettings& settings = run.settings;
  const int width = run.width, iteration = run.iteration;
  uint64_t local_rays = 0;
  for (int x = 0; x < width; ++x) {
    const uint64_t pixel = uint64_t(y) * width + x;
    PixelState& ps = run.state[pixel];
    ps.visible = false;
    rc::render::Sampler sampler = rc::render::Sampler::for_pixel_sample(settings.sampler, settings.seed, pixel, uint64_t(iteration));
    rc::scene::Ray ray = rc::render::camera_ray(run.camera, settings, x, y, sampler);
    rc::Rgb beta(1.0f), direct(0.0f);
    // Mirrors and glass only, without Russian roulette: 64 bounces at most.
    for (int depth = 0; depth < std::min(run.sppm.max_depth, 64); ++depth) {
      sampler.start_bounce(depth);
      ++local_rays;
      const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
      if (!hit) {
        direct += beta * rc::scene::escaped_radiance(scene.punctual_lights, glm::normalize(ray.direction));
        break;
      }
      const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
      rc::scene::Material textured;
      const rc::scene::Material& m = scene.shading_material(si, textured);
      if (m.kind == rc::scene::MaterialKind::dielectric && !si.front_face && !m.absorption.is_black())
        beta *= rc::exp(m.absorption * (-hit->t * glm::length(ray.direction)));
      const rc::Vec3 wo_world = -glm::normalize(ray.direction);
      if (m.is_emissive()) direct += beta * rc::scene::emitted_radiance(m, si.ng, wo_world);
      const rc::Frame frame = rc::Frame::from_normal(si.ns);
      const rc::Vec3 wo = frame.to_local(wo_world);
      const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f;
      if (!m.is_traced_through()) {
        direct += beta *
                  rc::render::sample_direct_mis(scene, si, m, frame, wo, wo_above, sampler, local_rays, 0.0f);
        ps.visible = true;
        ps.position = si.p;
        ps.lit_side = wo_above ? si.ng : -si.ng;
        ps.wo = wo;
        ps.frame = frame;
        ps.material = si.material;
        ps.uv = si.uv;
        ps.beta = beta;
        break;
      }
      const std::optional<rc::scene::BsdfSample> bs =
          rc::scene::bsdf_sample(m, wo, sampler.uniform(), sampler.uniform2());
      if (!bs || !(bs->pdf > 0.0f) || bs->f.is_black()) break;
      const rc::Vec3 wi_world = frame.to_world(bs->wi);
      if ((glm::dot(wi_world, si.ng) > 0.0f) != (bs->transmission ? !wo_above : wo_above)) break;
      beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf);
      ray = rc::scene::continue_ray(si, wi_world);
    }
    if (direct.is_finite()) ps.direct_sum += direct;
  }
  run.rays += local_rays;
}

/// 1. Camera pass over the rows this process owns (trace_visible_row).
void trace_visible_points(SppmRun& run) {
  rc::util::parallel_for(run.rows.size(), [&](size_t k) { trace_visible_row(run, run.rows[k]); });
}

/// 2. Photon pass: every diffuse or glossy hit but the first (direct light is the camera pass's),
/// unnormalised power. Reads the scene's lights, the settings and run.iteration; writes
/// run.photons and run.positions (every process's, in chunk order) and run.rays.
void trace_photons(SppmRun& run) {
  const rc::scene::Scene& scene = run.scene;
  const SppmSettings& sppm = run.sppm;
  const uint64_t count = sppm.photons_per_iteration;
  constexpr uint64_t kChunk = 4096;
  const size_t chunks = size_t((count + kChunk - 1) / kChunk);
  std::vector<std::vector<Photon>> stored(chunks);
  if (run.choice.size() > 0) {
    rc::util::distributed_chunks<Photon>(stored, [&](size_t c, std::vector<Photon>& out) {
      uint64_t local_rays = 0;
      for (uint64_t i = c * kChunk; i < std::min(count, (c + 1) * kChunk); ++i) {
        rc::util::Rng rng =
            rc::util::Rng::for_item(run.settings.seed, i, kPhotonStream + uint64_t(run.iteration));
        const uint32_t li = run.choice.sample(rng.uniform());
        const float pmf = run.choice.pmf(li);
        const rc::Vec2 u_position = rng.uniform2(), u_direction = rng.uniform2();
        const rc::scene::EmissionSample es =
            rc::scene::sample_emission(scene, run.lights[li], u_position, u_direction);
        if (es.power.is_black() || !(pmf > 0.0f)) continue;
        local_rays += trace_photon_path(scene, es.ray, es.power / pmf, rng, sppm.max_depth,
                                        [&](const Photon& p, int depth, bool) {
                                          if (depth > 0) out.push_back(p);
                                          return true;
                                        });
      }
      run.rays += local_rays;
    });
  }
  run.photons.clear();
  for (const auto& s : stored) run.photons.insert(run.photons.end(), s.begin(), s.end());
  run.positions.resize(run.photons.size());
  for (size_t i = 0; i < run.photons.size(); ++i) run.positions[i] = run.photons[i].position;
}

/// Reads run.positions and the pixels' radii (the largest over every process sizes the hash
/// grid's cells); returns this iteration's photon index.
PhotonIndex index_photons(const SppmRun& run) {
  float max_radius = 0.0f;
  for (size_t y : run.rows)
    for (int x = 0; x < run.width; ++x) max_radius = std::max(max_radius, run.state[y * run.width + x].radius);
  return PhotonIndex(run.positions, run.sppm.index, run.group.max(max_radius));
}

/// 3. Gather and radius update, one row. Reads the visible points, run.photons through the index
/// and run.iteration; writes each visible pixel's coverage probe, τ, N and radius.
void gather_row(SppmRun& run, const PhotonIndex& index, size_t y) {
  const rc::scene::Scene& scene = run.scene;
  const SppmSettings& sppm = run.sppm;
  const int width = run.width;
  for (int x = 0; x < width; ++x) {
    PixelState& ps = run.state[size_t(y) * width + x];
    if (!ps.visible) continue;
    rc::scene::SurfaceInteraction at;
    at.material = ps.material;
    at.uv = ps.uv;
    rc::scene::Material textured;
    const rc::scene::Material& m = scene.shading_material(at, textured);
    rc::Rgb phi(0.0f);
    uint32_t m_count = 0;
    index.for_each_within(ps.position, ps.radius * ps.radius, [&](Neighbour nb) {
      const Photon& p = run.photons[nb.index];
      // The photon method's test of a photon's surface (photon_map.h). SPPM had 60° from the
      // light-BVH session on: at 25° the facets of Šibenik's columns and arches turned away
      // each other's photons while the disk still counted their area (11.6 % dark at 30 s).
      // The disk's coverage (probe_coverage) counts only the surface that passes the test,
      // which took that darkening away, and the wider test then left a darkening of its own
      // (bench/README.md, "SPPM's test of a photon's surface").
      if (glm::dot(decode_direction(p.normal), ps.lit_side) < kSameSurfaceCosine) return;
      const rc::Vec3 wi = ps.frame.to_local(decode_direction(p.direction));
      phi += rc::scene::bsdf_eval(m, ps.wo, wi) * p.power;
      ++m_count;
    });
    // The pixel's probes, one an iteration, are the points of an Owen-scrambled 2D Sobol
    // sequence of its own: stratified over the disk, so a few dozen iterations already
    // measure the coverage closely (independent probes left 1 / coverage noisy enough to
    // bias the plank of test_sppm_convergence 6 % bright over 16 iterations).
    rc::util::Rng seeds =
        rc::util::Rng::for_item(run.settings.seed, uint64_t(y) * width + x, kCoverageStream);
    const uint32_t seed_x = seeds.next_u32(), seed_y = seeds.next_u32();
    const auto sobol_index = uint32_t(run.iteration);
    const rc::Vec2 u(rc::util::sobol::to_unit_float(rc::util::sobol::owen_scramble(rc::util::sobol::dimension0(sobol_index), seed_x)),
                     rc::util::sobol::to_unit_float(rc::util::sobol::owen_scramble(rc::util::sobol::dimension1(sobol_index), seed_y)));
    ++ps.probes;
    ps.covered += probe_coverage(scene, ps.position, ps.lit_side, ps.radius, u);
    if (m_count == 0) continue;
    const float n_new = ps.n + sppm.alpha * float(m_count);
    const float shrink2 = n_new / (ps.n + float(m_count));
    if (phi.is_finite()) ps.tau = (ps.tau + ps.beta * phi) * shrink2;
    ps.n = n_new;
    ps.radius *= std::sqrt(shrink2);
  }
}

/// 3. Gather at the visible points and shrink the radii, over the rows this process owns (gather_row).
void gather_and_shrink(SppmRun& run, const PhotonIndex& index) {
  rc::util::parallel_for(run.rows.size(), [&](size_t k) { gather_row(run, index, run.rows[k]); });
}

/// A pixel of the image as its row's owner made it.
struct PixelOut {
  rc::Rgb value;
  float radius = 0.0f;  ///< 0: no photon ever reached the pixel
};

/// 4. The image: mean direct light plus τ / (π R² · photons emitted), each row made by its owner
/// and joined. Reads the pixels and run.iteration; writes run.emitted, run.radius_sum and
/// run.radius_count, and returns the film.
rc::render::Film develop_image(SppmRun& run) {
  const int width = run.width, height = run.height, iteration = run.iteration;
  const double emitted = run.emitted = double(iteration) * double(run.sppm.photons_per_iteration);
  std::vector<std::vector<PixelOut>> out(static_cast<size_t>(height));
  for (size_t y : run.rows)
    for (int x = 0; x < width; ++x) {
      const PixelState& ps = run.state[y * width + x];
      PixelOut o{ps.direct_sum / float(std::max(iteration, 1))};
      if (ps.n > 0.0f) {
        const double coverage = ps.covered > 0.0f ? std::max(0.1, double(ps.covered) / double(ps.probes)) : 1.0;
        o.value += ps.tau * float(1.0 / (rc::kPi * double(ps.radius) * ps.radius * emitted * coverage));
        o.radius = ps.radius;
      }
      out[y].push_back(o);
    }
  rc::util::join_chunks(out);
  rc::render::Film film(width, height);
  double radius_sum = 0.0;
  size_t radius_count = 0;
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const PixelOut& o = out[y][x];
      if (o.radius > 0.0f) radius_sum += o.radius, ++radius_count;
      film.add_sample(x, y, o.value);
    }
  run.radius_sum = radius_sum;
  run.radius_count = radius_count;
  return film;
}

/// Reads run's counts (the rays summed over every process); writes *stats when asked for.
void report_sppm_stats(const SppmRun& run, SppmStats* stats) {
  uint64_t total_rays = run.rays;
  run.group.sum(std::span(&total_rays, 1));
  if (stats) {
    stats->iterations = run.iteration;
    stats->photons = uint64_t(run.emitted);
    stats->rays = total_rays;
    stats->seconds = run.elapsed();
    stats->initial_radius = run.r0;
    stats->mean_final_radius = run.radius_count ? float(run.radius_sum / double(run.radius_count)) : run.r0;
  }
}

}  // namespace

rc::render::Film render_sppm(const rc::scene::Scene& scene, const rc::scene::Camera& camera,
                             const rc::render::RenderSettings& settings, const SppmSettings& sppm,
                             SppmStats* stats) {
  check_sppm_settings(scene, settings, sppm);
  const rc::util::ThreadLimit limit(settings.threads);
  SppmRun run(scene, camera, settings, sppm);
  const bool timed = run.timed;
  rc::util::Progress progress(timed ? "sppm (time budget)" : "sppm", timed ? 0 : uint64_t(settings.spp), "iterations",
                        settings.progress && run.group.rank() == 0);
  for (;; ++run.iteration) {
    // Rank 0's clock decides for every process.
    if (timed ? run.group.broadcast_value(run.elapsed() >= settings.time_limit) && run.iteration > 0
              : run.iteration >= settings.spp)
      break;
    trace_visible_points(run);
    trace_photons(run);
    const PhotonIndex index = index_photons(run);
    gather_and_shrink(run, index);
    progress.advance(1);
  }
  progress.finish();
  rc::render::Film film = develop_image(run);
  report_sppm_stats(run, stats);
  return film;
}

}  // namespace gilt::photonmap
