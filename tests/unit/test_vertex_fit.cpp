// Vertex colours fitted to a field over a mesh's faces (radiosity/bake/vertex_fit.h): a linear field
// is reproduced by both fits, least squares is nearer a sharp field than point samples, unknown
// points are left out, and the result is never negative.

#include "radiosity/bake/vertex_fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace gilt::radiosity {
using namespace bake;
namespace {

/// A unit square in the xy-plane cut into n × n cells of two triangles, facing +z.
struct Grid {
  std::vector<Vec3> positions;
  std::vector<uint32_t> indices;
};

Grid grid(int n, float jitter = 0.0f) {
  Grid g;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) {
      // Interior vertices moved a little, deterministically, so the mesh is not regular.
      const bool interior = i > 0 && j > 0 && i < n && j < n;
      const float dx = interior ? jitter * std::sin(float(7 * i + 3 * j)) / float(n) : 0.0f;
      const float dy = interior ? jitter * std::cos(float(5 * i + 11 * j)) / float(n) : 0.0f;
      g.positions.emplace_back(float(i) / float(n) + dx, float(j) / float(n) + dy, 0.0f);
    }
  const auto at = [n](int i, int j) { return uint32_t(j * (n + 1) + i); };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      for (uint32_t v : {at(i, j), at(i + 1, j), at(i + 1, j + 1)}) g.indices.push_back(v);
      for (uint32_t v : {at(i, j), at(i + 1, j + 1), at(i, j + 1)}) g.indices.push_back(v);
    }
  return g;
}

/// ∫ (interpolated colours − f)² dA over the grid's faces, red channel, by a fine midpoint rule
/// independent of the fit's own quadrature.
double l2_error(const Grid& g, const std::vector<Rgb>& c, const std::function<float(const Vec3&)>& f) {
  double sum = 0.0;
  constexpr int kSplit = 64;
  for (size_t t = 0; t < g.indices.size(); t += 3) {
    const Vec3 &a = g.positions[g.indices[t]], &b = g.positions[g.indices[t + 1]], &d = g.positions[g.indices[t + 2]];
    const double area = 0.5 * glm::length(glm::cross(b - a, d - a)) / double(kSplit * kSplit);
    for (int i = 0; i < kSplit; ++i)
      for (int j = 0; i + j < kSplit; ++j)
        for (int up = 0; up < (i + j + 1 < kSplit ? 2 : 1); ++up) {
          const float u = (float(i) + (up ? 2.0f : 1.0f) / 3.0f) / kSplit;
          const float v = (float(j) + (up ? 2.0f : 1.0f) / 3.0f) / kSplit;
          const Vec3 p = (1.0f - u - v) * a + u * b + v * d;
          const double fit = (1.0f - u - v) * c[g.indices[t]].r + u * c[g.indices[t + 1]].r + v * c[g.indices[t + 2]].r;
          sum += area * std::pow(fit - f(p), 2.0);
        }
  }
  return sum;
}

/// ∫ over the grid's faces of the interpolated colours (red), exactly: the mean of a face's
/// corners times its area.
double integral(const Grid& g, const std::vector<Rgb>& c) {
  double sum = 0.0;
  for (size_t t = 0; t < g.indices.size(); t += 3) {
    const Vec3 &a = g.positions[g.indices[t]], &b = g.positions[g.indices[t + 1]], &d = g.positions[g.indices[t + 2]];
    sum += 0.5 * glm::length(glm::cross(b - a, d - a)) *
           (c[g.indices[t]].r + c[g.indices[t + 1]].r + c[g.indices[t + 2]].r) / 3.0;
  }
  return sum;
}

/// ∫ f dA over the grid's faces by the midpoint rule on a 1024² lattice (the grid is the unit square).
double integral(const Grid&, const std::function<double(const Vec3&)>& f) {
  double sum = 0.0;
  constexpr int kN = 1024;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) sum += f(Vec3((i + 0.5f) / kN, (j + 0.5f) / kN, 0.0f));
  return sum / double(kN * kN);
}

SurfaceField scalar_field(std::function<float(const Vec3&)> f) {
  return [f](const Vec3& p, const Vec3&, size_t) -> std::optional<Rgb> { return Rgb(f(p)); };
}

TEST(VertexFit, ALinearFieldIsReproducedExactlyByBothFits) {
  const Grid g = grid(5, 0.3f);
  const auto f = [](const Vec3& p) { return 0.25f + 2.0f * p.x + 0.5f * p.y; };
  for (VertexFit fit : {VertexFit::least_squares, VertexFit::point}) {
    const std::vector<Rgb> c = fit_vertex_colours(g.positions, g.indices, scalar_field(f), fit, 0.05f);
    // Both integrals use one quadrature, so without the smoothness term the fit of a linear field
    // is exact. That term pulls each vertex towards its neighbours with kFitSmoothness the weight
    // of the fit's, and neighbours differ by less than the field's range (2.5 here): the fit is
    // off by at most kFitSmoothness × 2.5 (measured: 1.5e-3). Point samples are exact.
    const float tolerance = fit == VertexFit::point ? 1e-6f : float(kFitSmoothness) * 2.5f;
    for (size_t v = 0; v < g.positions.size(); ++v) EXPECT_NEAR(c[v].r, f(g.positions[v]), tolerance) << v;
  }
}

TEST(VertexFit, LeastSquaresIsNearerASharpFieldThanPointSamples) {
  // Two kinds of detail smaller than a coarse 2 × 2 grid's faces: the shadow of a thin pole falling
  // across the middle column of vertices, which point samples spread over all four faces around
  // it, and a sun patch between vertices, which point samples miss altogether.
  const Grid g = grid(2);
  const std::function<float(const Vec3&)> fields[] = {
      [](const Vec3& p) { return std::fabs(p.x - 0.5f) < 0.06f ? 0.0f : 1.0f; },
      [](const Vec3& p) { return glm::length(p - Vec3(0.3f, 0.7f, 0.0f)) < 0.12f ? 4.0f : 0.0f; },
  };
  for (const auto& f : fields) {
    const auto ls = fit_vertex_colours(g.positions, g.indices, scalar_field(f), VertexFit::least_squares, 0.01f);
    const auto point = fit_vertex_colours(g.positions, g.indices, scalar_field(f), VertexFit::point, 0.01f);
    const double e_ls = l2_error(g, ls, f), e_point = l2_error(g, point, f);
    // Least squares is the best linear interpolant up to its quadrature and its smoothness term
    // (together below 1 %), so it cannot lose by more than that, and must win outright here.
    EXPECT_LT(e_ls, 0.99 * e_point) << e_ls << " vs " << e_point;
    for (const Rgb& c : ls) EXPECT_GE(c.r, 0.0f);
  }
  // Where no vertex is held at zero (the shadow), the fit's error is orthogonal to the constant
  // 1 = Σ φ_i, so the light on the whole grid is kept: ∫ fit dA = ∫ f dA up to the quadrature of
  // f's edges (parts of 0.01 along edges of length 2: 1 %); the point samples lose 43 % here.
  // (Beside the sun patch the unconstrained fit dips below zero; holding those vertices at zero
  // costs this property and adds light, 20 % there, for a smaller L² error.)
  {
    const auto& f = fields[0];
    const auto ls = fit_vertex_colours(g.positions, g.indices, scalar_field(f), VertexFit::least_squares, 0.01f);
    const double exact = integral(g, [&f](const Vec3& p) { return double(f(p)); });
    EXPECT_NEAR(integral(g, ls), exact, 0.01 * exact);
  }
}

TEST(VertexFit, NegativeOvershootIsHeldAtZeroNotClampedAfterwards) {
  // A step near a vertex column overshoots below zero in the unconstrained fit; holding those
  // vertices at zero and refitting the rest beats point samples even here, where the point
  // samples happen to be nearly right (clamping the unconstrained fit did not: 0.0486 vs 0.0468).
  const Grid g = grid(2);
  const auto f = [](const Vec3& p) { return p.x < 0.3f ? 0.0f : 1.0f; };
  const auto ls = fit_vertex_colours(g.positions, g.indices, scalar_field(f), VertexFit::least_squares, 0.01f);
  const auto point = fit_vertex_colours(g.positions, g.indices, scalar_field(f), VertexFit::point, 0.01f);
  EXPECT_LT(l2_error(g, ls, f), l2_error(g, point, f));
  for (const Rgb& c : ls) EXPECT_GE(c.r, 0.0f);
}

TEST(VertexFit, PointsWithoutAValueAreLeftOut) {
  // The field is known on the right half only (say the left half was buried); there it is 2. The
  // left vertices follow their neighbours through the smoothness term instead of turning black.
  const Grid g = grid(4);
  const SurfaceField half = [](const Vec3& p, const Vec3&, size_t) -> std::optional<Rgb> {
    if (p.x < 0.5f) return std::nullopt;
    return Rgb(2.0f);
  };
  FitStats stats;
  const auto c = fit_vertex_colours(g.positions, g.indices, half, VertexFit::least_squares, 0.05f, &stats);
  EXPECT_GT(stats.missing, 0u);
  EXPECT_LT(stats.missing, stats.samples);
  for (const Rgb& x : c) EXPECT_NEAR(x.r, 2.0f, 1e-3f);
}

TEST(VertexFit, UnusedAndDegenerateVerticesStayFiniteAndBlack) {
  // Vertex 3 is used by no face; vertices 4–6 only by a face of zero area.
  const std::vector<Vec3> p = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {5, 5, 5}, {2, 2, 0}, {2, 2, 0}, {2, 2, 0}};
  const std::vector<uint32_t> idx = {0, 1, 2, 4, 5, 6};
  for (VertexFit fit : {VertexFit::least_squares, VertexFit::point}) {
    const auto c = fit_vertex_colours(p, idx, scalar_field([](const Vec3&) { return 1.0f; }), fit, 0.1f);
    ASSERT_EQ(c.size(), p.size());
    for (int v : {0, 1, 2}) EXPECT_NEAR(c[size_t(v)].r, 1.0f, 1e-4f);
    for (int v : {3, 4, 5, 6}) EXPECT_EQ(c[size_t(v)].r, 0.0f);
  }
}

}  // namespace
}  // namespace gilt::radiosity
