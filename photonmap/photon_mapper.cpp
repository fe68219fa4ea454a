// Two-pass photon mapping: Jensen 1996; final gather with precomputed irradiance: Christensen
// 1999; multiple importance sampling of direct light: Veach & Guibas 1995.

#include "photonmap/photon_mapper.h"

#include <chrono>
#include <cmath>

#include "photonmap/coverage.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/render/direct_light.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/processes.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::photonmap {
namespace {

/// A point for spawning shadow rays at a photon position, whose rounding error is not tracked:
/// the bound allows for γ(16)·|p|, as the radiosity solver does for mesh points.
rc::scene::SurfacePoint point_at(const rc::Vec3& p, const rc::Vec3& n) {
  rc::scene::SurfacePoint sp;
  sp.p = p;
  sp.p_error = rc::scene::error_gamma(16) * rc::abs(p);
  sp.ng = n;
  return sp;
}

EstimateScratch& thread_scratch() {
  thread_local EstimateScratch scratch;
  return scratch;
}

}  // namespace

PhotonMapper::PhotonMapper(const rc::scene::Scene& scene, const PhotonMapperSettings& settings)
    : scene_(scene), settings_(settings) {
  if (!scene.committed()) throw std::logic_error("PhotonMapper: the scene was not committed");
  if (settings.k < 1) throw rc::InputError("--k must be at least 1");
  if (settings.gather_rays < 0) throw rc::InputError("--gather-rays must not be negative");
  if (settings.precompute_stride < 1) throw rc::InputError("the precompute stride must be at least 1");
  if (settings.direct_samples < 1) throw rc::InputError("direct samples must be at least 1");
  if (!(settings.max_radius >= 0.0f) || !std::isfinite(settings.max_radius))
    throw rc::InputError("--radius must be a positive number");
  if (settings.max_depth < 1) throw rc::InputError("--max-depth must be at least 1");

  maps_ = trace_photons(scene, settings.photons);
  stats_.skipped = maps_.skipped;
  stats_.global_photons = maps_.global.photons.size();
  stats_.caustic_photons = maps_.caustic.photons.size();
  stats_.paths = maps_.paths;
  stats_.trace_seconds = maps_.seconds;
  // The global map's estimates are divided by their disk's coverage of the scene's surface
  // (photonmap/coverage.h): a k-nearest disk that reaches past an edge or into a corner would
  // read dark. The caustic map is not: its photons are not spread evenly over any disk.
  if (!maps_.global.empty()) maps_.global.sides = every_side(scene);
  const float radius = settings.max_radius > 0.0f ? settings.max_radius : 0.05f * scene.bounds().radius();
  stats_.max_radius = radius;
  max_radius2_ = radius * radius;
  if (!map_needs(scene).global && settings_.gather_rays > 0) {
    settings_.gather_rays = 0;
    stats_.skipped.push_back("final gather skipped: no interreflection");
  }

  // Irradiance at sites for the gather rays to look up: where the global map's photons would be
  // stored, from one path in stride of their own (about one site per stride-th photon). Not at
  // the map's own photons, as Christensen (1999) has it: an estimate at a photon counts that
  // photon at its kernel's peak, k / (k − 2) too much on a flat surface and more where few of the
  // k nearest agree with the normal; and leaving it out is not enough, because the lookup takes
  // the nearest site, so a site's weight grows with its Voronoi cell, which is large where the
  // map happens to be sparse, and so its estimate low. On Šibenik (k = 50) an estimate at a
  // photon read 10 % more with it than without; without it, the looked-up irradiance averaged
  // 5.6 % below an estimate at the gather hit itself (bench/README.md, "The photon method's
  // biases"). Sites from paths of their own are independent of the map, and both biases go.
  const auto start = std::chrono::steady_clock::now();
  if (settings_.gather_rays > 0 && !maps_.global.empty()) {
    const uint64_t stride = uint64_t(settings.precompute_stride);
    const std::vector<Photon> sites =
        trace_global_sites(scene, settings.photons, (maps_.global.emitted + stride - 1) / stride, stats_.paths);
    const size_t count = sites.size();
    // Chunks of 1,024 points; under several processes each computes those it owns.
    std::vector<std::vector<IrradiancePoint>> chunks((count + 1023) / 1024);
    rc::util::distributed_chunks<IrradiancePoint>(chunks, [&](size_t chunk,
                                                              std::vector<IrradiancePoint>& out) {
      for (size_t i = chunk * 1024; i < std::min(count, chunk * 1024 + 1024); ++i) {
        const Photon& p = sites[i];
        rc::render::Sampler sampler(rc::util::Rng::for_item(settings.photons.seed, i, 0xd000000000ull));
        out.push_back({p.position, p.normal,
                       compute_irradiance(p.position, decode_direction(p.normal), sampler, settings.direct_samples)});
      }
    });
    points_.clear();
    points_.reserve(count);
    for (const auto& c : chunks) points_.insert(points_.end(), c.begin(), c.end());
    std::vector<rc::Vec3> positions(count);
    for (size_t i = 0; i < count; ++i) positions[i] = points_[i].position;
    point_index_ = PhotonIndex(positions, settings.index);
  }
  stats_.irradiance_points = points_.size();
  stats_.precompute_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

rc::Rgb PhotonMapper::compute_irradiance(const rc::Vec3& p, const rc::Vec3& normal,
                                         rc::render::Sampler& sampler, int direct_samples) const {
  rc::Rgb e(0.0f);
  const auto& lights = scene_.lights();
  const rc::scene::LightSampler& choice = scene_.light_sampler();
  if (choice.size() > 0) {
    const rc::scene::SurfacePoint at = point_at(p, normal);
    const rc::scene::LightQuery query{p, normal, false};
    for (int i = 0; i < direct_samples; ++i) {
      const rc::scene::LightChoice chosen = choice.sample(query, sampler.uniform());
      const float pmf = chosen.pmf;
      const rc::Vec2 u_light = sampler.uniform2();
      if (!(pmf > 0.0f)) continue;
      const rc::scene::LightSample ls =
          rc::scene::sample_light(scene_, lights[chosen.light], at, u_light, normal);
      const float cos_theta = glm::dot(ls.wi, normal);
      if (!(ls.pdf > 0.0f) || !(cos_theta > 0.0f) || ls.radiance.is_black()) continue;
      if (scene_.occluded(ls.shadow_ray)) continue;
      e += ls.radiance * (cos_theta / (ls.pdf * pmf * float(direct_samples)));
    }
  }
  const EstimateQuery query{p, normal, size_t(settings_.k), max_radius2_};
  e += estimate_irradiance(scene_, maps_.global, query, thread_scratch());
  e += estimate_irradiance(maps_.caustic, query, thread_scratch());
  return e;
}

rc::Rgb PhotonMapper::irradiance(const rc::Vec3& p, const rc::Vec3& normal,
                                 rc::render::Sampler& sampler) const {
  if (!points_.empty()) {
    constexpr size_t kCandidates = 8;
    Neighbour near[kCandidates];
    const size_t found = point_index_.knn(p, kCandidates, max_radius2_, near);
    for (size_t i = 0; i < found; ++i)
      if (glm::dot(decode_direction(points_[near[i].index].normal), normal) > 0.9f)
        return points_[near[i].index].irradiance;
  }
  return compute_irradiance(p, normal, sampler, 4);
}

rc::Rgb PhotonMapper::radiance(const rc::scene::Ray& camera_ray, rc::render::SampleContext& ctx) const {
  rc::Rgb radiance(0.0f), beta(1.0f);
  rc::scene::Ray ray = camera_ray;
  for (int depth = 0; depth < settings_.max_depth; ++depth) {
    ctx.sampler.start_bounce(depth);
    ++ctx.rays;
    const std::optional<rc::scene::Hit> hit = scene_.intersect(ray);
    if (!hit) {
      radiance += beta * rc::scene::escaped_radiance(scene_.punctual_lights, glm::normalize(ray.direction));
      break;
    }
    const rc::scene::SurfaceInteraction si = scene_.surface(ray, *hit);
    rc::scene::Material textured;
    const rc::scene::Material& m = scene_.shading_material(si, textured);
    if (m.kind == rc::scene::MaterialKind::dielectric && !si.front_face && !m.absorption.is_black())
      beta *= rc::exp(m.absorption * (-hit->t * glm::length(ray.direction)));
    const rc::Vec3 wo_world = -glm::normalize(ray.direction);
    // Seen from the camera or through mirrors and glass: emission counts in full.
    if (m.is_emissive()) radiance += beta * rc::scene::emitted_radiance(m, si.ng, wo_world);
    if (!m.is_traced_through()) {
      radiance += beta * shade(si, wo_world, ctx);
      break;
    }
    const rc::Frame frame = rc::Frame::from_normal(si.ns);
    const rc::Vec3 wo = frame.to_local(wo_world);
    const std::optional<rc::scene::BsdfSample> bs = rc::scene::bsdf_sample(m, wo, ctx.sampler.uniform(), ctx.sampler.uniform2());
    if (!bs || !(bs->pdf > 0.0f) || bs->f.is_black()) break;
    const rc::Vec3 wi_world = frame.to_world(bs->wi);
    const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f, wi_above = glm::dot(wi_world, si.ng) > 0.0f;
    if (wi_above != (bs->transmission ? !wo_above : wo_above)) break;
    beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf);
    ray = rc::scene::continue_ray(si, wi_world);
  }
  return radiance;
}

rc::Rgb PhotonMapper::shade(const rc::scene::SurfaceInteraction& si, const rc::Vec3& wo_world, rc::render::SampleContext& ctx) const {
  rc::scene::Material textured;
  const rc::scene::Material& m = scene_.shading_material(si, textured);
  const rc::Frame frame = rc::Frame::from_normal(si.ns);
  const rc::Vec3 wo = frame.to_local(wo_world);
  const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f;
  const rc::Vec3 lit_side = wo_above ? si.ng : -si.ng;
  const EstimateQuery query{si.p, lit_side, size_t(settings_.k), max_radius2_};
  const auto& lights = scene_.lights();
  const rc::scene::LightQuery light_query =
      rc::render::light_query(si, m, wo_above);  // sample_direct_mis's, for MIS
  const int gather = settings_.gather_rays;
  rc::Rgb l(0.0f);

  // Caustics from their map.
  l += estimate_radiance(maps_.caustic, query, m, frame, wo, thread_scratch());

  // Direct light, MIS-weighted against the gather rays as BSDF samples.
  l +=
      rc::render::sample_direct_mis(scene_, si, m, frame, wo, wo_above, ctx.sampler, ctx.rays, float(gather));
  if (gather == 0) {
    // Without a final gather the global map is read at x itself.
    l += estimate_radiance(scene_, maps_.global, query, m, frame, wo, thread_scratch());
    return l;
  }

  // Final gather.
  rc::Rgb gathered(0.0f);
  const bool caustics_in_map = !maps_.caustic.empty();
  // The gather rays of each camera sample are sub-samples: stratified among themselves and with
  // the other samples' rays in the pixel.
  const rc::render::Sampler::SubSamples gather_samples = ctx.sampler.split(uint32_t(gather));
  for (int j = 0; j < gather; ++j) {
    rc::render::Sampler sampler = gather_samples[uint32_t(j)];
    const std::optional<rc::scene::BsdfSample> bs =
        rc::scene::bsdf_sample(m, wo, sampler.uniform(), sampler.uniform2());
    if (!bs || !(bs->pdf > 0.0f) || bs->f.is_black()) continue;
    const rc::Vec3 wi_world = frame.to_world(bs->wi);
    const bool wi_above = glm::dot(wi_world, si.ng) > 0.0f;
    if (wi_above != (bs->transmission ? !wo_above : wo_above)) continue;
    rc::Rgb g = bs->f * (std::fabs(bs->wi.z) / bs->pdf);
    rc::scene::Ray ray = rc::scene::continue_ray(si, wi_world);
    bool through_specular = false;
    for (int depth = 0; depth < settings_.max_depth; ++depth) {
      ++ctx.rays;
      const std::optional<rc::scene::Hit> hit = scene_.intersect(ray);
      const rc::Vec3 dir = glm::normalize(ray.direction);
      if (!hit) {
        for (const uint32_t li : scene_.environment_lights()) {
          float w = 1.0f;
          if (!through_specular && !bs->delta)
            w = rc::util::power_heuristic(float(gather), bs->pdf, 1.0f,
                                    rc::render::light_choice_pmf(scene_, light_query, li) *
                                        rc::scene::light_pdf(scene_, lights[li], si, dir, si, rc::scene::receiving_normal(light_query)));
          else if (through_specular && caustics_in_map)
            w = 0.0f;
          gathered += g * rc::scene::environment_radiance(lights[li], dir) * w;
        }
        break;
      }
      const rc::scene::SurfaceInteraction sj = scene_.surface(ray, *hit);
      rc::scene::Material textured_j;
      const rc::scene::Material& mj = scene_.shading_material(sj, textured_j);
      if (mj.kind == rc::scene::MaterialKind::dielectric && !sj.front_face && !mj.absorption.is_black())
        g *= rc::exp(mj.absorption * (-hit->t * glm::length(ray.direction)));
      if (mj.is_emissive()) {
        const rc::Rgb le = rc::scene::emitted_radiance(mj, sj.ng, -dir);
        if (!le.is_black()) {
          // Straight from x: the BSDF-sampled half of direct light. Through mirrors and glass:
          // a caustic, which the caustic map already holds (when there is one).
          float w = 1.0f;
          if (!through_specular && sj.light >= 0)
            w = rc::util::power_heuristic(float(gather), bs->pdf, 1.0f,
                                    rc::render::light_choice_pmf(scene_, light_query, uint32_t(sj.light)) * rc::scene::light_pdf(scene_, lights[sj.light], si, dir, sj));
          else if (through_specular && caustics_in_map)
            w = 0.0f;
          gathered += g * le * w;
        }
      }
      if (mj.is_traced_through()) {
        const rc::Frame fj = rc::Frame::from_normal(sj.ns);
        const rc::Vec3 woj = fj.to_local(-dir);
        const std::optional<rc::scene::BsdfSample> bj = rc::scene::bsdf_sample(mj, woj, sampler.uniform(), sampler.uniform2());
        if (!bj || !(bj->pdf > 0.0f) || bj->f.is_black()) break;
        g *= bj->f * (std::fabs(bj->wi.z) / bj->pdf);
        ray = rc::scene::continue_ray(sj, fj.to_world(bj->wi));
        through_specular = true;
        continue;
      }
      // A diffuse or glossy hit: its reflected light from the precomputed irradiance.
      const rc::Vec3 side = glm::dot(-dir, sj.ng) > 0.0f ? sj.ng : -sj.ng;
      gathered += g * rc::scene::diffuse_reflectance(mj) * irradiance(sj.p, side, sampler) * rc::kInvPi;
      break;
    }
  }
  l += gathered / float(gather);
  return l;
}

}  // namespace gilt::photonmap
