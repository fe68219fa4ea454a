// Conforming refinement of the radiosity mesh by longest-edge bisection (Rivara 1984): a split
// edge splits every element on it, so no T-junction is ever made.

#include <algorithm>
#include <bit>
#include <cmath>
#include <unordered_map>

#include "radiosity/mesh/mesh.h"

namespace gilt::radiosity::mesh {
namespace {

/// An edge by the positions of its ends, in either order: elements on the two sides of a sharp
/// or material border have separate vertices but the same positions.
struct EdgeKey {
  std::array<uint32_t, 6> bits;
  bool operator==(const EdgeKey&) const = default;
};

EdgeKey edge_key(const Vec3& p, const Vec3& q) {
  auto bits = [](const Vec3& v) {
    return std::array<uint32_t, 3>{std::bit_cast<uint32_t>(v.x), std::bit_cast<uint32_t>(v.y),
                                   std::bit_cast<uint32_t>(v.z)};
  };
  std::array<uint32_t, 3> a = bits(p), b = bits(q);
  if (b < a) std::swap(a, b);
  return {{a[0], a[1], a[2], b[0], b[1], b[2]}};
}

struct EdgeKeyHash {
  size_t operator()(const EdgeKey& k) const {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (uint32_t x : k.bits) h = (h ^ x) * 0x100000001b3ull;
    return size_t(h ^ (h >> 29));
  }
};

float edge_length2(const RadiosityMesh& mesh, uint32_t a, uint32_t b) {
  const Vec3 d = mesh.positions[a] - mesh.positions[b];
  return glm::dot(d, d);
}

}  // namespace

size_t split_longest_edges(RadiosityMesh& mesh, const std::vector<uint32_t>& elements, float min_edge) {
  std::unordered_map<EdgeKey, std::vector<uint32_t>, EdgeKeyHash> on_edge;
  auto key_of = [&](uint32_t e, int i) {
    return edge_key(mesh.positions[mesh.elements[e][i]], mesh.positions[mesh.elements[e][(i + 1) % 3]]);
  };
  for (uint32_t e = 0; e < mesh.element_count(); ++e)
    for (int i = 0; i < 3; ++i) on_edge[key_of(e, i)].push_back(e);
  auto replace = [&](const EdgeKey& key, uint32_t from, uint32_t to) {
    for (uint32_t& x : on_edge[key])
      if (x == from) x = to;
  };

  const size_t vertices_before = mesh.vertex_count();
  std::vector<bool> split(mesh.element_count(), false);
  const float min_edge2 = min_edge * min_edge;
  for (uint32_t e : elements) {
    if (e >= split.size() || split[e]) continue;
    const auto& el = mesh.elements[e];
    int longest = 0;
    for (int i = 1; i < 3; ++i)
      if (edge_length2(mesh, el[i], el[(i + 1) % 3]) > edge_length2(mesh, el[longest], el[(longest + 1) % 3]))
        longest = i;
    if (edge_length2(mesh, el[longest], el[(longest + 1) % 3]) < min_edge2) continue;
    const EdgeKey key = key_of(e, longest);
    const std::vector<uint32_t> sharing = on_edge[key];
    if (std::any_of(sharing.begin(), sharing.end(), [&](uint32_t f) { return f < split.size() && split[f]; }))
      continue;  // a neighbour was split already this round; its turn comes next round
    on_edge.erase(key);
    // One midpoint per pair of end vertices: the two sides of a smooth edge share it, the two
    // sides of a border each get their own.
    std::vector<std::pair<uint64_t, uint32_t>> midpoints;
    for (uint32_t f : sharing) {
      int i = 0;
      while (key_of(f, i) != key) ++i;
      const uint32_t a = mesh.elements[f][i], b = mesh.elements[f][(i + 1) % 3], c = mesh.elements[f][(i + 2) % 3];
      const uint64_t pair = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
      uint32_t m = ~0u;
      for (const auto& [k, v] : midpoints)
        if (k == pair) m = v;
      if (m == ~0u) {
        m = uint32_t(mesh.vertex_count());
        const Vec3 lo = std::min(a, b) == a ? mesh.positions[a] : mesh.positions[b];
        const Vec3 hi = std::min(a, b) == a ? mesh.positions[b] : mesh.positions[a];
        mesh.positions.push_back(0.5f * (lo + hi));
        const Vec3 n = mesh.normals[a] + mesh.normals[b];
        mesh.normals.push_back(glm::dot(n, n) > 0.0f ? glm::normalize(n) : mesh.normals[a]);
        mesh.vertex_material.push_back(mesh.vertex_material[a]);
        midpoints.emplace_back(pair, m);
      }
      // f = (a, b, c) becomes (a, m, c), and g = (m, b, c) is new.
      const uint32_t g = uint32_t(mesh.element_count());
      mesh.elements[f] = {a, m, c};
      mesh.elements.push_back({m, b, c});
      mesh.element_material.push_back(mesh.element_material[f]);
      mesh.element_surface.push_back(mesh.element_surface[f]);
      mesh.element_normal.push_back(mesh.element_normal[f]);
      const float half = 0.5f * mesh.element_area[f];
      mesh.element_area[f] = half;
      mesh.element_area.push_back(half);
      if (!mesh.element_two_sided.empty()) mesh.element_two_sided.push_back(mesh.element_two_sided[f]);
      replace(key_of(g, 1), f, g);  // edge b–c moved to g
      on_edge[key_of(f, 0)].push_back(f);
      on_edge[key_of(f, 1)].push_back(f);
      on_edge[key_of(g, 0)].push_back(g);
      on_edge[key_of(g, 1)];  // already there
      on_edge[key_of(f, 1)].push_back(g);  // m–c is shared by f and g
      if (f < split.size()) split[f] = true;
    }
  }
  return mesh.vertex_count() - vertices_before;
}

}  // namespace gilt::radiosity::mesh
