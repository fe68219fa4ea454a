// Closed pieces of a triangle mesh (see closed_surface.h): vertices welded by position, pieces
// joined across shared edges by union-find, and a piece closed when each of its edges has two
// triangles.

#include "raytrace_core/scene/closed_surface.h"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <unordered_map>
#include <utility>

namespace gilt::raytrace_core::scene {

namespace {

struct PositionKey {
  uint32_t bits[3];
  bool operator==(const PositionKey& o) const { return std::equal(bits, bits + 3, o.bits); }
};

struct PositionHash {
  size_t operator()(const PositionKey& k) const {
    uint64_t h = 0x9e3779b97f4a7c15ull;
    for (uint32_t b : k.bits) h = (h ^ b) * 0x100000001b3ull;
    return size_t(h ^ (h >> 29));
  }
};

uint32_t find(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

}  // namespace

std::vector<char> triangles_on_closed_surfaces(const TriangleMesh& mesh) {
  const size_t triangles = mesh.triangle_count();
  std::vector<char> closed(triangles, 0);
  if (triangles == 0) return closed;
  // One index per distinct position (+0 and −0 apart, which no mesher writes twice).
  std::unordered_map<PositionKey, uint32_t, PositionHash> weld;
  weld.reserve(mesh.positions.size());
  std::vector<uint32_t> vertex(mesh.positions.size());
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    PositionKey key;
    std::memcpy(key.bits, &mesh.positions[i], sizeof key.bits);
    vertex[i] = weld.try_emplace(key, uint32_t(weld.size())).first->second;
  }
  // Each edge, its triangles counted and the first one kept to join the others to.
  struct EdgeUse {
    uint32_t first;
    uint32_t count;
  };
  std::unordered_map<uint64_t, EdgeUse> edges;
  edges.reserve(3 * triangles);
  std::vector<uint32_t> parent(triangles);
  std::iota(parent.begin(), parent.end(), 0u);
  for (uint32_t t = 0; t < triangles; ++t)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = vertex[mesh.indices[3 * size_t(t) + k]],
                     b = vertex[mesh.indices[3 * size_t(t) + (k + 1) % 3]];
      if (a == b) continue;
      const uint64_t key = uint64_t(std::min(a, b)) << 32 | std::max(a, b);
      auto [it, fresh] = edges.try_emplace(key, EdgeUse{t, 0});
      ++it->second.count;
      if (!fresh) parent[find(parent, t)] = find(parent, it->second.first);
    }
  // A piece is open when any of its edges has one triangle, or more than two.
  std::vector<char> open(triangles, 0);
  for (const auto& [key, use] : edges)
    if (use.count != 2) open[find(parent, use.first)] = 1;
  for (uint32_t t = 0; t < triangles; ++t) closed[t] = !open[find(parent, t)];
  return closed;
}

}  // namespace gilt::raytrace_core::scene
