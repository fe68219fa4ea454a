// The element hierarchy's "sends nothing" test (behind, radiosity/solver/cluster_tree.h): it
// must never cull a pair of clusters that can exchange light (it is a bound), and it should cull
// the twins that the mesher lays behind a surface lit on both sides (radiosity/mesh/sides.h):
// before it could, every cluster of a twinned wall was refined against its twins down to the
// elements, and Šibenik's coarsest timed level took 24 M links.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "radiosity/solver/cluster_tree.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
using rc::Rgb;
using rc::Vec3;

namespace {

/// An n × n grid of elements over the unit square at height y, facing up (or down), appended to mesh.
void add_sheet(rad::mesh::RadiosityMesh& mesh, int n, float y, bool up, float tilt = 0.0f) {
  const uint32_t base = uint32_t(mesh.positions.size());
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const float x = float(i) / float(n), z = float(j) / float(n);
      mesh.positions.push_back(Vec3(x, y + tilt * x, z));
      mesh.normals.push_back(Vec3(0.0f, up ? 1.0f : -1.0f, 0.0f));
      mesh.vertex_material.push_back(0);
    }
  const auto at = [&](int i, int j) { return base + uint32_t(i * (n + 1) + j); };
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const std::array<std::array<uint32_t, 3>, 2> tris = {
          {{at(i, j), at(i, j + 1), at(i + 1, j + 1)}, {at(i, j), at(i + 1, j + 1), at(i + 1, j)}}};
      for (auto t : tris) {
        if (!up) std::swap(t[1], t[2]);
        const Vec3 a = mesh.positions[t[0]], b = mesh.positions[t[1]], c = mesh.positions[t[2]];
        const Vec3 cr = glm::cross(b - a, c - a);
        mesh.elements.push_back(t);
        mesh.element_material.push_back(0);
        mesh.element_surface.push_back(0);
        mesh.element_normal.push_back(glm::normalize(cr));
        mesh.element_area.push_back(0.5f * glm::length(cr));
      }
    }
}

/// The elements under node k.
std::vector<uint32_t> elements_of(const rad::solver::detail::Tree& tree, uint32_t k) {
  const rad::solver::detail::Node& node = tree.nodes[k];
  return std::vector<uint32_t>(tree.order.begin() + node.first, tree.order.begin() + node.first + node.count);
}

/// Whether some vertex of `to`'s elements lies in front of some element of `from` by more than
/// `slack`: light could pass between them.
bool in_front(const rad::mesh::RadiosityMesh& mesh, const std::vector<uint32_t>& from,
              const std::vector<uint32_t>& to, float slack) {
  for (uint32_t f : from) {
    const Vec3 n = mesh.element_normal[f], p = mesh.positions[mesh.elements[f][0]];
    for (uint32_t t : to)
      for (uint32_t v : mesh.elements[t])
        if (glm::dot(n, mesh.positions[v] - p) > slack) return true;
  }
  return false;
}

}  // namespace

// A sheet facing up with its twins facing down on it, a parallel sheet above facing down, and a
// tilted one facing up: every pair of nodes behind() culls has no vertex of the one in front of
// an element of the other (beyond the test's own slack, 1e-4 of the nearest distance plus 1e-6
// of the farthest: at most 2e-6 here, as both lie in the unit box), and clusters of the sheet and
// of its twins (16 elements or more each) are culled both ways.
TEST(ClusterTree, BehindCullsTwinsAndNothingThatSeesLight) {
  rad::mesh::RadiosityMesh mesh;
  add_sheet(mesh, 8, 0.0f, true);
  add_sheet(mesh, 8, 0.0f, false);  // the twins
  add_sheet(mesh, 4, 0.5f, false);
  add_sheet(mesh, 4, 0.2f, true, 0.3f);
  const std::vector<Rgb> albedo(mesh.element_count(), Rgb(0.5f));
  const rad::solver::detail::Tree tree = rad::solver::detail::make_tree(mesh, albedo);

  const float slack = 2e-5f;  // the test's slack, above what behind() allows, for rounding
  size_t culled = 0;
  bool twins_apart = false;
  for (uint32_t a = 0; a < tree.nodes.size(); ++a)
    for (uint32_t b = 0; b < tree.nodes.size(); ++b) {
      if (a == b || !rad::solver::detail::behind(tree.nodes[a], tree.nodes[b])) continue;
      ++culled;
      const std::vector<uint32_t> from = elements_of(tree, a), to = elements_of(tree, b);
      ASSERT_FALSE(in_front(mesh, from, to, slack)) << "nodes " << a << " and " << b;
      // A cluster of the sheet's elements and one of its twins, both of many elements.
      const auto all_in = [](const std::vector<uint32_t>& es, uint32_t lo, uint32_t hi) {
        return std::all_of(es.begin(), es.end(), [&](uint32_t e) { return e >= lo && e < hi; });
      };
      if (from.size() >= 16 && to.size() >= 16 && all_in(from, 0, 128) && all_in(to, 128, 256))
        twins_apart = twins_apart || rad::solver::detail::behind(tree.nodes[b], tree.nodes[a]);
    }
  EXPECT_GT(culled, 0u);
  EXPECT_TRUE(twins_apart) << "a cluster of the sheet and one of its twins cull each other";
}

// Three sheets facing up, one above another with space between (a floor over a crawl space's,
// the floors of storeys): each sheet is a subtree of its own. A cluster that held pieces of two
// would share one visible fraction between an upper piece and the lower one it hides; split by
// position (the sheets are wider than they are apart) every node above the leaves held both.
TEST(ClusterTree, ParallelLayersAreSplitApart) {
  rad::mesh::RadiosityMesh mesh;
  add_sheet(mesh, 8, 0.0f, true);
  add_sheet(mesh, 8, 0.3f, true);
  add_sheet(mesh, 8, 0.6f, true);
  const uint32_t per_sheet = 128;
  ASSERT_EQ(mesh.element_count(), 3u * per_sheet);
  const std::vector<Rgb> albedo(mesh.element_count(), Rgb(0.5f));
  const rad::solver::detail::Tree tree = rad::solver::detail::make_tree(mesh, albedo);
  for (uint32_t sheet = 0; sheet < 3; ++sheet) {
    bool found = false;
    for (uint32_t k = 0; k < tree.nodes.size() && !found; ++k) {
      const std::vector<uint32_t> es = elements_of(tree, k);
      found = es.size() == per_sheet &&
              std::all_of(es.begin(), es.end(), [&](uint32_t e) { return e / per_sheet == sheet; });
    }
    EXPECT_TRUE(found) << "no node holds exactly sheet " << sheet;
  }
  // Nodes below the top two levels hold one sheet each.
  for (uint32_t k = 0; k < tree.nodes.size(); ++k) {
    const std::vector<uint32_t> es = elements_of(tree, k);
    if (es.size() > per_sheet) continue;
    const uint32_t sheet = es.front() / per_sheet;
    EXPECT_TRUE(std::all_of(es.begin(), es.end(), [&](uint32_t e) { return e / per_sheet == sheet; }))
        << "node " << k << " of " << es.size() << " elements mixes sheets";
  }
}
