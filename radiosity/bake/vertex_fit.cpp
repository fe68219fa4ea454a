// Least-squares vertex colours (Kavan, Bargteil & Sloan 2011). With φ_i the hat function of
// vertex i (linear over each face, 1 at i, 0 at the face's other corners) and f the field, the
// colours c minimise
//     Σ_faces ∫ (Σ_i c_i φ_i(x) − f(x))² dA  +  kFitSmoothness Σ_faces A/3 Σ_edges (c_a − c_b)²,
// whose normal equations (M + λL) c = b are sparse, symmetric and positive (semi-)definite: M is
// the mass matrix, L an area-weighted graph Laplacian, b_i = ∫ φ_i f dA. Both integrals are
// taken with the same quadrature (the centroids of a regular split of each face), so a point
// where the field is unknown leaves both out and a face with no known point is held by the
// smoothness term alone. Each colour channel is one conjugate-gradient solve (Eigen).

#include "radiosity/bake/vertex_fit.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include "raytrace_core/util/parallel.h"

namespace gilt::radiosity::bake {


const char* to_string(VertexFit fit) { return fit == VertexFit::point ? "point" : "least-squares"; }

namespace {

/// What one face adds to the normal equations: its 3×3 block of M + λL and its three rows of b.
struct FaceTerms {
  std::array<std::array<double, 3>, 3> m{};
  std::array<std::array<double, 3>, 3> b{};  ///< [corner][channel]
  uint32_t samples = 0, missing = 0;
};

FaceTerms face_terms(const Vec3& p0, const Vec3& p1, const Vec3& p2, size_t face, const SurfaceField& field,
                     float spacing) {
  FaceTerms t;
  const Vec3 cross = glm::cross(p1 - p0, p2 - p0);
  const double area = 0.5 * double(glm::length(cross));
  if (!(area > 0.0)) return t;
  const Vec3 n = glm::normalize(cross);
  const float longest = std::max({glm::length(p1 - p0), glm::length(p2 - p1), glm::length(p0 - p2)});
  const int split = std::clamp(int(std::ceil(longest / std::max(spacing, 1e-30f))), 2, kMaxFitSplit);
  const double weight = area / double(split * split);
  const auto sample = [&](double u, double v) {  // barycentrics of corners 1 and 2
    const double bary[3] = {1.0 - u - v, u, v};
    const Vec3 p = float(bary[0]) * p0 + float(bary[1]) * p1 + float(bary[2]) * p2;
    ++t.samples;
    const std::optional<Rgb> f = field(p, n, face);
    if (!f) {
      ++t.missing;
      return;
    }
    for (int a = 0; a < 3; ++a) {
      for (int c = 0; c < 3; ++c) t.m[a][c] += weight * bary[a] * bary[c];
      for (int ch = 0; ch < 3; ++ch) t.b[a][ch] += weight * bary[a] * double((*f)[ch]);
    }
  };
  // The split's upward parts have centroids at ((i + 1/3)/s, (j + 1/3)/s), its downward parts at
  // ((i + 2/3)/s, (j + 2/3)/s); every part has area A/s².
  const double s = split;
  for (int i = 0; i < split; ++i)
    for (int j = 0; i + j < split; ++j) {
      sample((i + 1.0 / 3.0) / s, (j + 1.0 / 3.0) / s);
      if (i + j + 1 < split) sample((i + 2.0 / 3.0) / s, (j + 2.0 / 3.0) / s);
    }
  const double smooth = kFitSmoothness * area / 3.0;
  for (int a = 0; a < 3; ++a) {
    const int c = (a + 1) % 3;
    t.m[a][a] += smooth;
    t.m[c][c] += smooth;
    t.m[a][c] -= smooth;
    t.m[c][a] -= smooth;
  }
  return t;
}

std::vector<Rgb> point_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                               const SurfaceField& field, FitStats& stats, rc::util::Progress* progress) {
  // The vertex's normal: its faces' normals weighted by area.
  std::vector<Vec3> normal(positions.size(), Vec3(0.0f));
  std::vector<size_t> face_of(positions.size(), 0);  // the largest face around the vertex
  std::vector<float> largest(positions.size(), 0.0f);
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    const Vec3 cross = glm::cross(positions[indices[f + 1]] - positions[indices[f]],
                                  positions[indices[f + 2]] - positions[indices[f]]);
    for (int k = 0; k < 3; ++k) {
      const uint32_t v = indices[f + size_t(k)];
      normal[v] += cross;
      if (glm::length(cross) > largest[v]) {
        largest[v] = glm::length(cross);
        face_of[v] = f / 3;
      }
    }
  }
  std::vector<Rgb> out(positions.size(), Rgb(0.0f));
  std::vector<uint8_t> missing(positions.size(), 0);
  rc::util::parallel_for(positions.size(), [&](size_t v) {
    const float len = glm::length(normal[v]);
    if (!(len > 0.0f)) return;  // no face uses it, or only degenerate ones
    const std::optional<Rgb> f = field(positions[v], normal[v] / len, face_of[v]);
    if (f) out[v] = *f;
    missing[v] = !f;
    if (progress) progress->advance(1);
  });
  for (size_t v = 0; v < positions.size(); ++v) {
    stats.samples += glm::length(normal[v]) > 0.0f;
    stats.missing += missing[v];
  }
  return out;
}

}  // namespace

std::vector<Rgb> fit_vertex_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                    const SurfaceField& field, VertexFit fit, float spacing, FitStats* stats,
                                    rc::util::Progress* progress) {
  FitStats local;
  FitStats& st = stats ? *stats : local;
  if (fit == VertexFit::point) return point_colours(positions, indices, field, st, progress);

  const size_t faces = indices.size() / 3;
  std::vector<FaceTerms> terms(faces);
  rc::util::parallel_for(faces, [&](size_t f) {
    terms[f] = face_terms(positions[indices[3 * f]], positions[indices[3 * f + 1]], positions[indices[3 * f + 2]], f,
                          field, spacing);
    if (progress) progress->advance(1);
  });

  const auto n = Eigen::Index(positions.size());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(faces * 9 + positions.size());
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  std::vector<uint8_t> used(positions.size(), 0);
  for (size_t f = 0; f < faces; ++f) {
    const FaceTerms& t = terms[f];
    st.samples += t.samples;
    st.missing += t.missing;
    for (int a = 0; a < 3; ++a) {
      const uint32_t va = indices[3 * f + size_t(a)];
      used[va] = 1;
      for (int c = 0; c < 3; ++c)
        if (t.m[a][c] != 0.0) triplets.emplace_back(Eigen::Index(va), Eigen::Index(indices[3 * f + size_t(c)]), t.m[a][c]);
      for (int ch = 0; ch < 3; ++ch) rhs(va, ch) += t.b[a][ch];
    }
  }
  // A vertex no face holds gets the equation c = 0, so the matrix has no empty row.
  for (size_t v = 0; v < positions.size(); ++v)
    if (!used[v]) triplets.emplace_back(Eigen::Index(v), Eigen::Index(v), 1.0);
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());

  std::vector<Rgb> out(positions.size(), Rgb(0.0f));
  if (n == 0) return out;
  // Colours cannot be negative, and the unconstrained fit overshoots below zero beside a sharp
  // change (a shadow edge). Clamping afterwards would leave its neighbours fitted to the
  // overshoot, so the negative vertices are instead held at zero (a large diagonal penalty) and
  // the rest fitted again: an active-set step towards the non-negative least-squares fit, a few
  // rounds, then whatever is still negative is clamped.
  constexpr int kRounds = 4;
  constexpr double kHold = 1e8;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(1e-10);
  cg.setMaxIterations(std::max<Eigen::Index>(1000, 4 * n));
  for (int ch = 0; ch < 3; ++ch) {
    Eigen::SparseMatrix<double> held = a;
    std::vector<uint8_t> is_held(positions.size(), 0);
    Eigen::VectorXd x;
    for (int round = 0; round < kRounds; ++round) {
      cg.compute(held);
      x = cg.solve(rhs.col(ch));
      st.iterations = std::max(st.iterations, int(cg.iterations()));
      bool changed = false;
      for (Eigen::Index v = 0; v < n; ++v)
        if (x[v] < 0.0 && !is_held[size_t(v)]) {
          is_held[size_t(v)] = 1;
          held.coeffRef(v, v) *= kHold;
          changed = true;
        }
      if (!changed) break;
    }
    for (Eigen::Index v = 0; v < n; ++v) out[size_t(v)][ch] = float(std::max(0.0, x[v]));
  }
  return out;
}

}  // namespace gilt::radiosity::bake
