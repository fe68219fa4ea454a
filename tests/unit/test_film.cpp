// Film accumulation and reconstruction-filter sampling.

#include "raytrace_core/render/film.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "raytrace_core/util/error.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::render {
namespace {

// ---------------------------------------------------------------------------------------------
// Film

TEST(Film, PixelIsTheMeanOfItsSamples) {
  Film film(3, 2);
  EXPECT_EQ(film.width(), 3);
  EXPECT_EQ(film.height(), 2);
  film.add_sample(2, 1, Rgb(1.0f, 2.0f, 3.0f));
  film.add_sample(2, 1, Rgb(3.0f, 0.0f, 1.0f));
  film.add_sample(0, 0, Rgb(0.5f));
  EXPECT_EQ(film.pixel(2, 1), Rgb(2.0f, 1.0f, 2.0f));
  EXPECT_EQ(film.pixel(0, 0), Rgb(0.5f));
  EXPECT_EQ(film.pixel(1, 0), Rgb());  // no samples: black

  const std::vector<Rgb> pixels = film.pixels();
  ASSERT_EQ(pixels.size(), 6u);
  EXPECT_EQ(pixels[0], Rgb(0.5f));                 // top-left
  EXPECT_EQ(pixels[1 * 3 + 2], film.pixel(2, 1));  // row-major
  EXPECT_EQ(film.non_finite_count(), 0u);
}

TEST(Film, CountsNonFinitePixels) {
  Film film(2, 2);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  film.add_sample(0, 0, Rgb(nan, 0.0f, 0.0f));
  film.add_sample(1, 0, Rgb(0.0f, inf, 0.0f));
  film.add_sample(1, 0, Rgb(1.0f));  // one bad sample spoils the mean
  film.add_sample(0, 1, Rgb(1.0f));
  EXPECT_EQ(film.non_finite_count(), 2u);
}

TEST(Film, DefaultAndEmptyFilms) {
  EXPECT_EQ(Film().pixels().size(), 0u);
  EXPECT_EQ(Film(0, 5).non_finite_count(), 0u);
  EXPECT_THROW(Film(-1, 4), InputError);
}

// ---------------------------------------------------------------------------------------------
// Filter sampling

/// Closed-form 1D CDF of each filter on [-r, r]: the brute-force twin of Filter::sample.
double filter_cdf(FilterKind kind, double x, double r) {
  const double t = std::clamp(x / r, -1.0, 1.0);
  switch (kind) {
    case FilterKind::box:
      return 0.5 * (t + 1.0);
    case FilterKind::tent:
      return t <= 0.0 ? 0.5 * (t + 1.0) * (t + 1.0) : 1.0 - 0.5 * (1.0 - t) * (1.0 - t);
    case FilterKind::gaussian: {
      // σ = r/3, truncated at ±r: x/(σ√2) = 3t/√2.
      const double e = std::erf(3.0 / std::sqrt(2.0));
      return 0.5 * (std::erf(3.0 * t / std::sqrt(2.0)) / e + 1.0);
    }
  }
  return 0.0;
}

/// Uniform float in [0, 1) from the top 24 bits of a 32-bit draw.
float uniform(std::mt19937& rng) { return static_cast<float>(rng() >> 8) * 0x1p-24f; }

/// Upper critical value of χ² with k degrees of freedom at significance level α, given the
/// standard-normal quantile z = Φ⁻¹(1 − α), by the Wilson–Hilferty cube-root approximation
/// (accurate to well under 1% for k ≥ 30, which is far finer than this test needs).
double chi_square_critical(int k, double z) {
  const double a = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - a + z * std::sqrt(a), 3.0);
}

constexpr int kBins = 40;
constexpr int kSamples = 100'000;
// α = 1e-4 per test: z = Φ⁻¹(1 − 1e-4) = 3.7190. With the fixed seed the outcome is fixed; the
// α only says how unlucky a correct sampler would have to be to fail for some other seed.
constexpr double kZ = 3.7190;

/// χ² statistic of the x (axis 0) or y (axis 1) offsets of `filter` against the histogram that
/// `expected_kind` predicts on kBins equal bins over [-r, r].
double chi_square(const Filter& filter, FilterKind expected_kind, int axis, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<int> histogram(kBins, 0);
  const float r = filter.radius;
  for (int i = 0; i < kSamples; ++i) {
    const Vec2 u(uniform(rng), uniform(rng));
    const float x = filter.sample(u)[axis];
    const int bin = std::clamp(static_cast<int>((x + r) / (2.0f * r) * kBins), 0, kBins - 1);
    ++histogram[bin];
  }
  double chi2 = 0.0;
  for (int b = 0; b < kBins; ++b) {
    const double lo = -r + 2.0 * r * b / kBins, hi = -r + 2.0 * r * (b + 1) / kBins;
    const double expected = kSamples * (filter_cdf(expected_kind, hi, r) - filter_cdf(expected_kind, lo, r));
    EXPECT_GE(expected, 5.0) << "bin " << b << " too small for the χ² approximation";
    chi2 += (histogram[b] - expected) * (histogram[b] - expected) / expected;
  }
  return chi2;
}

const FilterKind kKinds[] = {FilterKind::box, FilterKind::tent, FilterKind::gaussian};

TEST(Filter, SamplesStayWithinTheRadius) {
  for (FilterKind kind : kKinds) {
    for (float radius : {0.5f, 1.0f, 1.5f, 2.5f}) {
      const Filter filter{kind, radius};
      for (int i = 0; i <= 64; ++i) {
        for (int j = 0; j <= 64; ++j) {
          const Vec2 u(std::min(i / 64.0f, kOneMinusEpsilon), std::min(j / 64.0f, kOneMinusEpsilon));
          const Vec2 offset = filter.sample(u);
          ASSERT_LE(std::fabs(offset.x), radius) << int(kind) << " u=" << u.x;
          ASSERT_LE(std::fabs(offset.y), radius) << int(kind) << " u=" << u.y;
        }
      }
    }
  }
}

TEST(Filter, ZeroRadiusGivesThePixelCentre) {
  for (FilterKind kind : kKinds) {
    const Vec2 offset = Filter{kind, 0.0f}.sample(Vec2(0.3f, 0.9f));
    EXPECT_EQ(offset.x, 0.0f);
    EXPECT_EQ(offset.y, 0.0f);
  }
}

// Sampling inverts the CDF, so F(sample(u)) must give u back. Rounding the offset to float moves
// it by at most 2⁻²⁴·r, which moves F by at most that times the largest density (1.2/r for the
// gaussian): under 1e-7. The 1e-6 tolerance leaves room for the erf⁻¹ approximation's error.
TEST(Filter, SampleInvertsTheClosedFormCdf) {
  for (FilterKind kind : kKinds) {
    const Filter filter{kind, 1.5f};
    for (int i = 0; i <= 1000; ++i) {
      const float u = std::min(i / 1000.0f, kOneMinusEpsilon);
      const double x = filter.sample(Vec2(u, 0.5f)).x;
      EXPECT_NEAR(filter_cdf(kind, x, filter.radius), u, 1e-6) << int(kind) << " u=" << u;
    }
  }
}

TEST(Filter, GaussianIsSymmetricAndDeterministic) {
  const Filter filter{FilterKind::gaussian, 2.0f};
  EXPECT_EQ(filter.sample(Vec2(0.5f)).x, 0.0f);
  EXPECT_NEAR(filter.sample(Vec2(0.0f)).x, -2.0f, 1e-4f);
  EXPECT_NEAR(filter.sample(Vec2(kOneMinusEpsilon)).x, 2.0f, 1e-4f);
  for (float u : {0.01f, 0.2f, 0.37f, 0.49f}) {
    EXPECT_NEAR(filter.sample(Vec2(u)).x, -filter.sample(Vec2(1.0f - u)).x, 1e-5f);
    EXPECT_EQ(filter.sample(Vec2(u, 0.7f)), filter.sample(Vec2(u, 0.7f)));
  }
}

TEST(Filter, HistogramsMatchTheFilterShape) {
  const double threshold = chi_square_critical(kBins - 1, kZ);
  for (FilterKind kind : kKinds) {
    const Filter filter{kind, 1.5f};
    for (int axis = 0; axis < 2; ++axis) {
      EXPECT_LT(chi_square(filter, kind, axis, 1234 + axis), threshold) << int(kind) << " axis " << axis;
    }
  }
}

// The test has power: with these sample counts it tells each shape from its nearest rival of
// the same radius.
TEST(Filter, ChiSquareRejectsTheWrongShape) {
  const double threshold = chi_square_critical(kBins - 1, kZ);
  EXPECT_GT(chi_square(Filter{FilterKind::gaussian, 1.5f}, FilterKind::tent, 0, 99), threshold);
  EXPECT_GT(chi_square(Filter{FilterKind::tent, 1.5f}, FilterKind::gaussian, 0, 99), threshold);
  EXPECT_GT(chi_square(Filter{FilterKind::box, 1.5f}, FilterKind::tent, 0, 99), threshold);
}

// Every sample has weight 1: the filter is importance-sampled, so a pixel is the plain mean of
// its samples and converges to the filter-weighted mean of the radiance. An orthographic camera
// over a step (radiance 1 left of x = 0, 0 right of it) gives pixel px, centred 3.5 − px pixels
// left of the step, the filter's CDF there, F(3.5 − px). With n independent samples the error's
// standard deviation is √(F(1 − F)/n), and the test allows four; with Sobol samples the film
// offsets' x coordinates fall one in each 1/n of [0, 1), so the count of samples left of the
// step is nF rounded up or down, and the error is at most 1/n.
TEST(Filter, PixelsAreFilterWeightedMeansOfUnitWeightSamples) {
  scene::Scene scene;
  scene.commit();
  scene::Camera camera;
  camera.look_from = Vec3(0.0f, 0.0f, 1.0f);
  camera.look_at = Vec3(0.0f);
  camera.up = Vec3(0.0f, 1.0f, 0.0f);
  camera.orthographic = true;
  camera.ortho_height = 1.0f;  // 8 × 1 pixels: one scene unit per pixel, x = px + 0.5 − 4 at the centre
  constexpr int kSpp = 1024;
  for (FilterKind kind : kKinds) {
    for (SamplerKind sampler : {SamplerKind::sobol, SamplerKind::independent}) {
      RenderSettings settings;
      settings.width = 8, settings.height = 1, settings.spp = kSpp, settings.progress = false;
      settings.filter = Filter{kind, 1.5f};
      settings.sampler = sampler;
      const Film film = render_image(scene, camera, settings, [](const scene::Ray& ray, SampleContext&) {
        return Rgb(ray.origin.x < 0.0f ? 1.0f : 0.0f);
      });
      for (int px = 1; px <= 6; ++px) {
        const double f = filter_cdf(kind, 3.5 - px, 1.5);
        const double bound = sampler == SamplerKind::sobol ? 1.0 / kSpp + 1e-6 : 4.0 * std::sqrt(f * (1.0 - f) / kSpp) + 1e-6;
        EXPECT_NEAR(film.pixel(px, 0).r, f, bound) << "filter " << int(kind) << ", " << sampler_name(sampler) << ", pixel " << px;
      }
    }
  }
}

TEST(Filter, ParsesNames) {
  EXPECT_EQ(Filter::parse("box"), FilterKind::box);
  EXPECT_EQ(Filter::parse("tent"), FilterKind::tent);
  EXPECT_EQ(Filter::parse("gaussian"), FilterKind::gaussian);
  for (const char* bad : {"", "Box", "mitchell", "gauss"}) {
    try {
      Filter::parse(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()),
                "unknown filter '" + std::string(bad) + "' (expected box, tent or gaussian)");
    }
  }
}

}  // namespace
}  // namespace gilt::raytrace_core::render
