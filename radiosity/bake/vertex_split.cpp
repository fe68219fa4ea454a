#include "radiosity/bake/vertex_split.h"

#include <algorithm>
#include <numeric>
#include <tuple>

namespace gilt::radiosity::bake {

std::vector<SharedEdge> shared_edges(std::span<const uint32_t> indices) {
  struct HalfEdge {
    uint32_t lo, hi, face;
  };
  std::vector<HalfEdge> half;
  half.reserve(indices.size());
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    const uint32_t a = indices[f], b = indices[f + 1], c = indices[f + 2];
    if (a == b || b == c || c == a) continue;
    for (const auto& [p, q] : {std::pair{a, b}, std::pair{b, c}, std::pair{c, a}})
      half.push_back({std::min(p, q), std::max(p, q), uint32_t(f / 3)});
  }
  std::sort(half.begin(), half.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return std::tie(x.lo, x.hi, x.face) < std::tie(y.lo, y.hi, y.face);
  });
  std::vector<SharedEdge> out;
  for (size_t k = 0; k < half.size();) {
    size_t end = k + 1;
    while (end < half.size() && half[end].lo == half[k].lo && half[end].hi == half[k].hi) ++end;
    if (end - k == 2 && half[k].face != half[k + 1].face)
      out.push_back({half[k].face, half[k + 1].face, half[k].lo, half[k].hi});
    k = end;
  }
  std::sort(out.begin(), out.end(),
            [](const SharedEdge& x, const SharedEdge& y) { return std::tie(x.f, x.g) < std::tie(y.f, y.g); });
  return out;
}

namespace {

/// The corner of face f at vertex v (f is known to use v).
size_t corner_at(std::span<const uint32_t> indices, uint32_t f, uint32_t v) {
  const size_t base = 3 * size_t(f);
  return indices[base] == v ? base : indices[base + 1] == v ? base + 1 : base + 2;
}

uint32_t find(std::vector<uint32_t>& parent, uint32_t x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

/// Numbers the groups of `root_of` (one root per corner) in order of first corner.
Wedges number(std::span<const uint32_t> indices, const std::function<uint32_t(size_t)>& root_of) {
  Wedges w;
  w.of_corner.assign(indices.size(), 0);
  std::vector<uint32_t> id(indices.size(), UINT32_MAX);
  for (size_t c = 0; c < indices.size(); ++c) {
    const uint32_t r = root_of(c);
    if (id[r] == UINT32_MAX) {
      id[r] = uint32_t(w.vertex.size());
      w.vertex.push_back(indices[c]);
    }
    w.of_corner[c] = id[r];
  }
  return w;
}

}  // namespace

Wedges one_wedge_per_vertex(std::span<const uint32_t> indices) {
  // The first corner of each vertex stands for all of them.
  std::vector<uint32_t> first;
  for (size_t c = 0; c < indices.size(); ++c) {
    if (indices[c] >= first.size()) first.resize(size_t(indices[c]) + 1, UINT32_MAX);
    if (first[indices[c]] == UINT32_MAX) first[indices[c]] = uint32_t(c);
  }
  return number(indices, [&](size_t c) { return first[indices[c]]; });
}

Wedges wedges_across(std::span<const uint32_t> indices, std::span<const SharedEdge> edges,
                     const std::function<bool(const SharedEdge&)>& joined) {
  std::vector<uint32_t> parent(indices.size());
  std::iota(parent.begin(), parent.end(), 0u);
  for (const SharedEdge& e : edges) {
    if (!joined(e)) continue;
    for (const uint32_t v : {e.u, e.v}) {
      const uint32_t a = find(parent, uint32_t(corner_at(indices, e.f, v)));
      const uint32_t b = find(parent, uint32_t(corner_at(indices, e.g, v)));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  return number(indices, [&](size_t c) { return find(parent, uint32_t(c)); });
}

}  // namespace gilt::radiosity::bake
