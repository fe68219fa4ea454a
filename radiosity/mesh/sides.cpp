#include "radiosity/mesh/sides.h"

#include <algorithm>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::radiosity::mesh {
namespace {

/// Mirrors and glass met on the way are passed through, at most this many times: light comes
/// through a window as well as an opening.
constexpr int kPassThrough = 8;

/// Light arriving this close to a side's plane (cos θ) is taken as none.
constexpr float kGrazing = 1e-3f;

/// An element whose back lies on another element facing the other way (a wall modelled as two
/// sheets back to back, often two objects) has that element for its back: within this fraction
/// of the scene's size of its centroid, facing within about 2.5° of the opposite way.
constexpr float kCoverDistance = 1e-5f;
constexpr float kCoverCosine = 0.999f;

/// For each element, the element that covers its back (as above), or ~0u.
std::vector<uint32_t> covering_elements(const rc::scene::Scene& geometry, const RadiosityMesh& mesh,
                                        float size) {
  std::vector<uint32_t> cover(mesh.element_count(), ~0u);
  rc::util::parallel_for(mesh.element_count(), [&](size_t e) {
    const auto& el = mesh.elements[e];
    const Vec3 centroid = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
    const std::optional<rc::scene::Hit> near =
        geometry.nearest_triangle(0, centroid, kCoverDistance * size, -mesh.element_normal[e], kCoverCosine);
    if (near) cover[e] = near->prim_id;
  });
  return cover;
}

/// Union–find over vertices: the elements that share a vertex are one piece.
std::vector<uint32_t> vertex_pieces(const RadiosityMesh& mesh, size_t* count) {
  std::vector<uint32_t> parent(mesh.vertex_count());
  std::iota(parent.begin(), parent.end(), 0u);
  const auto find = [&](uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& e : mesh.elements)
    for (int i = 1; i < 3; ++i) {
      const uint32_t a = find(e[0]), b = find(e[i]);
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  // Pieces numbered in the order of their first vertex: the same for any thread count.
  std::vector<uint32_t> piece(mesh.vertex_count());
  std::vector<uint32_t> id(mesh.vertex_count(), ~0u);
  size_t n = 0;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const uint32_t r = find(v);
    if (id[r] == ~0u) id[r] = uint32_t(n++);
    piece[v] = id[r];
  }
  *count = n;
  return piece;
}

/// The first element a ray meets, passing through mirrors and glass; nothing if it leaves the
/// scene (or ends at its tmax). The ray may be moved along.
std::optional<rc::scene::Hit> first_element(const rc::scene::Scene& geometry, rc::scene::Ray& ray) {
  for (int pass = 0; pass <= kPassThrough; ++pass) {
    const std::optional<rc::scene::Hit> hit = geometry.intersect(ray);
    if (!hit || hit->geom_id == 0) return hit;
    const rc::scene::SurfaceInteraction si = geometry.surface(ray, *hit);
    const float left = ray.tmax - hit->t;
    ray = rc::scene::spawn_ray(si, ray.direction);
    ray.tmax = left;
  }
  return std::nullopt;
}

/// A side of a piece: 2 × piece + (0 front, 1 back).
using Node = uint32_t;

/// What one chunk of elements' rays found.
struct ChunkFindings {
  std::vector<std::pair<Node, Node>> edges;  ///< a ray from the first side met the second
  std::vector<Node> lit;                     ///< sides that a light reaches directly
  size_t rays = 0;
};

class SideTracer {
 public:
  SideTracer(const rc::scene::Scene& scene, const rc::scene::Scene& geometry, const RadiosityMesh& mesh,
             const std::vector<uint32_t>& element_piece, const std::vector<uint32_t>& rays_per_side,
             const std::vector<uint32_t>& cover)
      : scene_(scene),
        geometry_(geometry),
        mesh_(mesh),
        piece_(element_piece),
        rays_(rays_per_side),
        cover_(cover) {}

  void trace(uint32_t e, ChunkFindings& out) const {
    const auto& el = mesh_.elements[e];
    const Vec3 a = mesh_.positions[el[0]], b = mesh_.positions[el[1]], c = mesh_.positions[el[2]];
    for (int side = 0; side < 2; ++side) {
      // A covered back is the covering element's front, which sends its own rays.
      if (side == 1 && cover_[e] != ~0u) continue;
      const Node from = 2 * piece_[e] + Node(side);
      const Vec3 n = side == 0 ? mesh_.element_normal[e] : -mesh_.element_normal[e];
      const rc::Frame frame = rc::Frame::from_normal(n);
      for (uint32_t i = 0; i < rays_[e]; ++i) {
        rc::util::Rng rng = rc::util::Rng::for_item(0x51de5u, e, 2 * uint64_t(i) + uint64_t(side));
        const rc::Vec2 w = rc::util::sample_uniform_triangle(rng.uniform2());
        const rc::scene::SurfacePoint sp = mesh_surface_point((1.0f - w.x - w.y) * a + w.x * b + w.y * c, n);
        if (reaches_a_light(sp, n, rng, out)) out.lit.push_back(from);
        rc::scene::Ray ray =
            rc::scene::spawn_ray(sp, frame.to_world(rc::util::sample_cosine_hemisphere(rng.uniform2())));
        ++out.rays;
        const std::optional<rc::scene::Hit> hit = first_element(geometry_, ray);
        if (!hit) {
          if (!rc::scene::escaped_radiance(scene_.punctual_lights, glm::normalize(ray.direction)).is_black())
            out.lit.push_back(from);
          continue;
        }
        uint32_t met = hit->prim_id;
        bool front = glm::dot(ray.direction, mesh_.element_normal[met]) < 0.0f;
        // Of two elements back to back, the ray may meet either: the side it meets is the front
        // of the one facing it.
        if (!front && cover_[met] != ~0u) met = cover_[met], front = true;
        if (emits_towards(met, -ray.direction)) {
          out.lit.push_back(from);
          continue;
        }
        out.edges.emplace_back(from, 2 * piece_[met] + (front ? 0 : 1));
      }
    }
  }

 private:
  bool emits_towards(uint32_t element, const Vec3& w) const {
    const rc::scene::Material& m = scene_.materials[mesh_.element_material[element]];
    return m.is_emissive() &&
           !rc::scene::emitted_radiance(m, mesh_.element_normal[element], glm::normalize(w)).is_black();
  }

  /// One shadow ray to a light drawn at random: whether it arrives on this side unblocked.
  bool reaches_a_light(const rc::scene::SurfacePoint& sp, const Vec3& n, rc::util::Rng& rng,
                       ChunkFindings& out) const {
    const std::vector<rc::scene::Light>& lights = scene_.lights();
    if (lights.empty()) return false;
    const rc::scene::Light& light = lights[rng.next_u32() % lights.size()];
    const rc::scene::LightSample ls = rc::scene::sample_light(scene_, light, sp, rng.uniform2(), n);
    // A light in the side's own plane (an emitting face of the same surface) lies along it up to
    // rounding, and gives it nothing.
    if (ls.radiance.is_black() || !(glm::dot(ls.wi, n) > kGrazing)) return false;
    rc::scene::Ray ray = ls.shadow_ray;
    ++out.rays;
    const std::optional<rc::scene::Hit> hit = first_element(geometry_, ray);
    // An emitting element in the way is the light itself (a chord of a curved emitter) or another.
    return !hit || emits_towards(hit->prim_id, -ray.direction);
  }

  const rc::scene::Scene& scene_;
  const rc::scene::Scene& geometry_;
  const RadiosityMesh& mesh_;
  const std::vector<uint32_t>& piece_;
  const std::vector<uint32_t>& rays_;
  const std::vector<uint32_t>& cover_;
};

/// Which sides light reaches: those a light reaches directly, and those whose rays meet a side it
/// reaches, found backwards from the first.
std::vector<char> lit_sides(size_t nodes, std::vector<ChunkFindings>& chunks) {
  std::vector<uint32_t> offsets(nodes + 1, 0);
  for (const ChunkFindings& c : chunks)
    for (const auto& [from, to] : c.edges) ++offsets[to + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  std::vector<Node> towards(offsets.back());
  std::vector<uint32_t> next(offsets.begin(), offsets.end() - 1);
  for (const ChunkFindings& c : chunks)
    for (const auto& [from, to] : c.edges) towards[next[to]++] = from;
  std::vector<char> lit(nodes, 0);
  std::vector<Node> queue;
  for (const ChunkFindings& c : chunks)
    for (Node n : c.lit)
      if (!lit[n]) {
        lit[n] = 1;
        queue.push_back(n);
      }
  while (!queue.empty()) {
    const Node n = queue.back();
    queue.pop_back();
    for (uint32_t k = offsets[n]; k < offsets[n + 1]; ++k)
      if (!lit[towards[k]]) {
        lit[towards[k]] = 1;
        queue.push_back(towards[k]);
      }
  }
  return lit;
}

void turn_over(RadiosityMesh& mesh, const std::vector<uint32_t>& vertex_piece, const std::vector<char>& turn,
               size_t* turned) {
  for (size_t v = 0; v < mesh.vertex_count(); ++v)
    if (turn[vertex_piece[v]]) mesh.normals[v] = -mesh.normals[v];
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    if (!turn[vertex_piece[mesh.elements[e][0]]]) continue;
    std::swap(mesh.elements[e][1], mesh.elements[e][2]);
    mesh.element_normal[e] = -mesh.element_normal[e];
    ++*turned;
  }
}

/// Gives every element of the pieces marked `both` whose back is not covered a twin behind it.
void add_backs(RadiosityMesh& mesh, const std::vector<uint32_t>& vertex_piece, const std::vector<char>& both,
               const std::vector<uint32_t>& cover, size_t* doubled) {
  const size_t nv = mesh.vertex_count(), ne = mesh.element_count();
  const auto doubles = [&](size_t e) { return both[vertex_piece[mesh.elements[e][0]]] && cover[e] == ~0u; };
  std::vector<uint32_t> twin(nv, ~0u);
  for (size_t e = 0; e < ne; ++e)
    if (doubles(e))
      for (uint32_t v : mesh.elements[e]) twin[v] = 0;
  for (size_t v = 0; v < nv; ++v) {
    if (twin[v] == ~0u) continue;
    twin[v] = uint32_t(mesh.positions.size());
    mesh.positions.push_back(mesh.positions[v]);
    mesh.normals.push_back(-mesh.normals[v]);
    mesh.vertex_material.push_back(mesh.vertex_material[v]);
  }
  if (mesh.vertex_count() == nv) return;
  if (mesh.element_two_sided.size() != ne) mesh.element_two_sided.assign(ne, 0);
  for (size_t e = 0; e < ne; ++e) {
    if (!doubles(e)) continue;
    const std::array<uint32_t, 3> el = mesh.elements[e];
    mesh.elements.push_back({twin[el[0]], twin[el[2]], twin[el[1]]});
    mesh.element_material.push_back(mesh.element_material[e]);
    mesh.element_surface.push_back(mesh.element_surface[e]);
    mesh.element_normal.push_back(-mesh.element_normal[e]);
    mesh.element_area.push_back(mesh.element_area[e]);
    mesh.element_two_sided[e] = 1;
    mesh.element_two_sided.push_back(2);
    ++*doubled;
  }
}

}  // namespace

SidesReport orient_sides(const rc::scene::Scene& scene, RadiosityMesh& mesh) {
  SidesReport report;
  const size_t ne = mesh.element_count();
  if (ne == 0) return report;
  size_t pieces = 0;
  const std::vector<uint32_t> vertex_piece = vertex_pieces(mesh, &pieces);
  report.pieces = pieces;
  std::vector<uint32_t> element_piece(ne), piece_size(pieces, 0);
  for (size_t e = 0; e < ne; ++e) ++piece_size[element_piece[e] = vertex_piece[mesh.elements[e][0]]];
  // Each piece sends about kSideRaysPerPiece rays from each side, each element at least one.
  std::vector<uint32_t> rays(ne);
  for (size_t e = 0; e < ne; ++e)
    rays[e] = std::max(
        1u, (uint32_t(kSideRaysPerPiece) + piece_size[element_piece[e]] - 1) / piece_size[element_piece[e]]);

  const rc::scene::Scene geometry = element_scene(scene, mesh);
  const std::vector<uint32_t> cover =
      covering_elements(geometry, mesh, glm::length(scene.bounds().diagonal()));
  const SideTracer tracer(scene, geometry, mesh, element_piece, rays, cover);
  constexpr size_t kChunk = 256;
  std::vector<ChunkFindings> chunks((ne + kChunk - 1) / kChunk);
  rc::util::parallel_for(chunks.size(), [&](size_t c) {
    for (size_t e = c * kChunk; e < std::min(ne, (c + 1) * kChunk); ++e) tracer.trace(uint32_t(e), chunks[c]);
  });
  for (const ChunkFindings& c : chunks) report.rays += c.rays;
  const std::vector<char> lit = lit_sides(2 * pieces, chunks);

  // A piece partly covered on its back is never turned over (its covered elements would then lie
  // on their covers facing the same way): where light reaches its back alone, its uncovered
  // elements are given twins instead, and its front stays unlit.
  std::vector<char> covered(pieces, 0);
  for (size_t e = 0; e < ne; ++e) covered[element_piece[e]] |= cover[e] != ~0u;
  std::vector<char> turn(pieces, 0), both(pieces, 0);
  for (size_t p = 0; p < pieces; ++p) {
    turn[p] = !lit[2 * p] && lit[2 * p + 1] && !covered[p];
    both[p] = lit[2 * p + 1] && (lit[2 * p] || covered[p]);
  }
  turn_over(mesh, vertex_piece, turn, &report.turned_elements);
  add_backs(mesh, vertex_piece, both, cover, &report.two_sided_elements);
  return report;
}

}  // namespace gilt::radiosity::mesh
