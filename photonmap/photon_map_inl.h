#pragma once
// Template body of trace_photon_path (included from photon_map.h).

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "raytrace_core/scene/bsdf.h"

namespace gilt::photonmap {

template <class Store>
uint64_t trace_photon_path(const rc::scene::Scene& scene, rc::scene::Ray ray, rc::Rgb power,
                           rc::util::Rng& rng, int max_depth, Store&& store) {
  uint64_t rays = 0;
  bool specular_only = true;
  for (int depth = 0; depth < max_depth; ++depth) {
    ++rays;
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    if (!hit) break;
    const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
    rc::scene::Material textured;
    const rc::scene::Material& m = scene.shading_material(si, textured);
    if (m.kind == rc::scene::MaterialKind::dielectric && !si.front_face && !m.absorption.is_black())
      power *= rc::exp(m.absorption * (-hit->t * glm::length(ray.direction)));
    const rc::Vec3 wo_world = -glm::normalize(ray.direction);
    if (!m.is_traced_through()) {
      Photon p;
      p.position = si.p;
      p.power = power;
      p.direction = encode_direction(wo_world);
      p.normal = encode_direction(glm::dot(si.ng, wo_world) >= 0.0f ? si.ng : -si.ng);
      bool go_on;
      if constexpr (std::is_invocable_v<Store, const Photon&, int, bool, const rc::scene::Hit&>)
        go_on = store(p, depth, specular_only, *hit);
      else
        go_on = store(p, depth, specular_only);
      if (!go_on) break;
    }
    const rc::Frame frame = rc::Frame::from_normal(si.ns);
    const rc::Vec3 wo = frame.to_local(wo_world);
    const std::optional<rc::scene::BsdfSample> bs =
        rc::scene::bsdf_sample(m, wo, rng.uniform(), rng.uniform2(), rc::scene::TransportMode::importance);
    if (!bs || !(bs->pdf > 0.0f) || bs->f.is_black()) break;
    const rc::Vec3 wi_world = frame.to_world(bs->wi);
    // The sampled direction must leave on the side the BSDF meant (shading normals can disagree).
    const bool wo_above = glm::dot(wo_world, si.ng) > 0.0f, wi_above = glm::dot(wi_world, si.ng) > 0.0f;
    if (wi_above != (bs->transmission ? !wo_above : wo_above)) break;
    // Importance transport with shading normals: |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|), with wo
    // towards where the photon came from (Veach 1997, section 5.3).
    float correction = 1.0f;
    if (!bs->delta) {
      const float denom = std::fabs(glm::dot(wo_world, si.ng)) * std::fabs(bs->wi.z);
      correction = denom > 0.0f ? std::fabs(wo.z) * std::fabs(glm::dot(wi_world, si.ng)) / denom : 0.0f;
    }
    const rc::Rgb scaled = power * bs->f * (std::fabs(bs->wi.z) / bs->pdf * correction);
    if (!m.is_traced_through()) specular_only = false;
    // Russian roulette: survive with the ratio of new to old power (the bounce's albedo), so the
    // survivors carry about the same power as before.
    const float survive = std::min(1.0f, scaled.max_component() / std::max(power.max_component(), 1e-30f));
    if (!(survive > 0.0f) || rng.uniform() >= survive) break;
    power = scaled / survive;
    ray = rc::scene::spawn_ray(si, wi_world);
  }
  return rays;
}

}  // namespace gilt::photonmap
