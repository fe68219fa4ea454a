#include "raytrace_core/render/direct_light.h"

#include <cmath>

#include "raytrace_core/scene/bsdf.h"

namespace gilt::raytrace_core::render {

namespace {

/// One sample of light `li`, chosen with probability `pmf`; `receiving` is receiving_normal() of the
/// point's light query, computed once by the caller for all its lights.
DirectSample sample_one(const scene::Scene& scene, uint32_t li, float pmf, const scene::SurfaceInteraction& si, const scene::Material& m,
                        const Frame& frame, const Vec3& wo, bool wo_above, const Vec3& receiving, Sampler& sampler,
                        uint64_t& rays) {
  DirectSample out;
  const scene::LightSample ls =
      scene::sample_light(scene, scene.lights()[li], si, sampler.uniform2(), receiving);
  // The light must be on wo's side of the geometric surface (no leaks), unless the surface
  // transmits into a lobe (a rough dielectric): then light from behind it counts too.
  if (!(ls.pdf > 0.0f) || ls.radiance.is_black()) return out;
  if ((glm::dot(ls.wi, si.ng) > 0.0f) != wo_above && !m.is_rough_dielectric()) return out;
  out.wi = frame.to_local(ls.wi);
  out.pdf = ls.pdf * pmf;
  out.delta = ls.delta;
  const Rgb f = scene::bsdf_eval(m, wo, out.wi) * std::fabs(out.wi.z);
  if (f.is_black()) return out;
  ++rays;
  if (scene.occluded(ls.shadow_ray)) return out;
  out.value = f * ls.radiance / out.pdf;
  return out;
}

}  // namespace

scene::LightQuery light_query(const scene::SurfaceInteraction& si, const scene::Material& m, bool wo_above) {
  return {si.p, wo_above ? si.ng : -si.ng, m.is_rough_dielectric()};
}

DirectSample sample_direct(const scene::Scene& scene, const scene::SurfaceInteraction& si, const scene::Material& m, const Frame& frame,
                           const Vec3& wo, bool wo_above, Sampler& sampler, uint64_t& rays) {
  const scene::LightSampler& lights = scene.light_sampler();
  if (lights.size() == 0) return {};
  const scene::LightQuery query = light_query(si, m, wo_above);
  const scene::LightChoice choice = lights.sample(query, sampler.uniform());
  if (!(choice.pmf > 0.0f)) {
    sampler.uniform2();  // keep the dimensions of the next requests where they would be
    return {};
  }
  return sample_one(scene, choice.light, choice.pmf, si, m, frame, wo, wo_above, scene::receiving_normal(query), sampler,
                    rays);
}

Rgb estimate_direct(const scene::Scene& scene, const scene::SurfaceInteraction& si, const scene::Material& m,
                    const Frame& frame, const Vec3& wo, bool wo_above, Sampler& sampler, uint64_t& rays,
                    bool constant_sky) {
  const size_t count = scene.lights().size();
  if (count > kEachLightLimit) return sample_direct(scene, si, m, frame, wo, wo_above, sampler, rays).value;
  const Vec3 receiving = scene::receiving_normal(light_query(si, m, wo_above));
  Rgb sum(0.0f);
  for (uint32_t li = 0; li < count; ++li) {
    const scene::Light& light = scene.lights()[li];
    if (!constant_sky && scene::is_constant_environment(light)) {
      sampler.uniform2();  // keep the dimensions of the next requests where they would be
      continue;
    }
    sum += sample_one(scene, li, 1.0f, si, m, frame, wo, wo_above, receiving, sampler, rays).value;
  }
  return sum;
}

bool samples_each_light(const scene::Scene& scene) {
  return scene.lights().size() <= kEachLightLimit && scene.lights().size() == scene.punctual_lights.size();
}

float light_choice_pmf(const scene::Scene& scene, const scene::LightQuery& query, uint32_t light) {
  return samples_each_light(scene) ? 1.0f : scene.light_sampler().pmf(query, light);
}

Rgb sample_direct_mis(const scene::Scene& scene, const scene::SurfaceInteraction& si,
                      const scene::Material& m, const Frame& frame, const Vec3& wo, bool wo_above,
                      Sampler& sampler, uint64_t& rays, float bsdf_samples) {
  const auto weighted = [&](const DirectSample& ds) {
    if (ds.value.is_black() || ds.delta || bsdf_samples == 0.0f) return ds.value;
    return ds.value * util::power_heuristic(1.0f, ds.pdf, bsdf_samples, scene::bsdf_pdf(m, wo, ds.wi));
  };
  if (!samples_each_light(scene)) return weighted(sample_direct(scene, si, m, frame, wo, wo_above, sampler, rays));
  const Vec3 receiving = scene::receiving_normal(light_query(si, m, wo_above));
  Rgb sum(0.0f);
  for (uint32_t li = 0; li < scene.lights().size(); ++li)
    sum += weighted(sample_one(scene, li, 1.0f, si, m, frame, wo, wo_above, receiving, sampler, rays));
  return sum;
}

bool sky_left_to_bsdf_sampling(const scene::Scene& scene) {
  if (scene.lights().size() > kEachLightLimit) return false;
  for (const scene::Light& light : scene.lights())
    if (scene::is_constant_environment(light)) return true;
  return false;
}

}  // namespace gilt::raytrace_core::render
