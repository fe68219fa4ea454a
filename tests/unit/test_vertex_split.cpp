// Vertex colours with split vertices (radiosity/bake/vertex_split.h, fit_split_colours in
// vertex_fit.h): a crease, a change of material and a shadow line along an edge each split the
// vertices on their edge, so a field that jumps there is fitted exactly; a smooth field with
// noise, and an edge of three faces, split nothing that need not be.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "radiosity/bake/vertex_fit.h"
#include "radiosity/bake/vertex_split.h"

namespace gilt::radiosity {
using namespace bake;
namespace {

struct Mesh {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
};

/// An n × n grid of two triangles per cell over the unit square in the xy-plane (facing +z),
/// folded up by 90° along x = fold (a wall standing on a floor) when fold is in (0, 1).
Mesh grid(int n, float fold = 2.0f) {
  Mesh g;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      const float x = float(i) / float(n), y = float(j) / float(n);
      g.positions.push_back(x <= fold ? Vec3(x, y, 0.0f) : Vec3(fold, y, x - fold));
    }
  const auto at = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      for (uint32_t v : {at(i, j), at(i + 1, j), at(i + 1, j + 1)}) g.indices.push_back(v);
      for (uint32_t v : {at(i, j), at(i + 1, j + 1), at(i, j + 1)}) g.indices.push_back(v);
    }
  return g;
}

/// The face's centroid's x in the unfolded square (the wall's z counts on from the fold).
float unfolded_x(const Mesh& g, size_t face) {
  Vec3 c(0.0f);
  for (size_t k = 0; k < 3; ++k) c += g.positions[g.indices[3 * face + k]] / 3.0f;
  return c.x + c.z;
}

/// ∫ (interpolated colours − f)² dA (red) by a 32 × 32 split of each face, with f constant per
/// face (`field_of_face`): the fit's error against a field that is piecewise constant on faces.
double l2_error(const Mesh& g, const Wedges& w, const std::vector<Rgb>& c,
                const std::function<float(size_t)>& field_of_face) {
  double sum = 0.0;
  constexpr int kSplit = 32;
  for (size_t f = 0; f < g.indices.size() / 3; ++f) {
    const Vec3 &a = g.positions[g.indices[3 * f]], &b = g.positions[g.indices[3 * f + 1]],
               &d = g.positions[g.indices[3 * f + 2]];
    const double area = 0.5 * glm::length(glm::cross(b - a, d - a)) / double(kSplit * kSplit);
    const float c0 = c[w.of_corner[3 * f]].r, c1 = c[w.of_corner[3 * f + 1]].r,
                c2 = c[w.of_corner[3 * f + 2]].r;
    for (int i = 0; i < kSplit; ++i)
      for (int j = 0; i + j < kSplit; ++j)
        for (int up = 0; up < (i + j + 1 < kSplit ? 2 : 1); ++up) {
          const float u = (float(i) + (up ? 2.0f : 1.0f) / 3.0f) / kSplit;
          const float v = (float(j) + (up ? 2.0f : 1.0f) / 3.0f) / kSplit;
          sum += area * std::pow((1.0f - u - v) * c0 + u * c1 + v * c2 - field_of_face(f), 2.0);
        }
  }
  return sum;
}

/// The same error for colours per vertex (fit_vertex_colours).
double l2_error(const Mesh& g, const std::vector<Rgb>& per_vertex,
                const std::function<float(size_t)>& field_of_face) {
  Wedges w;
  w.of_corner = g.indices;
  return l2_error(g, w, per_vertex, field_of_face);
}

constexpr float kSpacing = 0.02f;

TEST(VertexSplit, AnEdgeOfThreeFacesJoinsNone) {
  // Two triangles on edge (0, 1) and a third, a fin, on it too; one more on edge (1, 2).
  const std::vector<uint32_t> indices = {0, 1, 2, 1, 0, 3, 0, 1, 4, 2, 1, 5};
  const std::vector<SharedEdge> edges = shared_edges(indices);
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].f, 0u);
  EXPECT_EQ(edges[0].g, 3u);
  const Wedges all = wedges_across(indices, edges, [](const SharedEdge&) { return true; });
  // Vertices 1 and 2 are joined across (1, 2); vertex 0's and 1's corners in the fin stay apart.
  EXPECT_EQ(all.of_corner[1], all.of_corner[9 + 1]);
  EXPECT_EQ(all.of_corner[2], all.of_corner[9]);
  EXPECT_NE(all.of_corner[0], all.of_corner[4]);
  EXPECT_EQ(one_wedge_per_vertex(indices).count(), 6u);
}

TEST(VertexSplit, ACreaseIsSplitAndEachSideFittedExactly) {
  // A floor meeting a wall (the fold at x = 0.5), each lit evenly but differently: the shared
  // fit makes a compromise along the whole crease, the split one fits both sides exactly.
  const Mesh g = grid(8, 0.5f);
  const auto value = [&](size_t f) { return unfolded_x(g, f) < 0.5f ? 1.0f : 0.25f; };
  const SurfaceField field = [&](const Vec3&, const Vec3&, size_t f) -> std::optional<Rgb> {
    return Rgb(value(f));
  };
  Wedges w;
  const std::vector<Rgb> split =
      fit_split_colours(g.positions, g.indices, field, VertexFit::least_squares, kSpacing, {}, w);
  EXPECT_EQ(w.count(), g.positions.size() + 9u);  // the 9 vertices on the crease, twice
  const std::vector<Rgb> shared =
      fit_vertex_colours(g.positions, g.indices, field, VertexFit::least_squares, kSpacing);
  const double split_error = l2_error(g, w, split, value), shared_error = l2_error(g, shared, value);
  EXPECT_LT(split_error, 1e-8);
  EXPECT_GT(shared_error, 1e-3);
  // Point samples split the same way and read each side's own value.
  Wedges wp;
  const std::vector<Rgb> point =
      fit_split_colours(g.positions, g.indices, field, VertexFit::point, kSpacing, {}, wp);
  EXPECT_EQ(wp.count(), w.count());
  EXPECT_LT(l2_error(g, wp, point, value), 1e-8);
}

TEST(VertexSplit, AShadowLineAlongAnEdgeIsSplitASmoothFieldIsNot) {
  const Mesh g = grid(8);
  // Sun on the left half, sky alone on the right (ten times darker): the line x = 0.5 runs
  // along edges of the grid.
  const auto shadow = [&](size_t f) { return unfolded_x(g, f) < 0.5f ? 1.0f : 0.1f; };
  const SurfaceField lit = [&](const Vec3&, const Vec3&, size_t f) -> std::optional<Rgb> {
    return Rgb(shadow(f));
  };
  Wedges w;
  const std::vector<Rgb> split =
      fit_split_colours(g.positions, g.indices, lit, VertexFit::least_squares, kSpacing, {}, w);
  EXPECT_EQ(w.count(), g.positions.size() + 9u);
  EXPECT_LT(l2_error(g, w, split, shadow), 1e-8);
  EXPECT_GT(l2_error(g, fit_vertex_colours(g.positions, g.indices, lit, VertexFit::least_squares, kSpacing),
                     shadow),
            1e-3);

  // A gradient with ±20 % noise from point to point (a final gather's) jumps by far less than
  // kLightEdgeRatio from one face's own fit to the next: nothing is split.
  const SurfaceField noisy = [](const Vec3& p, const Vec3&, size_t) -> std::optional<Rgb> {
    const float noise = 0.2f * std::sin(917.0f * p.x + 413.0f * p.y);
    return Rgb((0.3f + 0.7f * p.x) * (1.0f + noise));
  };
  Wedges quiet;
  fit_split_colours(g.positions, g.indices, noisy, VertexFit::least_squares, kSpacing, {}, quiet);
  EXPECT_EQ(quiet.count(), g.positions.size());
  // Without light edges the shadow line stays shared.
  SplitRules creases_only;
  creases_only.light_edges = false;
  Wedges kept;
  fit_split_colours(g.positions, g.indices, lit, VertexFit::least_squares, kSpacing, creases_only, kept);
  EXPECT_EQ(kept.count(), g.positions.size());
}

TEST(VertexSplit, FacesOfDifferentKeysDoNotShare) {
  // An even field over two materials (keys) meeting at x = 0.5: split along their boundary even
  // though the light itself is continuous there (a radiance jumps with the albedo).
  const Mesh g = grid(8);
  std::vector<uint32_t> key(g.indices.size() / 3);
  for (size_t f = 0; f < key.size(); ++f) key[f] = unfolded_x(g, f) < 0.5f ? 0 : 1;
  const SurfaceField even = [](const Vec3&, const Vec3&, size_t) -> std::optional<Rgb> { return Rgb(0.5f); };
  SplitRules rules;
  rules.face_key = key;
  Wedges w;
  const std::vector<Rgb> c =
      fit_split_colours(g.positions, g.indices, even, VertexFit::least_squares, kSpacing, rules, w);
  EXPECT_EQ(w.count(), g.positions.size() + 9u);
  for (const Rgb& x : c) EXPECT_NEAR(x.r, 0.5f, 1e-5f);
}

}  // namespace
}  // namespace gilt::radiosity
