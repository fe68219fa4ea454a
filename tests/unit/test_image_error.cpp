// The shared image error measures against values worked out by hand.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "raytrace_core/util/image_error.h"
#include "raytrace_core/util/rng.h"

namespace rc = gilt::raytrace_core;

TEST(ImageError, MatchesHandComputedValues) {
  // Differences: 0.1 in every channel of the first pixel, 0 in the second.
  const std::vector<rc::Rgb> reference = {rc::Rgb(0.4f), rc::Rgb(1.0f)};
  const std::vector<rc::Rgb> image = {rc::Rgb(0.5f), rc::Rgb(1.0f)};
  const rc::util::ImageError e = rc::util::image_error(image, reference);
  const double d = double(0.5f) - double(0.4f), r = double(0.4f);
  EXPECT_NEAR(e.mae, d / 2, 1e-12);
  EXPECT_NEAR(e.rmse, std::sqrt(d * d / 2), 1e-12);
  EXPECT_NEAR(e.relmse, d * d / (r * r + 0.01) / 2, 1e-12);
  EXPECT_NEAR(e.mean_relative, d / (r + 0.01) / 2, 1e-12);
  EXPECT_EQ(rc::util::mean_relative_error(image, reference), e.mean_relative);
  EXPECT_EQ(rc::util::image_error(reference, reference).rmse, 0.0);
  // Brightness: (0.5 + 1) / (0.4 + 1) in every channel; a black reference reads 1.
  EXPECT_NEAR(e.mean_ratio, (double(0.5f) + 1.0) / (r + 1.0), 1e-12);
  EXPECT_EQ(rc::util::image_error(image, std::vector<rc::Rgb>(2, rc::Rgb(0.0f))).mean_ratio, 1.0);
  EXPECT_THROW(rc::util::image_error(image, std::vector<rc::Rgb>(1)), std::invalid_argument);
}

namespace {

/// A standard normal variate (Box–Muller).
double normal(rc::util::Rng& rng) {
  const double u1 = 1.0 - double(rng.uniform()), u2 = rng.uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * 3.14159265358979323846 * u2);
}

}  // namespace

TEST(ImageError, TheReferencesNoiseIsTakenOutOfTheSquaredErrors) {
  // An exact image μ, a reference mixed 3 : 1 from two noisy halves (as gilt compare's halves
  // with 300 and 100 samples), and two "methods" whose noise is half and twice the reference's
  // variance. Against the noisy reference the squared errors carry its variance on top of each
  // method's own; corrected, they must agree with the errors against μ itself within the
  // estimators' stated standard errors (4 of each: the two estimates are correlated, so their
  // difference spreads less than the sum), and the uncorrected ones must not.
  constexpr int kPixels = 128 * 128;
  constexpr double kRelativeNoise = 0.03;  // the reference's standard deviation over μ
  constexpr double kW = 0.75;             // share of the reference's samples in half A
  rc::util::Rng rng(2026);
  std::vector<rc::Rgb> exact(kPixels), a(kPixels), b(kPixels), reference(kPixels), better(kPixels), worse(kPixels);
  double true_floor = 0.0;
  for (int i = 0; i < kPixels; ++i)
    for (int c = 0; c < 3; ++c) {
      const double mu = 0.05 + 1.95 * rng.uniform(), sd = kRelativeNoise * mu;
      exact[i][c] = float(mu);
      // Var(R) = sd²: half A holds 3/4 of the samples, so its variance is sd²/w, B's sd²/(1 − w).
      a[i][c] = float(mu + sd / std::sqrt(kW) * normal(rng));
      b[i][c] = float(mu + sd / std::sqrt(1.0 - kW) * normal(rng));
      reference[i][c] = float(kW * a[i][c] + (1.0 - kW) * b[i][c]);
      better[i][c] = float(mu + sd * std::sqrt(0.5) * normal(rng));
      worse[i][c] = float(mu + sd * std::sqrt(2.0) * normal(rng));
      true_floor += sd * sd;
    }
  true_floor /= 3.0 * kPixels;
  const std::vector<rc::Rgb> variance = rc::util::reference_variance(a, b, kW);

  for (const std::vector<rc::Rgb>* method : {&better, &worse}) {
    const rc::util::ImageError clean = rc::util::image_error(*method, exact);
    const rc::util::ImageError noisy = rc::util::image_error(*method, reference, variance);
    EXPECT_TRUE(noisy.noise_corrected);
    EXPECT_FALSE(clean.noise_corrected);
    const double tolerance = 4.0 * (noisy.relmse_stderr + clean.relmse_stderr);
    EXPECT_NEAR(noisy.relmse, clean.relmse, tolerance);
    EXPECT_GT(std::abs(noisy.relmse_measured - clean.relmse), 3.0 * tolerance) << "the test cannot tell the correction";
    // MSE likewise, within 4 standard errors of the difference, taken from the spread of its
    // per-pixel terms (X − R)² − v − (X − μ)².
    double sum = 0.0, sum_sq = 0.0;
    for (int i = 0; i < kPixels; ++i)
      for (int c = 0; c < 3; ++c) {
        const double x = (*method)[i][c], r = reference[i][c], mu = exact[i][c];
        const double t = (x - r) * (x - r) - variance[i][c] - (x - mu) * (x - mu);
        sum += t, sum_sq += t * t;
      }
    const double n = 3.0 * kPixels, mse_stderr = std::sqrt((sum_sq / n - (sum / n) * (sum / n)) / (n - 1.0));
    EXPECT_NEAR(noisy.rmse * noisy.rmse, clean.rmse * clean.rmse, 4.0 * mse_stderr);
    // The floor against the true variance: each term is sd² times a χ² variate with one degree of
    // freedom (variance 2·sd⁴), so the mean's variance is 2·Σ sd⁴ / n², at most
    // 2·max(sd²)·(Σ sd² / n) / n.
    const double max_sd2 = (kRelativeNoise * 2.0) * (kRelativeNoise * 2.0);
    EXPECT_NEAR(noisy.mse_floor, true_floor, 4.0 * std::sqrt(2.0 * max_sd2 * true_floor / n));
  }
  // The two rank as against the exact image, and the better one is found below the floor.
  const rc::util::ImageError better_e = rc::util::image_error(better, reference, variance);
  const rc::util::ImageError worse_e = rc::util::image_error(worse, reference, variance);
  EXPECT_LT(better_e.relmse, worse_e.relmse);
  EXPECT_LT(better_e.relmse, better_e.relmse_floor);
  EXPECT_GT(worse_e.relmse, worse_e.relmse_floor);
  // Without a variance nothing is subtracted.
  const rc::util::ImageError plain = rc::util::image_error(better, reference);
  EXPECT_EQ(plain.relmse, plain.relmse_measured);
  EXPECT_EQ(plain.relmse_floor, 0.0);
  EXPECT_THROW(rc::util::image_error(better, reference, std::vector<rc::Rgb>(3)), std::invalid_argument);
  EXPECT_THROW(rc::util::reference_variance(a, b, 1.0), std::invalid_argument);
}
