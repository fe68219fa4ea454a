// White furnace: inside a closed box whose walls all emit Le and reflect with albedo ρ, the
// radiance is Le / (1 − ρ) in every direction. Every pixel of a path-traced image must agree,
// also with a glass and a mirror sphere inside (they neither create nor destroy energy).
//
// Tolerance: each pixel is estimated K = 16 times independently (different seeds, N/K samples
// each). The mean of the K estimates must lie within t·s/√K of the answer, where s is their
// sample standard deviation and t the two-sided Student-t quantile (K − 1 degrees of freedom) at
// the Šidák-corrected level α = 1e-3 over all pixels, channels and settings. The seeds are
// fixed, so the test is deterministic; its bound comes from the estimator's own variance.

#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <cmath>

#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;

namespace {

constexpr int kSize = 12;    // pixels per side
constexpr int kRuns = 16;    // independent estimates per pixel
constexpr int kSppPerRun = 16;
constexpr int kSettings = 8; // test cases sharing the significance level

/// t such that P(|T| > t) over every pixel, channel and setting stays below α = 1e-3 (Šidák).
double critical_t() {
  const double tests = double(kSize) * kSize * 3 * kSettings;
  const double alpha_each = 1.0 - std::pow(1.0 - 1e-3, 1.0 / tests);
  return boost::math::quantile(boost::math::complement(boost::math::students_t(kRuns - 1), alpha_each / 2.0));
}

void expect_furnace(rc::scene::Scene& scene, float le, float rho, const char* what) {
  scene.commit();
  const double expected = le / (1.0 - rho);
  const rc::render::PathSettings path;
  const rc::scene::Camera camera = scene.effective_camera();
  auto radiance = [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); };

  const size_t values = size_t(kSize) * kSize * 3;
  std::vector<double> sum(values, 0.0), sum2(values, 0.0);
  for (int run = 0; run < kRuns; ++run) {
    rc::render::RenderSettings settings;
    settings.width = settings.height = kSize;
    settings.spp = kSppPerRun;
    settings.seed = 100 + run;
    settings.progress = false;
    rc::render::RenderStats stats;
    const rc::render::Film film = rc::render::render_image(scene, camera, settings, radiance, &stats);
    ASSERT_EQ(stats.non_finite, 0u);
    const std::vector<rc::Rgb> px = film.pixels();
    for (size_t i = 0; i < px.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        sum[3 * i + k] += px[i][k];
        sum2[3 * i + k] += double(px[i][k]) * px[i][k];
      }
  }
  const double t = critical_t();
  int bad = 0;
  double worst = 0.0;
  for (size_t i = 0; i < values; ++i) {
    const double mean = sum[i] / kRuns;
    const double var = std::max(0.0, (sum2[i] - kRuns * mean * mean) / (kRuns - 1));
    // Floor: float accumulation of 16 samples is exact to ~1e-6 relative.
    const double tol = t * std::sqrt(var / kRuns) + 1e-5 * expected;
    worst = std::max(worst, std::abs(mean - expected) / tol);
    if (std::abs(mean - expected) > tol && bad++ < 5)
      ADD_FAILURE() << what << " rho=" << rho << ": pixel " << i / 3 << " channel " << i % 3 << " = " << mean
                    << ", expected " << expected << " +- " << tol;
  }
  EXPECT_EQ(bad, 0) << what << " rho=" << rho;
  ::testing::Test::RecordProperty("worst_error_over_tolerance", std::to_string(worst));
}

}  // namespace

class Furnace : public ::testing::TestWithParam<float> {};

TEST_P(Furnace, EmptyBoxGivesLeOverOneMinusRho) {
  const float le = 0.5f, rho = GetParam();
  rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
  expect_furnace(scene, le, rho, "empty furnace");
}

TEST_P(Furnace, GlassAndMirrorSpheresConserveEnergy) {
  const float le = 0.5f, rho = GetParam();
  rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
  // Spheres in front of the camera, sized from the box so the test holds for any furnace size.
  const rc::Bounds3 b = [&] {
    rc::Bounds3 bb;
    for (const auto& m : scene.meshes)
      for (const auto& p : m.positions) bb.extend(p);
    return bb;
  }();
  const float r = 0.15f * b.diagonal().x;
  const uint32_t glass = uint32_t(scene.materials.size());
  scene.materials.push_back(rc::scene::Material::make_dielectric("glass", 1.5f));
  scene.materials.push_back(rc::scene::Material::make_mirror("mirror", rc::Rgb(1.0f)));
  const rc::scene::Camera cam = scene.effective_camera();
  const rc::Vec3 forward = glm::normalize(cam.look_at - cam.look_from);
  const rc::Vec3 side = glm::normalize(glm::cross(forward, cam.up));
  const rc::Vec3 centre = cam.look_from + forward * (2.5f * r);
  scene.spheres.push_back({centre - side * (1.1f * r), r, glass});
  scene.spheres.push_back({centre + side * (1.1f * r), r, glass + 1});
  expect_furnace(scene, le, rho, "furnace with glass and mirror");
}

INSTANTIATE_TEST_SUITE_P(Albedo, Furnace, ::testing::Values(0.5f, 0.8f, 0.9f, 0.95f));
