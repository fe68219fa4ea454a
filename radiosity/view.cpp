// Two-pass display of a radiosity solution (Wallace, Cohen & Greenberg 1987): diffuse radiance
// from the solution, specular transport by ray tracing.

#include "radiosity/view.h"

#include "radiosity/element_scene.h"
#include "raytrace_core/bsdf.h"

namespace gilt::radiosity {

RadiosityView::RadiosityView(const rc::Scene& scene, const Solution& solution, bool ambient)
    : scene_(scene), elements_(solution.mesh.elements) {
  const RadiosityMesh& mesh = solution.mesh;
  vertex_radiance_.resize(mesh.vertex_count());
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    vertex_radiance_[v] = solution.vertex_radiance(v);
    if (ambient)
      vertex_radiance_[v] += scene.materials[mesh.vertex_material[v]].albedo * solution.ambient * (1.0f / rc::kPi);
  }

  // Geometry 0: every element; then the scene's specular meshes and spheres.
  display_ = element_scene(scene, mesh);
  for (const rc::Light& l : scene.punctual_lights)
    if (l.kind == rc::LightKind::environment) environment_ += l.radiance;
}

Rgb RadiosityView::radiance(const rc::Ray& camera_ray, rc::SampleContext& ctx) const {
  Rgb beta(1.0f);
  rc::Ray ray = camera_ray;
  for (int depth = 0; depth < 64; ++depth) {
    ++ctx.rays;
    const std::optional<rc::Hit> hit = display_.intersect(ray);
    if (!hit) return beta * environment_;
    const rc::SurfaceInteraction si = display_.surface(ray, *hit);
    if (hit->geom_id == 0) {
      // Radiosity is solved for the element fronts; their backs are not part of the answer.
      if (!si.front_face) return Rgb(0.0f);
      const auto& e = elements_[hit->prim_id];
      const Rgb l = vertex_radiance_[e[0]] * (1.0f - hit->u - hit->v) + vertex_radiance_[e[1]] * hit->u +
                    vertex_radiance_[e[2]] * hit->v;
      return beta * l;
    }
    const rc::Material& m = display_.materials[si.material];
    if (m.kind == rc::MaterialKind::dielectric && !si.front_face && !m.absorption.is_black())
      beta *= rc::exp(m.absorption * (-hit->t * glm::length(ray.direction)));
    const rc::Frame frame = rc::Frame::from_normal(si.ns);
    const rc::Vec3 wo = frame.to_local(-glm::normalize(ray.direction));
    const float u_lobe = ctx.rng.uniform();
    const auto bs = rc::bsdf_sample(m, wo, u_lobe, ctx.rng.uniform2());
    if (!bs || !(bs->pdf > 0.0f)) return Rgb(0.0f);
    beta *= bs->f * (std::fabs(bs->wi.z) / bs->pdf);
    ray = rc::spawn_ray(si, frame.to_world(bs->wi));
  }
  return Rgb(0.0f);
}

}  // namespace gilt::radiosity
