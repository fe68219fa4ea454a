#pragma once
// Pearson chi-square goodness-of-fit tests for sampling routines, in the manner of Mitsuba's
// `ChiSquareTest` and pbrt's sampling tests: histogram N samples on a grid, integrate the claimed
// density numerically over every cell to get the expected counts, pool cells whose expected count
// is below 5 (the usual validity rule for Pearson's statistic), and reject when the p-value falls
// below a significance level that is Šidák-corrected for the number of tests in the program.
//
// Every grid has one extra "remainder" cell: samples that fell outside the grid or were not
// produced at all (e.g. a BSDF sample under the surface). Its expected count is N minus the
// integral over the grid, so a density that does not integrate to one is tested as well.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <boost/math/distributions/chi_squared.hpp>

#include "raytrace_core/util/math.h"
#include "raytrace_core/util/rng.h"

namespace gilt::test {

/// Family-wise significance level of every chi-square test program.
inline constexpr double kFamilyAlpha = 0.01;

/// Per-test level such that `num_tests` independent tests all pass with probability 1 − alpha
/// when every null hypothesis holds (Šidák correction).
inline double sidak_alpha(double alpha, int num_tests) {
  return 1.0 - std::pow(1.0 - alpha, 1.0 / static_cast<double>(num_tests));
}

/// Outcome of one chi-square test.
struct Chi2Result {
  bool passed = false;
  double statistic = 0.0;
  double p_value = 0.0;
  int dof = 0;
  double alpha = 0.0;
  std::string summary;  ///< statistic, degrees of freedom, p-value and level
  std::string message;  ///< summary, pooling and the cells that contribute most, for a failure report
};

/// Pearson test of observed against expected counts (both summing to the sample count). Cells with
/// expected count below `min_expected` are pooled, smallest first, into one cell; if that pool is
/// still below `min_expected` the next-smallest cells join it until it is not.
inline Chi2Result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                            double alpha, double min_expected = 5.0) {
  Chi2Result r;
  r.alpha = alpha;
  std::vector<size_t> order(expected.size());
  std::iota(order.begin(), order.end(), size_t{0});
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });

  struct Term {
    double contribution, obs, exp;
    size_t cell;
  };
  std::vector<Term> terms;
  double pool_obs = 0.0, pool_exp = 0.0;
  size_t pooled = 0, cells = 0;
  for (size_t i : order) {
    if (expected[i] < min_expected || (pooled > 0 && pool_exp < min_expected)) {
      pool_obs += observed[i];
      pool_exp += expected[i];
      ++pooled;
      continue;
    }
    const double d = observed[i] - expected[i];
    terms.push_back({d * d / expected[i], observed[i], expected[i], i});
    r.statistic += d * d / expected[i];
    ++cells;
  }
  std::ostringstream msg;
  if (pool_exp > 0.0) {
    const double d = pool_obs - pool_exp;
    r.statistic += d * d / pool_exp;
    ++cells;
    msg << "pooled " << pooled << " cells (obs " << pool_obs << ", exp " << pool_exp << "); ";
  } else if (pool_obs > 0.0) {
    r.message = "samples in cells of zero expected count: " + std::to_string(pool_obs);
    return r;
  }
  if (cells < 2) {
    r.message = "fewer than two cells with expected counts: nothing to test";
    return r;
  }
  r.dof = static_cast<int>(cells) - 1;  // the counts are constrained to the same total
  r.p_value = boost::math::cdf(boost::math::complement(boost::math::chi_squared(r.dof), r.statistic));
  r.passed = r.p_value >= alpha;
  std::ostringstream summary;
  summary << "chi2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.p_value
          << ", alpha = " << alpha;
  r.summary = summary.str();
  msg << r.summary;
  std::sort(terms.begin(), terms.end(),
            [](const Term& a, const Term& b) { return a.contribution > b.contribution; });
  for (size_t k = 0; k < std::min<size_t>(5, terms.size()); ++k)
    msg << "\n  cell " << terms[k].cell << ": obs " << terms[k].obs << ", exp " << terms[k].exp;
  r.message = msg.str();
  return r;
}

/// A regular grid over [a_lo, a_hi] × [b_lo, b_hi] with one extra remainder cell at index size() − 1.
struct Grid2 {
  int na = 1, nb = 1;
  double a_lo = 0.0, a_hi = 1.0, b_lo = 0.0, b_hi = 1.0;

  size_t size() const { return static_cast<size_t>(na) * static_cast<size_t>(nb) + 1; }
  size_t remainder() const { return size() - 1; }
  /// Cell of the point (a, b); the remainder cell when it lies outside the grid.
  size_t cell(double a, double b) const {
    if (!(a >= a_lo && a <= a_hi && b >= b_lo && b <= b_hi)) return remainder();
    const int i = std::min(na - 1, static_cast<int>((a - a_lo) / (a_hi - a_lo) * na));
    const int j = std::min(nb - 1, static_cast<int>((b - b_lo) / (b_hi - b_lo) * nb));
    return static_cast<size_t>(i) * static_cast<size_t>(nb) + static_cast<size_t>(j);
  }
  /// ∫∫ f(a, b) da db over cell (i, j): `sub` × `sub` sub-cells, 3 × 3-point Gauss–Legendre in each
  /// (exact for polynomials of degree 5 per axis). An open rule never evaluates f on a cell
  /// boundary, where a density may jump (e.g. at the horizon) and would leak into the neighbour.
  template <class F>
  double integrate(int i, int j, const F& f, int sub) const {
    static constexpr double kNode[3] = {-0.77459666924148337704, 0.0, 0.77459666924148337704};  // ±sqrt(3/5)
    static constexpr double kWeight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    const double da = (a_hi - a_lo) / na, db = (b_hi - b_lo) / nb;
    const double ha = da / sub, hb = db / sub;
    double sum = 0.0;
    for (int x = 0; x < sub; ++x)
      for (int y = 0; y < sub; ++y) {
        const double ca = a_lo + i * da + (x + 0.5) * ha, cb = b_lo + j * db + (y + 0.5) * hb;
        for (int p = 0; p < 3; ++p)
          for (int q = 0; q < 3; ++q)
            sum += kWeight[p] * kWeight[q] * f(ca + 0.5 * ha * kNode[p], cb + 0.5 * hb * kNode[q]);
      }
    return sum * ha * hb / 4.0;
  }
  /// ∫∫ f over [a0, a1] × [b0, b1], refining into quadrants while the 3 × 3 Gauss–Legendre estimate
  /// of a rectangle and the sum over its quadrants differ by more than `tol`, at most `depth`
  /// times: for densities with jumps inside cells (e.g. the edges of a light's silhouette).
  template <class F>
  static double integrate_adaptive(double a0, double a1, double b0, double b1, const F& f, double tol,
                                   int depth) {
    auto gauss = [&f](double x0, double x1, double y0, double y1) {
      static constexpr double kNode[3] = {-0.77459666924148337704, 0.0, 0.77459666924148337704};
      static constexpr double kWeight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
      double sum = 0.0;
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q)
          sum +=
              kWeight[p] * kWeight[q] *
              f(0.5 * (x0 + x1) + 0.5 * (x1 - x0) * kNode[p], 0.5 * (y0 + y1) + 0.5 * (y1 - y0) * kNode[q]);
      return sum * (x1 - x0) * (y1 - y0) / 4.0;
    };
    struct Rect {
      double a0, a1, b0, b1, estimate, tol;
      int depth;
    };
    std::vector<Rect> stack{{a0, a1, b0, b1, gauss(a0, a1, b0, b1), tol, depth}};
    double total = 0.0;
    while (!stack.empty()) {
      const Rect r = stack.back();
      stack.pop_back();
      const double am = 0.5 * (r.a0 + r.a1), bm = 0.5 * (r.b0 + r.b1);
      const Rect quads[4] = {{r.a0, am, r.b0, bm, 0, 0, 0},
                             {am, r.a1, r.b0, bm, 0, 0, 0},
                             {r.a0, am, bm, r.b1, 0, 0, 0},
                             {am, r.a1, bm, r.b1, 0, 0, 0}};
      double fine[4], sum = 0.0;
      for (int k = 0; k < 4; ++k) sum += fine[k] = gauss(quads[k].a0, quads[k].a1, quads[k].b0, quads[k].b1);
      if (r.depth == 0 || std::fabs(sum - r.estimate) <= r.tol) {
        total += sum;
        continue;
      }
      for (int k = 0; k < 4; ++k)
        stack.push_back(
            {quads[k].a0, quads[k].a1, quads[k].b0, quads[k].b1, fine[k], 0.25 * r.tol, r.depth - 1});
    }
    return total;
  }

  /// Expected counts of n samples with density `f` in the grid's coordinates. The remainder cell
  /// gets n · outside_mass when the caller knows the mass outside the grid (e.g. 0 when the grid
  /// covers the whole support), else what the grid integral leaves of n (clamped at zero). The
  /// first keeps integration error, which the subtraction would gather into one cell, spread
  /// thinly over all cells. With `adaptive_depth` > 0 each of the sub × sub sub-cells is refined
  /// adaptively up to that depth.
  template <class F>
  std::vector<double> expected_counts(double n, const F& f, int sub = 3, int adaptive_depth = 0,
                                      std::optional<double> outside_mass = std::nullopt) const {
    std::vector<double> e(size(), 0.0);
    double inside = 0.0;
    const double da = (a_hi - a_lo) / na, db = (b_hi - b_lo) / nb;
    for (int i = 0; i < na; ++i)
      for (int j = 0; j < nb; ++j) {
        double p = 0.0;
        if (adaptive_depth > 0) {  // each of the sub × sub sub-cells adaptively, to 10⁻³ samples per cell
          const double ha = da / sub, hb = db / sub, tol = 1e-3 / (n * sub * sub);
          for (int x = 0; x < sub; ++x)
            for (int y = 0; y < sub; ++y) {
              const double a0 = a_lo + i * da + x * ha, b0 = b_lo + j * db + y * hb;
              p += integrate_adaptive(a0, a0 + ha, b0, b0 + hb, f, tol, adaptive_depth);
            }
        } else {
          p = integrate(i, j, f, sub);
        }
        e[static_cast<size_t>(i) * static_cast<size_t>(nb) + static_cast<size_t>(j)] = n * p;
        inside += n * p;
      }
    e[remainder()] = outside_mass ? n * *outside_mass : std::max(0.0, n - inside);
    return e;
  }
};

/// A grid over a band of the sphere of directions, in rows of cos θ (equal solid angle per cell)
/// or of θ (finer near the poles, where a narrow lobe around the normal lives), and columns of
/// φ ∈ [0, 2π).
struct DirectionGrid {
  Grid2 grid;
  bool theta_rows = false;  ///< rows in θ rather than cos θ

  size_t size() const { return grid.size(); }
  size_t remainder() const { return grid.remainder(); }
  /// Cell of direction w (need not be exactly unit).
  size_t cell(const raytrace_core::Vec3& w) const {
    const double x = w.x, y = w.y, z = w.z;
    double phi = std::atan2(y, x);
    if (phi < 0.0) phi += 2.0 * std::numbers::pi;
    if (phi >= 2.0 * std::numbers::pi) phi = 0.0;
    const double len = std::sqrt(x * x + y * y + z * z);
    const double row = theta_rows ? std::atan2(std::sqrt(x * x + y * y), z) : std::clamp(z / len, -1.0, 1.0);
    return grid.cell(row, phi);
  }
  /// Expected counts of n directions with solid-angle density pdf(Vec3). dω = d(cos θ) dφ, or
  /// sin θ dθ dφ with θ rows.
  template <class Pdf>
  std::vector<double> expected_counts(double n, const Pdf& pdf, int sub = 3, int adaptive_depth = 0,
                                      std::optional<double> outside_mass = std::nullopt) const {
    return grid.expected_counts(
        n,
        [&](double row, double phi) {
          const double z = theta_rows ? std::cos(row) : row;
          const double jacobian = theta_rows ? std::sin(row) : 1.0;
          const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
          const raytrace_core::Vec3 w{static_cast<float>(r * std::cos(phi)),
                                      static_cast<float>(r * std::sin(phi)), static_cast<float>(z)};
          return jacobian * static_cast<double>(pdf(w));
        },
        sub, adaptive_depth, outside_mass);
  }
};

/// Grid with nz rows of cos θ ∈ [z_lo, z_hi] and nphi columns: cells of equal solid angle.
inline DirectionGrid sphere_grid(int nz, int nphi, double z_lo = -1.0, double z_hi = 1.0) {
  return {{nz, nphi, z_lo, z_hi, 0.0, 2.0 * std::numbers::pi}, false};
}

/// Grid with ntheta rows of θ ∈ [0, theta_max] and nphi columns.
inline DirectionGrid theta_grid(int ntheta, int nphi, double theta_max = std::numbers::pi) {
  return {{ntheta, nphi, 0.0, theta_max, 0.0, 2.0 * std::numbers::pi}, true};
}

/// Chi-square test of a direction sampler against its claimed solid-angle density.
/// `sample(Rng&)` returns std::optional<Vec3> (empty: no sample, counted in the remainder cell);
/// `pdf(Vec3)` is the density per steradian.
template <class Sample, class Pdf>
Chi2Result chi2_directions(const DirectionGrid& grid, size_t n, uint64_t seed, const Sample& sample,
                           const Pdf& pdf, double alpha, int sub = 3, int adaptive_depth = 0,
                           std::optional<double> outside_mass = std::nullopt) {
  raytrace_core::util::Rng rng(seed);
  std::vector<double> observed(grid.size(), 0.0);
  for (size_t k = 0; k < n; ++k) {
    const std::optional<raytrace_core::Vec3> w = sample(rng);
    observed[w ? grid.cell(*w) : grid.remainder()] += 1.0;
  }
  return chi2_test(
      observed, grid.expected_counts(static_cast<double>(n), pdf, sub, adaptive_depth, outside_mass), alpha);
}

/// Prints the outcome (so passing runs show their p-values too) and fails the test if rejected.
inline void expect_chi2_pass(const Chi2Result& r) {
  std::printf("    [chi2] %s\n", r.summary.empty() ? r.message.c_str() : r.summary.c_str());
  EXPECT_TRUE(r.passed) << r.message;
}

}  // namespace gilt::test
