// The gathered ambient term (see ambient_gather.h): cosine-weighted rays from each shooting
// patch read the unshot radiosity of the elements they hit.

#include "radiosity/solver/ambient_gather.h"

#include <algorithm>

#include "radiosity/mesh/element_scene.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::solver {

namespace {

using rc::Rgb;
using rc::Vec3;

/// The element whose front a ray travelling along `w` sees at hit `h` of geometry 0, or none:
/// the element hit, from its front, or the twin lying on it when the hit was on its back.
std::optional<uint32_t> seen_element(const rc::scene::Scene& geometry, const mesh::RadiosityMesh& mesh,
                                     const rc::scene::Hit& h, const rc::scene::Ray& ray) {
  const uint32_t e = h.prim_id;
  if (glm::dot(ray.direction, mesh.element_normal[e]) < 0.0f) return e;
  if (!mesh.two_sided(e)) return std::nullopt;
  // The twin lies on e's plane with its own vertices: the nearest element facing the ray, within
  // a thousandth of e's size of the hit.
  const auto& el = mesh.elements[e];
  const float size = std::max({glm::distance(mesh.positions[el[0]], mesh.positions[el[1]]),
                               glm::distance(mesh.positions[el[1]], mesh.positions[el[2]]),
                               glm::distance(mesh.positions[el[2]], mesh.positions[el[0]])});
  const Vec3 p = ray.origin + h.t * ray.direction;
  const std::optional<rc::scene::Hit> twin =
      geometry.nearest_triangle(0, p, 1e-3f * size, -ray.direction, 0.0f);
  if (!twin || twin->prim_id == e) return std::nullopt;
  return twin->prim_id;
}

}  // namespace

AmbientGather gather_ambient(const rc::scene::Scene& geometry, const mesh::RadiosityMesh& mesh,
                             std::span<const uint32_t> patch_offsets,
                             std::span<const uint32_t> patch_elements, std::span<const Rgb> unshot,
                             std::span<const Rgb> albedo, int rays_per_patch, uint64_t seed) {
  AmbientGather out;
  if (rays_per_patch < 1) return out;
  const size_t ne = mesh.element_count(), patches = patch_offsets.empty() ? 0 : patch_offsets.size() - 1;
  std::vector<Rgb>& element_gathered = out.element_ambient;
  element_gathered.assign(ne, Rgb(0.0f));
  std::vector<float> patch_escaped(patches, 0.0f);
  rc::util::parallel_for(patches, [&](size_t q) {
    const std::span<const uint32_t> elements =
        patch_elements.subspan(patch_offsets[q], patch_offsets[q + 1] - patch_offsets[q]);
    double area = 0.0;
    for (uint32_t e : elements) area += mesh.element_area[e];
    if (!(area > 0.0)) return;
    rc::util::Rng rng = rc::util::Rng::for_item(seed, q, 0x616d6269656e74ull);  // "ambient"
    Rgb sum(0.0f);
    int escaped = 0;
    for (int i = 0; i < rays_per_patch; ++i) {
      // The element by area (stratified over the patch), a point on it, a cosine-weighted direction.
      double pick = (i + rng.uniform()) / rays_per_patch * area;
      uint32_t e = elements.back();
      for (uint32_t candidate : elements) {
        if (pick < mesh.element_area[candidate]) {
          e = candidate;
          break;
        }
        pick -= mesh.element_area[candidate];
      }
      const auto& el = mesh.elements[e];
      const rc::Vec2 b = rc::util::sample_uniform_triangle(rng.uniform2());
      const Vec3 x = (1.0f - b.x - b.y) * mesh.positions[el[0]] + b.x * mesh.positions[el[1]] +
                     b.y * mesh.positions[el[2]];
      const Vec3 n = mesh.element_normal[e];
      const Vec3 w = rc::Frame::from_normal(n).to_world(rc::util::sample_cosine_hemisphere(rng.uniform2()));
      const rc::scene::Ray ray = rc::scene::spawn_ray(mesh::mesh_surface_point(x, n), w);
      const std::optional<rc::scene::Hit> h = geometry.intersect(ray);
      if (!h) {
        ++escaped;
        continue;
      }
      if (h->geom_id != 0) continue;  // a mirror or glass: opaque to the solver
      // Irradiance from radiosity B seen in a cosine-weighted direction: ∫ (B/π) cos dω = E[B].
      if (const std::optional<uint32_t> seen = seen_element(geometry, mesh, *h, ray)) sum += unshot[*seen];
    }
    const Rgb gathered = sum * (1.0f / rays_per_patch);
    for (uint32_t e : elements) element_gathered[e] = gathered;
    patch_escaped[q] = float(escaped) / rays_per_patch;
  });
  out.rays = uint64_t(patches) * rays_per_patch;

  // The later bounces: Cohen's series over the reflectance of what the rays meet.
  double area = 0.0, escaped = 0.0;
  Rgb rho_sum(0.0f);
  for (size_t q = 0; q < patches; ++q)
    for (uint32_t e : patch_elements.subspan(patch_offsets[q], patch_offsets[q + 1] - patch_offsets[q])) {
      area += mesh.element_area[e];
      escaped += double(patch_escaped[q]) * mesh.element_area[e];
      rho_sum += albedo[e] * mesh.element_area[e];
    }
  if (!(area > 0.0)) return out;
  out.escaped = escaped / area;
  Rgb& series = out.series;
  for (int k = 0; k < 3; ++k)
    series[k] = 1.0f / std::max(1e-3f, 1.0f - float(rho_sum[k] / area) * float(1.0 - out.escaped));
  for (Rgb& g : element_gathered) g = g * series;

  // Per vertex: the area-weighted mean of its elements'.
  const size_t nv = mesh.vertex_count();
  out.vertex_ambient.assign(nv, Rgb(0.0f));
  std::vector<float> weight(nv, 0.0f);
  for (size_t e = 0; e < ne; ++e)
    for (uint32_t v : mesh.elements[e]) {
      out.vertex_ambient[v] += element_gathered[e] * mesh.element_area[e];
      weight[v] += mesh.element_area[e];
    }
  for (size_t v = 0; v < nv; ++v)
    if (weight[v] > 0.0f) out.vertex_ambient[v] = out.vertex_ambient[v] * (1.0f / weight[v]);
  return out;
}

}  // namespace gilt::radiosity::solver
