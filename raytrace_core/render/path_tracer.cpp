// Unidirectional path tracing with next-event estimation and MIS (Veach & Guibas 1995, power
// heuristic), Russian roulette (Arvo & Kirk 1990), Beer–Lambert absorption inside dielectrics.

#include "raytrace_core/render/path_tracer.h"

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/render/direct_light.h"

namespace gilt::raytrace_core::render {

Rgb path_radiance(const scene::Scene& scene, const scene::Ray& camera_ray, SampleContext& ctx, const PathSettings& settings) {
  const auto& lights = scene.lights();
  Rgb radiance(0.0f), beta(1.0f);
  scene::Ray ray = camera_ray;
  bool specular_bounce = true;  // the camera counts as a delta event: emission seen directly is not weighted
  float bsdf_pdf_prev = 0.0f;
  scene::SurfacePoint prev;
  scene::LightQuery prev_query;  // what light sampling at prev chose lights for

  for (int depth = 0;; ++depth) {
    ctx.sampler.start_bounce(depth);
    ++ctx.rays;
    const std::optional<scene::Hit> hit = scene.intersect(ray);
    const Vec3 wo_world = -glm::normalize(ray.direction);
    if (!hit) {
      // Escaped: environment lights, MIS-weighted against light sampling.
      for (const uint32_t li : scene.environment_lights()) {
        float weight = 1.0f;
        if (!specular_bounce) {
          const float light_pdf_v = light_choice_pmf(scene, prev_query, li) *
                                    scene::light_pdf(scene, lights[li], prev, -wo_world, prev, scene::receiving_normal(prev_query));
          weight = util::power_heuristic(1.0f, bsdf_pdf_prev, 1.0f, light_pdf_v);
        }
        radiance += beta * scene::environment_radiance(lights[li], -wo_world) * weight;
      }
      // The sun's disk, where light sampling could not stand for it (the camera, a mirror, glass).
      if (specular_bounce) radiance += beta * scene::sun_disk_radiance(scene.punctual_lights, -wo_world);
      break;
    }
    const scene::SurfaceInteraction si = scene.surface(ray, *hit);
    scene::Material textured;
    const scene::Material& m = depth == 0 && settings.first_surface ? *settings.first_surface : scene.shading_material(si, textured);

    // Leaving the inside of a dielectric: attenuate by its absorption over the segment.
    if (m.kind == scene::MaterialKind::dielectric && !si.front_face && !m.absorption.is_black())
      beta *= exp(m.absorption * (-hit->t * glm::length(ray.direction)));

    if (m.is_emissive()) {
      const Rgb le = scene::emitted_radiance(m, si.ng, wo_world);
      if (!le.is_black()) {
        float weight = 1.0f;
        if (!specular_bounce && si.light >= 0) {
          const float light_pdf_v =
              light_choice_pmf(scene, prev_query, uint32_t(si.light)) * scene::light_pdf(scene, lights[si.light], prev, -wo_world, si);
          weight = util::power_heuristic(1.0f, bsdf_pdf_prev, 1.0f, light_pdf_v);
        }
        radiance += beta * le * weight;
      }
    }
    if (depth + 1 >= settings.max_depth) break;

    const Frame frame = Frame::from_normal(si.ns);
    const Vec3 wo = frame.to_local(wo_world);
    const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f;

    // Next-event estimation, MIS-weighted against BSDF sampling.
    if (!m.is_specular()) radiance += beta * sample_direct_mis(scene, si, m, frame, wo, wo_above, ctx.sampler, ctx.rays);

    // Continue the path by sampling the BSDF.
    const float u_lobe = ctx.sampler.uniform();
    const std::optional<scene::BsdfSample> bs = scene::bsdf_sample(m, wo, u_lobe, ctx.sampler.uniform2());
    if (!bs || !(bs->pdf > 0.0f) || bs->f.is_black()) break;
    const Vec3 wi_world = frame.to_world(bs->wi);
    // A shading normal may send a reflected ray through the geometric surface: end such paths.
    const bool wi_above = glm::dot(wi_world, si.ng) > 0.0f;
    if (wi_above != (bs->transmission ? !wo_above : wo_above)) break;
    beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf);
    specular_bounce = bs->delta;
    bsdf_pdf_prev = bs->pdf;
    prev = si;
    prev_query = light_query(si, m, wo_above);
    ray = scene::continue_ray(si, wi_world);

    // Russian roulette on the throughput.
    if (depth + 1 >= settings.rr_depth) {
      const float survive = std::min(1.0f, beta.max_component());
      if (survive <= 0.0f || ctx.sampler.uniform() >= survive) break;
      beta /= survive;
    }
  }
  return radiance;
}

}  // namespace gilt::raytrace_core::render
