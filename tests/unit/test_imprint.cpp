// gilt's own imprinting (radiosity/mesh/imprint.h): a surface cut along the lines where tool triangles
// cross or touch it stays a conforming surface of the same area and facing, carries the contact
// outline as cuts, and comes out the same whatever else the process did.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "radiosity/mesh/imprint.h"

namespace rad = gilt::radiosity;
using rad::mesh::detail::DVec3;
using rad::mesh::detail::ImprintCounts;
using rad::mesh::detail::TriangleSoup;
using Triangle = std::array<DVec3, 3>;

namespace {

/// A floor: the square [0, size]² at z = 0 cut into n × n cells of two triangles, facing +z.
TriangleSoup floor_grid(int n, double size = 1.0) {
  TriangleSoup s;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) s.points.emplace_back(size * i / n, size * j / n, 0.0);
  const auto at = [n](int i, int j) { return static_cast<uint32_t>(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      s.triangles.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
      s.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
    }
  return s;
}

/// The twelve triangles of the box [lo, hi], wound outward.
std::vector<Triangle> box(const DVec3& lo, const DVec3& hi) {
  const auto c = [&](int i) { return DVec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z); };
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  std::vector<Triangle> out;
  for (const auto& q : quads) {
    out.push_back({c(q[0]), c(q[1]), c(q[2])});
    out.push_back({c(q[0]), c(q[2]), c(q[3])});
  }
  return out;
}

DVec3 normal(const TriangleSoup& s, const std::array<uint32_t, 3>& t) {
  return glm::cross(s.points[t[1]] - s.points[t[0]], s.points[t[2]] - s.points[t[0]]);
}

double area(const TriangleSoup& s) {
  double a = 0.0;
  for (const auto& t : s.triangles) a += 0.5 * glm::length(normal(s, t));
  return a;
}

/// Checks that `s` is an oriented surface without T-junctions: every edge is used at most once
/// in each direction, and an edge used in one direction only lies on the square's border.
void expect_conforming(const TriangleSoup& s, double size = 1.0) {
  std::map<std::pair<uint32_t, uint32_t>, int> uses;
  for (const auto& t : s.triangles)
    for (int k = 0; k < 3; ++k) ++uses[{t[k], t[(k + 1) % 3]}];
  for (const auto& [edge, count] : uses) {
    ASSERT_EQ(count, 1) << "an edge used twice in one direction: the faces overlap";
    if (uses.count({edge.second, edge.first})) continue;
    const DVec3 a = s.points[edge.first], b = s.points[edge.second];
    const bool on_border = (a.x == 0 && b.x == 0) || (a.y == 0 && b.y == 0) || (a.x == size && b.x == size) ||
                           (a.y == size && b.y == size);
    EXPECT_TRUE(on_border) << "an open edge inside the floor (" << a.x << ", " << a.y << ")–(" << b.x << ", " << b.y
                           << "): a T-junction";
  }
}

double cut_length(const TriangleSoup& s) {
  double length = 0.0;
  for (const auto& c : s.cuts) length += glm::length(s.points[c[1]] - s.points[c[0]]);
  return length;
}

}  // namespace

TEST(Imprint, ABlockStandingOnTheFloorLeavesItsOutline) {
  const TriangleSoup floor = floor_grid(4);
  // A block 0.3 × 0.2 standing on the floor, its sides crossing cell edges and diagonals.
  const std::vector<Triangle> block = box({0.33, 0.41, 0.0}, {0.63, 0.61, 0.5});
  ImprintCounts counts;
  const TriangleSoup cut = rad::mesh::detail::imprint(floor, block, &counts);
  EXPECT_GT(counts.faces_cut, 0u);
  EXPECT_EQ(counts.segments_lost, 0u);
  expect_conforming(cut);
  // Cutting moves no area, and every piece still faces up.
  EXPECT_NEAR(area(cut), 1.0, 1e-12);
  for (const auto& t : cut.triangles) EXPECT_GT(normal(cut, t).z, 0.0);
  // The cuts are the block's outline, and nothing else: its perimeter, every cut on it.
  EXPECT_NEAR(cut_length(cut), 2 * (0.3 + 0.2), 1e-12);
  for (const auto& c : cut.cuts)
    for (uint32_t v : c) {
      const DVec3 p = cut.points[v];
      const bool on_outline = std::abs(p.x - 0.33) < 1e-12 || std::abs(p.x - 0.63) < 1e-12 ||
                              std::abs(p.y - 0.41) < 1e-12 || std::abs(p.y - 0.61) < 1e-12;
      EXPECT_TRUE(on_outline) << p.x << ", " << p.y;
    }
  // The input's points come first, unchanged.
  for (size_t i = 0; i < floor.points.size(); ++i) EXPECT_EQ(cut.points[i], floor.points[i]);
}

TEST(Imprint, ALegPiercingTheFloorAndAWallAlongItsEdgeAreImprinted) {
  const TriangleSoup floor = floor_grid(3);
  std::vector<Triangle> tools = box({0.1, 0.1, -0.2}, {0.2, 0.25, 0.7});  // pierces the floor
  // A wall standing on the floor's cell edge y = 2/3 from x = 0.2 to x = 0.9: its bottom edge lies
  // along the floor's edges, which carry it as cuts.
  const double y = 2.0 / 3.0;
  tools.push_back({DVec3(0.2, y, 0.0), DVec3(0.9, y, 0.0), DVec3(0.9, y, 1.0)});
  tools.push_back({DVec3(0.2, y, 0.0), DVec3(0.9, y, 1.0), DVec3(0.2, y, 1.0)});
  const TriangleSoup cut = rad::mesh::detail::imprint(floor, tools);
  expect_conforming(cut);
  EXPECT_NEAR(area(cut), 1.0, 1e-12);
  EXPECT_NEAR(cut_length(cut), 2 * (0.1 + 0.15) + 0.7, 1e-12);
}

TEST(Imprint, ToolsThatIntersectThemselvesAndCrossEachOther) {
  const TriangleSoup floor = floor_grid(2);
  // Two overlapping blocks read as one tool (a self-intersecting mesh): their outlines cross.
  std::vector<Triangle> tools = box({0.2, 0.2, 0.0}, {0.6, 0.6, 0.3});
  const std::vector<Triangle> second = box({0.4, 0.4, 0.0}, {0.8, 0.7, 0.3});
  tools.insert(tools.end(), second.begin(), second.end());
  const TriangleSoup cut = rad::mesh::detail::imprint(floor, tools);
  expect_conforming(cut);
  EXPECT_NEAR(area(cut), 1.0, 1e-12);
  // Both outlines whole, each cut where the other crosses it.
  EXPECT_NEAR(cut_length(cut), 2 * (0.4 + 0.4) + 2 * (0.4 + 0.3), 1e-12);
}

TEST(Imprint, CoplanarAndFarToolsLeaveTheSurfaceAsItIs) {
  const TriangleSoup floor = floor_grid(2);
  std::vector<Triangle> tools = {{DVec3(0.1, 0.1, 0.0), DVec3(0.5, 0.1, 0.0), DVec3(0.1, 0.5, 0.0)}};  // a decal
  const std::vector<Triangle> above = box({0.2, 0.2, 0.1}, {0.4, 0.4, 0.3});  // floating
  tools.insert(tools.end(), above.begin(), above.end());
  ImprintCounts counts;
  const TriangleSoup cut = rad::mesh::detail::imprint(floor, tools, &counts);
  EXPECT_EQ(counts.faces_cut, 0u);
  EXPECT_EQ(cut.triangles, floor.triangles);
  EXPECT_TRUE(cut.cuts.empty());
}

TEST(Imprint, TheSameInputGivesTheSameBytes) {
  const TriangleSoup floor = floor_grid(6);
  std::vector<Triangle> tools;
  for (int k = 0; k < 9; ++k) {
    const double x = 0.05 + 0.1 * k, y = 0.9 - 0.093 * k;
    const std::vector<Triangle> leg = box({x, y - 0.04, -0.01 * k}, {x + 0.031, y, 0.4});
    tools.insert(tools.end(), leg.begin(), leg.end());
  }
  const TriangleSoup first = rad::mesh::detail::imprint(floor, tools);
  expect_conforming(first);
  for (int run = 0; run < 3; ++run) {
    std::vector<std::unique_ptr<char[]>> clutter;  // a different heap each time
    for (int k = 0; k < 50 * (run + 1); ++k) clutter.emplace_back(new char[size_t(40 + 977 * k)]);
    const TriangleSoup again = rad::mesh::detail::imprint(floor, tools);
    EXPECT_EQ(again.points, first.points);
    EXPECT_EQ(again.triangles, first.triangles);
    EXPECT_EQ(again.cuts, first.cuts);
  }
}
