// Whitted-style ray tracing (Whitted 1980, "An Improved Illumination Model for Shaded Display"):
// direct light through shadow rays, recursive mirror reflection and Fresnel-weighted refraction.
// Diffuse and glossy surfaces see only direct light; there is no indirect diffuse term.

#include "raytrace_core/render/whitted.h"

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/render/direct_light.h"

namespace gilt::raytrace_core::render {
namespace {

Rgb trace(const scene::Scene& scene, const scene::Ray& ray, SampleContext& ctx, const WhittedSettings& settings, int depth) {
  ctx.sampler.start_bounce(depth);
  ++ctx.rays;
  const std::optional<scene::Hit> hit = scene.intersect(ray);
  if (!hit) return scene::escaped_radiance(scene.punctual_lights, glm::normalize(ray.direction));
  const scene::SurfaceInteraction si = scene.surface(ray, *hit);
  scene::Material textured;
  const scene::Material& m = scene.shading_material(si, textured);
  const Vec3 wo_world = -glm::normalize(ray.direction);
  Rgb radiance = m.is_emissive() ? scene::emitted_radiance(m, si.ng, wo_world) : Rgb(0.0f);
  const Frame frame = Frame::from_normal(si.ns);
  const Vec3 wo = frame.to_local(wo_world);
  const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f;

  if (!m.is_traced_through()) {
    // Local shading: the material's diffuse + Phong BSDF lit by shadow rays, each towards a light
    // chosen by the scene's light sampler (the path tracer's next-event estimate, unweighted).
    const int n = std::max(1, settings.area_light_samples);
    for (int i = 0; i < n; ++i)
      radiance += sample_direct(scene, si, m, frame, wo, wo_above, ctx.sampler, ctx.rays).value / float(n);
    return radiance;
  }
  if (depth + 1 >= settings.max_depth) return radiance;

  auto follow = [&](const Vec3& wi_local, const Rgb& weight) {
    const Vec3 wi_world = frame.to_world(wi_local);
    Rgb l = trace(scene, scene::continue_ray(si, wi_world), ctx, settings, depth + 1);
    return weight * l;
  };
  if (m.kind == scene::MaterialKind::mirror) {
    const Vec3 wi(-wo.x, -wo.y, wo.z);
    return radiance + follow(wi, m.specular);
  }
  // Dielectric: both branches, weighted by Fresnel, as in Whitted's original.
  Rgb absorb(1.0f);
  if (!si.front_face && !m.absorption.is_black()) absorb = exp(m.absorption * (-hit->t * glm::length(ray.direction)));
  const float eta = m.ior;
  const float cos_o = wo.z;
  const float fr = scene::fresnel_dielectric(cos_o, eta);
  const Vec3 wr(-wo.x, -wo.y, wo.z);
  radiance += follow(wr, Rgb(fr));
  if (fr < 1.0f) {
    const float e = cos_o > 0.0f ? eta : 1.0f / eta;  // IOR ratio of the side entered over the side left
    const float sin2_t = (1.0f - cos_o * cos_o) / (e * e);
    const float cos_t = std::sqrt(std::max(0.0f, 1.0f - sin2_t)) * (cos_o > 0.0f ? -1.0f : 1.0f);
    const Vec3 wt = glm::normalize(Vec3(-wo.x / e, -wo.y / e, cos_t));
    radiance += follow(wt, Rgb((1.0f - fr) / (e * e)));
  }
  return radiance * absorb;
}

}  // namespace

Rgb whitted_radiance(const scene::Scene& scene, const scene::Ray& ray, SampleContext& ctx, const WhittedSettings& settings) {
  return trace(scene, ray, ctx, settings, 0);
}

}  // namespace gilt::raytrace_core::render
