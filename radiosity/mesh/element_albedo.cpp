#include "radiosity/mesh/element_albedo.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::mesh {

namespace {

/// Barycentrics (of the second and third corner) of x projected into the plane of triangle
/// `prim` of `mesh` (x may lie outside the triangle: the map is affine); none for a triangle of
/// no area.
std::optional<rc::Vec2> barycentrics(const rc::scene::TriangleMesh& mesh, uint32_t prim, const Vec3& x) {
  const uint32_t* c = &mesh.indices[3 * size_t(prim)];
  const Vec3 p0 = mesh.positions[c[0]], e1 = mesh.positions[c[1]] - p0, e2 = mesh.positions[c[2]] - p0;
  const Vec3 d = x - p0;
  const float a11 = glm::dot(e1, e1), a12 = glm::dot(e1, e2), a22 = glm::dot(e2, e2);
  const float det = a11 * a22 - a12 * a12;
  if (!(det > 0.0f)) return std::nullopt;
  return rc::Vec2((a22 * glm::dot(d, e1) - a12 * glm::dot(d, e2)) / det,
                  (a11 * glm::dot(d, e2) - a12 * glm::dot(d, e1)) / det);
}

/// Texture coordinates at the point of triangle `prim` of `mesh` with x's barycentrics.
rc::Vec2 uv_at(const rc::scene::TriangleMesh& mesh, uint32_t prim, const Vec3& x) {
  if (mesh.uvs.empty()) return rc::Vec2(0.0f);
  const uint32_t* c = &mesh.indices[3 * size_t(prim)];
  const std::optional<rc::Vec2> b = barycentrics(mesh, prim, x);
  if (!b) return mesh.uvs[c[0]];
  return (1.0f - b->x - b->y) * mesh.uvs[c[0]] + b->x * mesh.uvs[c[1]] + b->y * mesh.uvs[c[2]];
}

/// Whether x lies on triangle `prim` of `mesh`: its projection inside the triangle (with a
/// margin of 1e-4 of the edges) and x within `slack` of its plane.
bool lies_on(const rc::scene::TriangleMesh& mesh, uint32_t prim, const Vec3& x, float slack) {
  const uint32_t* c = &mesh.indices[3 * size_t(prim)];
  const Vec3 p0 = mesh.positions[c[0]];
  const Vec3 n = glm::cross(mesh.positions[c[1]] - p0, mesh.positions[c[2]] - p0);
  const float n_len = glm::length(n);
  if (!(n_len > 0.0f) || std::abs(glm::dot(x - p0, n)) > slack * n_len) return false;
  const std::optional<rc::Vec2> b = barycentrics(mesh, prim, x);
  constexpr float kMargin = 1e-4f;
  return b && b->x >= -kMargin && b->y >= -kMargin && b->x + b->y <= 1.0f + kMargin;
}

}  // namespace

std::vector<rc::Rgb> element_reflectance(const rc::scene::Scene& scene, const RadiosityMesh& mesh) {
  const size_t ne = mesh.element_count();
  std::vector<rc::Rgb> out(ne);
  const rc::scene::TextureSet* textures = scene.texture_set();
  rc::util::parallel_for((ne + 255) / 256, [&](size_t chunk) {
    for (size_t e = chunk * 256; e < std::min(ne, chunk * 256 + 256); ++e) {
      const rc::scene::Material& m = scene.materials[mesh.element_material[e]];
      const uint32_t s = mesh.element_surface[e];
      if (!m.albedo_texture.valid() || !textures || s >= scene.meshes.size()) {
        out[e] = rc::scene::diffuse_reflectance(m);  // untextured, or a sphere (whose texture has no seam-free UVs here)
        continue;
      }
      const rc::scene::TriangleMesh& input = scene.meshes[s];
      const rc::scene::TextureRef& t = m.albedo_texture;
      const auto& el = mesh.elements[e];
      const Vec3 p0 = mesh.positions[el[0]], p1 = mesh.positions[el[1]], p2 = mesh.positions[el[2]];
      const float reach = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
      constexpr int kSide = 4;
      const Vec3 step1 = (p1 - p0) * (1.0f / kSide), step2 = (p2 - p0) * (1.0f / kSide);
      // Most samples lie on the input triangle the one before found (an element is seldom cut
      // by an input edge): it is kept while they lie on it, to within 1e-5 of the element's size
      // off its plane (plus the rounding of coordinates this far from the origin), and the search
      // runs only when one does not.
      const float on_plane =
          1e-5f * reach + 1e-6f * std::max({std::abs(p0.x), std::abs(p0.y), std::abs(p0.z)});
      uint32_t last = ~0u;
      rc::Rgb sum(0.0f);
      int found = 0;
      for (int i = 0; i < kSide; ++i)
        for (int j = 0; j < kSide; ++j) {
          const rc::Vec2 w = rc::util::sample_uniform_triangle({(i + 0.5f) / kSide, (j + 0.5f) / kSide});
          const Vec3 x = (1.0f - w.x - w.y) * p0 + w.x * p1 + w.y * p2;
          if (last == ~0u || !lies_on(input, last, x, on_plane)) {
            // An element turned over, or the twin of one, faces against its input face: the
            // nearer of the faces facing either way, not the nearest facing the element's way
            // (on a turned sheet that was another surface a tenth of the element away).
            std::optional<rc::scene::Hit> h =
                scene.nearest_triangle(s, x, reach, mesh.element_normal[e], 0.5f);
            const std::optional<rc::scene::Hit> back =
                scene.nearest_triangle(s, x, reach, -mesh.element_normal[e], 0.5f);
            if (back && (!h || back->t < h->t)) h = back;
            if (!h) continue;
            last = h->prim_id;
          }
          // The footprint: this point's share of the element, as the found triangle maps it.
          const rc::Vec2 uv = uv_at(input, last, x);
          const rc::Vec2 dx = uv_at(input, last, x + step1) - uv, dy = uv_at(input, last, x + step2) - uv;
          sum += textures->lookup(t.image, t.st(uv), t.st_delta(dx), t.st_delta(dy)).rgb;
          ++found;
        }
      if (found > 0) {
        out[e] = rc::scene::diffuse_reflectance(m) * sum * (1.0f / float(found));
      } else {
        // No input face near (should not happen): the image's mean, from its coarsest level.
        out[e] = rc::scene::diffuse_reflectance(m) * textures->lookup(t.image, rc::Vec2(0.5f), rc::Vec2(1.0f, 0.0f), rc::Vec2(0.0f, 1.0f)).rgb;
      }
    }
  });
  return out;
}

}  // namespace gilt::radiosity::mesh
