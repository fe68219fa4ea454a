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

#include <Eigen/Cholesky>
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

/// One colour per wedge, sampled at its vertex along the area-weighted normal of its faces, as
/// seen from the largest of them.
std::vector<Rgb> point_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                               const Wedges& wedges, const SurfaceField& field, FitStats& stats,
                               rc::util::Progress* progress) {
  const size_t n = wedges.count();
  std::vector<Vec3> normal(n, Vec3(0.0f));
  std::vector<size_t> face_of(n, 0);
  std::vector<float> largest(n, 0.0f);
  for (size_t f = 0; f + 2 < indices.size(); f += 3) {
    const Vec3 cross = glm::cross(positions[indices[f + 1]] - positions[indices[f]],
                                  positions[indices[f + 2]] - positions[indices[f]]);
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t w = wedges.of_corner[f + k];
      normal[w] += cross;
      if (glm::length(cross) > largest[w]) {
        largest[w] = glm::length(cross);
        face_of[w] = f / 3;
      }
    }
  }
  std::vector<Rgb> out(n, Rgb(0.0f));
  std::vector<uint8_t> missing(n, 0);
  rc::util::parallel_for(n, [&](size_t w) {
    const float len = glm::length(normal[w]);
    if (!(len > 0.0f)) return;  // only degenerate faces use it
    const std::optional<Rgb> f = field(positions[wedges.vertex[w]], normal[w] / len, face_of[w]);
    if (f) out[w] = *f;
    missing[w] = !f;
    if (progress) progress->advance(1);
  });
  for (size_t w = 0; w < n; ++w) {
    stats.samples += glm::length(normal[w]) > 0.0f;
    stats.missing += missing[w];
  }
  return out;
}

std::vector<FaceTerms> all_face_terms(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                      const SurfaceField& field, float spacing, FitStats& stats,
                                      rc::util::Progress* progress) {
  std::vector<FaceTerms> terms(indices.size() / 3);
  rc::util::parallel_for(terms.size(), [&](size_t f) {
    terms[f] = face_terms(positions[indices[3 * f]], positions[indices[3 * f + 1]], positions[indices[3 * f + 2]], f,
                          field, spacing);
    if (progress) progress->advance(1);
  });
  for (const FaceTerms& t : terms) {
    stats.samples += t.samples;
    stats.missing += t.missing;
  }
  return terms;
}

/// The least-squares colours of the wedges: the faces' terms assembled by the wedge of each corner.
std::vector<Rgb> solve_wedges(const std::vector<FaceTerms>& terms, const Wedges& wedges, FitStats& st) {
  const auto n = Eigen::Index(wedges.count());
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(terms.size() * 9);
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(n, 3);
  for (size_t f = 0; f < terms.size(); ++f) {
    const FaceTerms& t = terms[f];
    for (size_t a = 0; a < 3; ++a) {
      const auto wa = Eigen::Index(wedges.of_corner[3 * f + a]);
      for (size_t c = 0; c < 3; ++c)
        if (t.m[a][c] != 0.0) triplets.emplace_back(wa, Eigen::Index(wedges.of_corner[3 * f + c]), t.m[a][c]);
      for (int ch = 0; ch < 3; ++ch) rhs(wa, ch) += t.b[a][size_t(ch)];
    }
  }
  // A wedge only degenerate faces hold gets the equation c = 0, so the matrix has no empty row.
  std::vector<uint8_t> held_by_face(size_t(n), 0);
  for (const Eigen::Triplet<double>& t : triplets) held_by_face[size_t(t.row())] = 1;
  for (Eigen::Index w = 0; w < n; ++w)
    if (!held_by_face[size_t(w)]) triplets.emplace_back(w, w, 1.0);
  Eigen::SparseMatrix<double> a(n, n);
  a.setFromTriplets(triplets.begin(), triplets.end());

  std::vector<Rgb> out(size_t(n), Rgb(0.0f));
  if (n == 0) return out;
  // Colours cannot be negative, and the unconstrained fit overshoots below zero beside a sharp
  // change (a shadow edge). Clamping afterwards would leave its neighbours fitted to the
  // overshoot, so the negative wedges are instead held at zero (a large diagonal penalty) and
  // the rest fitted again: an active-set step towards the non-negative least-squares fit, a few
  // rounds, then whatever is still negative is clamped.
  constexpr int kRounds = 4;
  constexpr double kHold = 1e8;
  Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper> cg;
  cg.setTolerance(1e-10);
  cg.setMaxIterations(std::max<Eigen::Index>(1000, 4 * n));
  for (int ch = 0; ch < 3; ++ch) {
    Eigen::SparseMatrix<double> held = a;
    std::vector<uint8_t> is_held(size_t(n), 0);
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

/// Each face's own least-squares fit, alone, as the sum of its channels at its three corners;
/// nothing (negative) for a face with fewer than three known samples.
std::vector<std::array<double, 3>> face_fits(const std::vector<FaceTerms>& terms) {
  std::vector<std::array<double, 3>> out(terms.size(), {-1.0, -1.0, -1.0});
  rc::util::parallel_for(terms.size(), [&](size_t f) {
    const FaceTerms& t = terms[f];
    if (t.samples < t.missing + 3) return;
    Eigen::Matrix3d m;
    Eigen::Vector3d b;
    for (size_t a = 0; a < 3; ++a) {
      for (size_t c = 0; c < 3; ++c) m(Eigen::Index(a), Eigen::Index(c)) = t.m[a][c];
      b[Eigen::Index(a)] = t.b[a][0] + t.b[a][1] + t.b[a][2];
    }
    const Eigen::LDLT<Eigen::Matrix3d> ldlt(m);
    if (ldlt.info() != Eigen::Success || !ldlt.isPositive()) return;
    const Eigen::Vector3d x = ldlt.solve(b);
    for (size_t a = 0; a < 3; ++a) out[f][a] = std::max(0.0, x[Eigen::Index(a)]);
  });
  return out;
}

}  // namespace

std::vector<Rgb> fit_vertex_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                    const SurfaceField& field, VertexFit fit, float spacing, FitStats* stats,
                                    rc::util::Progress* progress) {
  FitStats local;
  FitStats& st = stats ? *stats : local;
  const Wedges wedges = one_wedge_per_vertex(indices);
  const std::vector<Rgb> colours =
      fit == VertexFit::point
          ? point_colours(positions, indices, wedges, field, st, progress)
          : solve_wedges(all_face_terms(positions, indices, field, spacing, st, progress), wedges, st);
  std::vector<Rgb> out(positions.size(), Rgb(0.0f));  // vertices no face uses stay black
  for (size_t w = 0; w < wedges.count(); ++w) out[wedges.vertex[w]] = colours[w];
  return out;
}

std::vector<Rgb> fit_split_colours(std::span<const Vec3> positions, std::span<const uint32_t> indices,
                                   const SurfaceField& field, VertexFit fit, float spacing,
                                   const SplitRules& rules, Wedges& wedges, FitStats* stats,
                                   rc::util::Progress* progress) {
  FitStats local;
  FitStats& st = stats ? *stats : local;
  const size_t faces = indices.size() / 3;
  std::vector<Vec3> normal(faces);
  std::vector<double> area(faces);
  for (size_t f = 0; f < faces; ++f) {
    const Vec3 cross = glm::cross(positions[indices[3 * f + 1]] - positions[indices[3 * f]],
                                  positions[indices[3 * f + 2]] - positions[indices[3 * f]]);
    const float len = glm::length(cross);
    normal[f] = len > 0.0f ? cross / len : Vec3(0.0f);
    area[f] = 0.5 * double(len);
  }
  const std::vector<SharedEdge> edges = shared_edges(indices);
  const auto smooth = [&](const SharedEdge& e) {
    return glm::dot(normal[e.f], normal[e.g]) >= rules.crease_cos &&
           (rules.face_key.empty() || rules.face_key[e.f] == rules.face_key[e.g]);
  };
  if (fit == VertexFit::point) {
    wedges = wedges_across(indices, edges, smooth);
    return point_colours(positions, indices, wedges, field, st, progress);
  }
  const std::vector<FaceTerms> terms = all_face_terms(positions, indices, field, spacing, st, progress);
  if (!rules.light_edges) {
    wedges = wedges_across(indices, edges, smooth);
    return solve_wedges(terms, wedges, st);
  }
  const std::vector<std::array<double, 3>> own = face_fits(terms);
  double sum = 0.0, weight = 0.0;
  for (size_t f = 0; f < faces; ++f)
    if (own[f][0] >= 0.0) sum += area[f] * (own[f][0] + own[f][1] + own[f][2]) / 3.0, weight += area[f];
  const double floor = weight > 0.0 ? 0.01 * sum / weight : 0.0;
  const auto at = [&](uint32_t f, uint32_t v) {
    const size_t base = 3 * size_t(f);
    return floor + own[f][indices[base] == v ? 0 : indices[base + 1] == v ? 1 : 2];
  };
  const auto light_edge = [&](const SharedEdge& e) {
    if (own[e.f][0] < 0.0 || own[e.g][0] < 0.0) return false;
    const double fu = at(e.f, e.u), gu = at(e.g, e.u), fv = at(e.f, e.v), gv = at(e.g, e.v);
    const double r = kLightEdgeRatio;
    return (fu >= r * gu && fv >= r * gv) || (gu >= r * fu && gv >= r * fv);
  };
  wedges = wedges_across(indices, edges, [&](const SharedEdge& e) { return smooth(e) && !light_edge(e); });
  return solve_wedges(terms, wedges, st);
}

}  // namespace gilt::radiosity::bake
