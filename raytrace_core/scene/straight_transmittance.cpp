#include "raytrace_core/scene/straight_transmittance.h"

#include <algorithm>
#include <cmath>

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::scene {

namespace {

/// Surfaces a ray is followed through before it counts as blocked (a pane is two).
constexpr int kMaxCrossings = 16;

bool crossed(const Material& m) { return m.kind == MaterialKind::dielectric && m.is_specular(); }

}  // namespace

Rgb straight_transmittance(const Scene& scene, Ray ray) {
  // Most rays meet no glass: an occlusion query settles them, and a scene without glass needs
  // no more.
  if (!scene.occluded(ray)) return Rgb(1.0f);
  if (std::none_of(scene.materials.begin(), scene.materials.end(), crossed)) return Rgb(0.0f);
  Rgb carried(1.0f);
  for (int crossing = 0; crossing <= kMaxCrossings; ++crossing) {
    const std::optional<Hit> hit = scene.intersect(ray);
    if (!hit) return carried;
    const SurfaceInteraction si = scene.surface(ray, *hit);
    const Material& m = scene.materials[si.material];
    if (!crossed(m) || crossing == kMaxCrossings) return Rgb(0.0f);
    const float length = glm::length(ray.direction);
    // Leaving the glass: what it absorbed between the two crossings.
    if (!si.front_face && !m.absorption.is_black()) carried *= util::exp(m.absorption * (-hit->t * length));
    // Fresnel from outside at the outside angle: on a pane's far side the light meets the
    // surface at the refracted angle from inside, whose reflectance is the same.
    carried *= 1.0f - fresnel_dielectric(std::fabs(glm::dot(ray.direction, si.ng)) / length, m.ior);
    const float left = ray.tmax - hit->t;
    ray = spawn_ray(si, ray.direction);
    ray.tmax = left;
  }
  return Rgb(0.0f);
}

}  // namespace gilt::raytrace_core::scene
