// Chi-square tests of the warping functions in raytrace_core/util/sampling.h (see chi2.h for the method).
//
// Each test draws 10⁶ samples from a fixed seed, so results are deterministic; the significance
// level α = 0.01 is shared by the kChi2Tests chi-square tests of this program (Šidák correction),
// i.e. a correct implementation fails somewhere in this file for about 1 seed in 100.

#include <gtest/gtest.h>

#include <numbers>
#include <vector>

#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "tests/statistical/chi2.h"

namespace gilt::raytrace_core::util {
namespace {

using test::chi2_directions;
using test::Grid2;
using test::sphere_grid;

constexpr int kChi2Tests = 10;  // harness check, disk, cosine, sphere, 3 cones, triangle, 2 discrete
constexpr size_t kSamples = 1000000;
const double kAlpha = test::sidak_alpha(test::kFamilyAlpha, kChi2Tests);

// ---- The harness itself. ----

TEST(Chi2Harness, GridIntegralsOfDensitiesSumToOne) {
  // In cos θ rows, cos θ / π and 1/4π are polynomials of the row coordinate, which Gauss–Legendre
  // integrates exactly; what remains is the float rounding of the directions handed to the pdf
  // (relative 2^-24 per cell), far below 1e-6. In θ rows the integrand cos θ sin θ / π is smooth
  // and the rule's error is O(h⁶) with h = π/48: below 1e-9.
  using test::theta_grid;
  for (const auto& grid : {sphere_grid(16, 32), theta_grid(16, 32)}) {
    const auto cosine = grid.expected_counts(1.0, [](Vec3 w) { return cosine_hemisphere_pdf(w.z); });
    const auto uniform = grid.expected_counts(1.0, [](Vec3) { return uniform_sphere_pdf(); });
    EXPECT_NEAR(cosine[grid.remainder()], 0.0, 1e-6);
    EXPECT_NEAR(uniform[grid.remainder()], 0.0, 1e-6);
    double sum_cos = 0.0, sum_uni = 0.0;
    for (size_t i = 0; i < grid.remainder(); ++i) sum_cos += cosine[i], sum_uni += uniform[i];
    EXPECT_NEAR(sum_cos, 1.0, 1e-6);
    EXPECT_NEAR(sum_uni, 1.0, 1e-6);
  }
}

TEST(Chi2Harness, RejectsAWrongDensityAndAcceptsTheRightOne) {
  // Uniform sphere samples tested against cos θ / 2π on the upper half (a wrong density with the
  // right total mass) must fail with an overwhelming statistic; against 1/4π they must pass.
  const auto grid = sphere_grid(16, 32);
  auto sample = [](Rng& rng) { return std::optional<Vec3>(sample_uniform_sphere(rng.uniform2())); };
  const auto wrong = chi2_directions(
      grid, 100000, 7, sample,
      [](Vec3 w) { return w.z > 0.0f ? w.z / (2.0f * kPi) + 0.5f * kInv4Pi : 0.5f * kInv4Pi; }, kAlpha);
  EXPECT_FALSE(wrong.passed) << wrong.message;
  EXPECT_LT(wrong.p_value, 1e-12);
  const auto right = chi2_directions(
      grid, 100000, 7, sample, [](Vec3) { return uniform_sphere_pdf(); }, kAlpha);
  test::expect_chi2_pass(right);
}

// ---- Continuous warps. ----

TEST(Sampling, UniformDiskChiSquare) {
  // Grid on (r², φ): a uniform point on the unit disk has density 1/2π there (dA = ½ d(r²) dφ).
  const Grid2 grid{32, 64, 0.0, 1.0, 0.0, 2.0 * std::numbers::pi};
  Rng rng(101);
  std::vector<double> observed(grid.size(), 0.0);
  for (size_t k = 0; k < kSamples; ++k) {
    const Vec2 p = sample_uniform_disk(rng.uniform2());
    double phi = std::atan2(static_cast<double>(p.y), static_cast<double>(p.x));
    if (phi < 0.0) phi += 2.0 * std::numbers::pi;
    observed[grid.cell(static_cast<double>(p.x) * p.x + static_cast<double>(p.y) * p.y, phi)] += 1.0;
  }
  const auto expected = grid.expected_counts(kSamples, [](double, double) { return 0.5 / std::numbers::pi; });
  EXPECT_EQ(observed[grid.remainder()], 0.0) << "points outside the unit disk";
  const auto r = test::chi2_test(observed, expected, kAlpha);
  test::expect_chi2_pass(r);
}

TEST(Sampling, DiskCornerCases) {
  EXPECT_EQ(sample_uniform_disk({0.5f, 0.5f}), Vec2(0.0f));
  for (Vec2 u :
       {Vec2(0.0f), Vec2(kOneMinusEpsilon), Vec2(0.0f, kOneMinusEpsilon), Vec2(kOneMinusEpsilon, 0.0f)}) {
    const Vec2 p = sample_uniform_disk(u);
    EXPECT_LE(glm::length(p), 1.0f + 1e-6f);
    EXPECT_TRUE(std::isfinite(p.x) && std::isfinite(p.y));
  }
}

TEST(Sampling, CosineHemisphereChiSquare) {
  // Full sphere grid: nothing may land below the horizon (those cells expect zero samples).
  const auto r = chi2_directions(
      sphere_grid(32, 64), kSamples, 202,
      [](Rng& rng) { return std::optional<Vec3>(sample_cosine_hemisphere(rng.uniform2())); },
      [](Vec3 w) { return cosine_hemisphere_pdf(w.z); }, kAlpha);
  test::expect_chi2_pass(r);
  Rng rng(203);
  for (int k = 0; k < 10000; ++k) {
    const Vec3 w = sample_cosine_hemisphere(rng.uniform2());
    ASSERT_GE(w.z, 0.0f);
    ASSERT_NEAR(glm::length(w), 1.0f, 1e-5f);
  }
}

TEST(Sampling, UniformSphereChiSquare) {
  const auto r = chi2_directions(
      sphere_grid(32, 64), kSamples, 303,
      [](Rng& rng) { return std::optional<Vec3>(sample_uniform_sphere(rng.uniform2())); },
      [](Vec3) { return uniform_sphere_pdf(); }, kAlpha);
  test::expect_chi2_pass(r);
}

class ConeChiSquare : public testing::TestWithParam<float> {};

TEST_P(ConeChiSquare, MatchesPdf) {
  // The grid covers exactly cos θ ∈ [cos_max, 1]: any sample outside the cone lands in the
  // remainder cell, whose expected count is zero.
  const float cos_max = GetParam();
  const auto r = chi2_directions(
      sphere_grid(32, 64, cos_max, 1.0), kSamples, 404 + static_cast<uint64_t>(1000.0f * (1.0f + cos_max)),
      [cos_max](Rng& rng) { return std::optional<Vec3>(sample_uniform_cone(rng.uniform2(), cos_max)); },
      [cos_max](Vec3) { return uniform_cone_pdf(cos_max); }, kAlpha);
  test::expect_chi2_pass(r);
  Rng rng(405);
  for (int k = 0; k < 10000; ++k) {
    const Vec3 w = sample_uniform_cone(rng.uniform2(), cos_max);
    ASSERT_GE(w.z, cos_max);
    ASSERT_NEAR(glm::length(w), 1.0f, 1e-5f);
  }
}

INSTANTIATE_TEST_SUITE_P(Sampling, ConeChiSquare, testing::Values(0.95f, 0.3f, -0.6f));

TEST(Sampling, NarrowConeKeepsPrecision) {
  // A cone of half-angle ~1e-3 rad: at its rim sin θ must match the exact value for the given
  // (float) cos_max, computed in double, to float precision rather than lose digits to the
  // cancellation in 1 − cos²θ (which errs by ~ulp(1)/sin²θ ≈ 6% here).
  const float cos_max = std::cos(1e-3f);
  const double exact_sin = std::sqrt(1.0 - static_cast<double>(cos_max) * cos_max);
  const Vec3 w = sample_uniform_cone({kOneMinusEpsilon, 0.0f}, cos_max);
  EXPECT_NEAR(w.x / exact_sin, 1.0, 1e-5);
}

TEST(Sampling, UniformTriangleChiSquare) {
  // K × K cells over (b1, b2) ∈ [0,1]²; the triangle b1 + b2 ≤ 1 has area ½, so the density is 2.
  // Expected counts are exact: cells below the diagonal hold 1/K² of area, cells cut by it half.
  constexpr int K = 40;
  const Grid2 grid{K, K, 0.0, 1.0, 0.0, 1.0};
  std::vector<double> expected(grid.size(), 0.0);
  for (int i = 0; i < K; ++i)
    for (int j = 0; j < K; ++j) {
      const double area = i + j + 1 < K ? 1.0 : (i + j + 1 == K ? 0.5 : 0.0);
      expected[static_cast<size_t>(i * K + j)] = kSamples * 2.0 * area / (K * K);
    }
  Rng rng(505);
  std::vector<double> observed(grid.size(), 0.0);
  for (size_t k = 0; k < kSamples; ++k) {
    const Vec2 b = sample_uniform_triangle(rng.uniform2());
    ASSERT_TRUE(b.x >= 0.0f && b.y >= 0.0f && b.x + b.y <= 1.0f) << b.x << ", " << b.y;
    observed[grid.cell(b.x, b.y)] += 1.0;
  }
  const auto r = test::chi2_test(observed, expected, kAlpha);
  test::expect_chi2_pass(r);
}

// ---- Distribution1D. ----

void discrete_chi2(const std::vector<float>& weights, uint64_t seed) {
  const Distribution1D dist(weights);
  ASSERT_EQ(dist.size(), weights.size());
  std::vector<double> observed(weights.size(), 0.0), expected(weights.size(), 0.0);
  double pmf_sum = 0.0;
  for (uint32_t i = 0; i < weights.size(); ++i) {
    expected[i] = kSamples * static_cast<double>(dist.pmf(i));
    pmf_sum += dist.pmf(i);
  }
  EXPECT_NEAR(pmf_sum, 1.0, 1e-5);
  Rng rng(seed);
  for (size_t k = 0; k < kSamples; ++k) {
    const uint32_t i = dist.sample(rng.uniform());
    ASSERT_LT(i, weights.size());
    ASSERT_GT(weights[i], 0.0f) << "drew zero-weight entry " << i;
    observed[i] += 1.0;
  }
  const auto r = test::chi2_test(observed, expected, kAlpha);
  test::expect_chi2_pass(r);
}

TEST(Distribution1D, SmallChiSquare) {
  discrete_chi2({0.0f, 1.0f, 0.0f, 3.0f, 0.5f, 0.0f, 2.0f, 1e-3f, 0.0f}, 606);
}

TEST(Distribution1D, LargeChiSquare) {
  // 2000 entries, a third of them zero, weights spanning four decades.
  std::vector<float> weights(2000);
  Rng rng(707);
  for (float& w : weights) w = rng.uniform() < 0.33f ? 0.0f : std::pow(10.0f, 4.0f * rng.uniform());
  discrete_chi2(weights, 708);
}

TEST(Distribution1D, EmptyAndAllZero) {
  EXPECT_EQ(Distribution1D().size(), 0u);
  const std::vector<float> none;
  EXPECT_EQ(Distribution1D(none).size(), 0u);
  const std::vector<float> zeros(5, 0.0f);
  const Distribution1D dist(zeros);
  EXPECT_EQ(dist.size(), 0u);
  EXPECT_EQ(dist.total(), 0.0f);
  EXPECT_EQ(dist.pmf(2), 0.0f);
}

TEST(Distribution1D, EndsOfTheUnitIntervalSkipZeroWeights) {
  const std::vector<float> weights{0.0f, 0.0f, 2.0f, 0.0f, 1.0f, 0.0f, 0.0f};
  const Distribution1D dist(weights);
  EXPECT_EQ(dist.sample(0.0f), 2u);
  EXPECT_EQ(dist.sample(kOneMinusEpsilon), 4u);
  EXPECT_EQ(dist.sample(0.6f), 2u);
  EXPECT_EQ(dist.sample(0.7f), 4u);
  EXPECT_FLOAT_EQ(dist.total(), 3.0f);
  EXPECT_FLOAT_EQ(dist.pmf(2), 2.0f / 3.0f);
}

TEST(Distribution1D, NegativeAndNanWeightsCountAsZero) {
  const std::vector<float> weights{-1.0f, std::nanf(""), 1.0f};
  const Distribution1D dist(weights);
  EXPECT_EQ(dist.total(), 1.0f);
  EXPECT_EQ(dist.sample(0.0f), 2u);
  EXPECT_EQ(dist.pmf(0), 0.0f);
}

}  // namespace
}  // namespace gilt::raytrace_core::util
