// The visible fractions read after a stopping probe (radiosity/solver/probe_fraction.h) are unbiased:
// over every outcome of the probe and the rays after it, weighted by its probability for given
// true fractions, they average to the true fraction. Exact enumeration, no sampling, so the
// tolerance is rounding.

#include <gtest/gtest.h>

#include <array>
#include <cmath>

#include "radiosity/solver/probe_fraction.h"

namespace rad = gilt::radiosity;

namespace {

double choose(int n, int k) {
  return k < 0 || k > n ? 0.0 : std::exp(std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0));
}

/// P(k hits in n independent rays of pass rate v).
double binomial(int n, int k, double v) { return choose(n, k) * std::pow(v, k) * std::pow(1.0 - v, n - k); }

}  // namespace

// One sequence: a probe of p rays that stops when all pass (reading 1) or all fail (0), else goes
// on to R rays. P(k hits in R, the first p mixed) = [C(R, k) − C(R−p, k−p) − C(R−p, k)] vᵏ (1−v)^(R−k).
// hits / R, read instead, averages to 0.86 at v = 0.8 (R = 16).
TEST(ProbeFraction, ExtendedIsUnbiased) {
  constexpr int probe = 4;
  for (int rays : {5, 8, 16, 64}) {
    for (double v : {0.02, 0.2, 0.5, 0.8, 0.97}) {
      double expected = std::pow(v, probe), naive = expected;
      for (int k = 1; k < rays; ++k) {
        const double p = (choose(rays, k) - choose(rays - probe, k - probe) - choose(rays - probe, k)) *
                         std::pow(v, k) * std::pow(1.0 - v, rays - k);
        const double f = rad::solver::extended_fraction(k, rays, probe);
        ASSERT_GE(f, 1.0 / probe - 1e-12);
        ASSERT_LE(f, (probe - 1.0) / probe + 1e-12);
        expected += p * f;
        naive += p * double(k) / rays;
      }
      EXPECT_NEAR(expected, v, 1e-9) << rays << " rays, v " << v;
      if (rays == 16 && v == 0.8) {
        EXPECT_NEAR(naive, 0.86, 0.005) << "the bias the estimator removes";
      }
    }
  }
}

// Four quarters of pass rates v_j, one probe ray each; where the four disagree, n − 1 more rays
// in each quarter. Enumerated over the probe's 16 patterns and each quarter's count after it.
// The rule it replaces read the probe's 1 where all passed and a fresh set of rays elsewhere:
// P(all pass) + P(mixed) · v̄, so the penumbra of an edge across two quarters (v = 0.4, 0.4, 1, 1)
// read 0.748 for 0.7.
TEST(ProbeFraction, QuarteredIsUnbiased) {
  const std::array<std::array<double, 4>, 5> cases = {{{0.4, 0.4, 1.0, 1.0},
                                                       {0.9, 0.9, 1.0, 1.0},
                                                       {0.0, 0.3, 0.7, 1.0},
                                                       {0.5, 0.5, 0.5, 0.5},
                                                       {0.05, 0.1, 0.95, 0.2}}};
  for (int n : {2, 4, 9}) {
    for (const auto& v : cases) {
      const double truth = (v[0] + v[1] + v[2] + v[3]) / 4.0;
      double expected = 0.0, all_pass = 1.0, all_fail = 1.0;
      for (int j = 0; j < 4; ++j) all_pass *= v[j], all_fail *= 1.0 - v[j];
      const double old_rule = all_pass + (1.0 - all_pass - all_fail) * truth;
      for (int pattern = 0; pattern < 16; ++pattern) {
        double p_pattern = 1.0;
        for (int j = 0; j < 4; ++j) p_pattern *= (pattern >> j & 1) ? v[j] : 1.0 - v[j];
        if (pattern == 15) {
          expected += p_pattern;  // all open reads 1; all blocked 0
          continue;
        }
        if (pattern == 0 || !(p_pattern > 0.0)) continue;
        // Each quarter's further n − 1 rays, independently.
        std::array<int, 4> hits;
        for (int c = 0; c < int(std::pow(n, 4)); ++c) {
          double p = p_pattern;
          int rest = c;
          for (int j = 0; j < 4; ++j) {
            const int more = rest % n;
            rest /= n;
            hits[j] = (pattern >> j & 1) + more;
            p *= binomial(n - 1, more, v[j]);
          }
          if (!(p > 0.0)) continue;
          const double f = rad::solver::quartered_fraction(hits, n);
          ASSERT_GE(f, 0.0);
          ASSERT_LE(f, 1.0);
          expected += p * f;
        }
      }
      EXPECT_NEAR(expected, truth, 1e-9) << n << " rays per quarter, v " << v[0] << " " << v[1] << " " << v[2] << " " << v[3];
      if (v[0] == 0.4 && v[2] == 1.0) {
        EXPECT_NEAR(old_rule, 0.748, 1e-9) << "the bias the estimator removes";
      }
    }
  }
}
