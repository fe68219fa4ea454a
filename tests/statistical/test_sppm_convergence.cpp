// SPPM on cornell-caustics approaches the path-traced reference as iterations grow.
//
// Error measure: mean relative error over pixels and channels, |S − P| / (P + 0.01), S the SPPM
// image and P a path-traced reference (two independent halves of 2,048 spp at 32 × 32; their
// own noise n is half the same error between the halves). SPPM's error has a bias that shrinks
// with the radii and a variance that shrinks with the photons gathered; Hachisuka & Jensen (2009)
// show both vanish, so the error must fall with every fourfold increase in iterations (4, 16,
// 64), by more than the reference noise so the fall is not the noise; the slope of log error
// against log iterations, fitted over the three points, is printed and recorded and must be
// negative. (Measured: 0.292, 0.175, 0.114 against a noise of 0.040; slope −0.34.)

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstdio>

#include "raytrace_core/util/image_error.h"
#include "photonmap/sppm.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
namespace pm = gilt::photonmap;

namespace {

constexpr int kSize = 32;

rc::render::RenderSettings settings(int spp, uint64_t seed) {
  rc::render::RenderSettings s;
  s.width = s.height = kSize;
  s.spp = spp;
  s.seed = seed;
  s.progress = false;
  return s;
}

/// A closed icosphere of radius 1 (1,280 facets, facing in), diffuse 0.5, lit by a point light
/// of intensity 1 at `lamp`; not yet committed, so that a test can add to it.
rc::scene::Scene lit_sphere_room(const rc::Vec3& lamp_position) {
  rc::scene::Scene scene;
  scene.materials = {rc::scene::Material::make_diffuse("wall", rc::Rgb(0.5f))};
  rc::scene::TriangleMesh sphere = gilt::test::icosphere(3);
  for (size_t i = 0; i < sphere.indices.size(); i += 3) std::swap(sphere.indices[i + 1], sphere.indices[i + 2]);
  scene.meshes.push_back(std::move(sphere));
  rc::scene::Light lamp;
  lamp.kind = rc::scene::LightKind::point;
  lamp.position = lamp_position;
  lamp.intensity = rc::Rgb(1.0f);
  scene.punctual_lights.push_back(lamp);
  return scene;
}

/// Image means over four independent seeds each: the path tracer at 256 spp (seeds path_seed +
/// 0..3) and SPPM at `iterations` with 20,000 photons each and the initial radius `radius`
/// (seeds sppm_seed + 0..3). Returns the two means and the standard error of their difference.
struct MeanComparison {
  double path, sppm, standard_error;
};

MeanComparison compare_means(const rc::scene::Scene& scene, const rc::scene::Camera& camera, uint64_t path_seed, uint64_t sppm_seed,
                             int iterations, float radius) {
  double path[4], photons[4];
  for (int s = 0; s < 4; ++s) {
    const rc::render::PathSettings ps;
    path[s] = gilt::test::film_mean(
        rc::render::render_image(scene, camera, settings(256, path_seed + s),
                                 [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
                                   return rc::render::path_radiance(scene, ray, ctx, ps);
                                 }));
    pm::SppmSettings sppm;
    sppm.photons_per_iteration = 20000;
    sppm.initial_radius = radius;
    photons[s] = gilt::test::film_mean(pm::render_sppm(scene, camera, settings(iterations, sppm_seed + s), sppm));
  }
  auto mean_and_variance = [](const double* v) {
    const double m = (v[0] + v[1] + v[2] + v[3]) / 4.0;
    double var = 0.0;
    for (int i = 0; i < 4; ++i) var += (v[i] - m) * (v[i] - m) / 3.0;
    return std::pair{m, var / 4.0};  // variance of the mean
  };
  const auto [pm_mean, pm_var] = mean_and_variance(path);
  const auto [sp_mean, sp_var] = mean_and_variance(photons);
  const MeanComparison c{pm_mean, sp_mean, std::sqrt(pm_var + sp_var)};
  std::printf("path %.5f, SPPM %.5f: ratio %.4f (standard error of the difference %.5f)\n", c.path, c.sppm,
              c.sppm / c.path, c.standard_error);
  return c;
}

}  // namespace

TEST(Sppm, ApproachesThePathTracedReference) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
  const rc::scene::Camera camera = scene.effective_camera();
  const rc::render::PathSettings path;
  auto path_render = [&](uint64_t seed) {
    return rc::render::render_image(scene, camera, settings(2048, seed),
                            [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); })
        .pixels();
  };
  const std::vector<rc::Rgb> a = path_render(101), b = path_render(102);
  std::vector<rc::Rgb> reference(a.size());
  for (size_t i = 0; i < a.size(); ++i) reference[i] = (a[i] + b[i]) * 0.5f;
  const double noise = 0.5 * rc::util::mean_relative_error(a, b);

  pm::SppmSettings sppm;
  sppm.photons_per_iteration = 20000;
  const int iterations[] = {4, 16, 64};
  double error[3];
  for (int i = 0; i < 3; ++i) {
    pm::SppmStats stats;
    const rc::render::Film film = pm::render_sppm(scene, camera, settings(iterations[i], 7), sppm, &stats);
    ASSERT_EQ(stats.iterations, iterations[i]);
    ASSERT_EQ(film.non_finite_count(), 0u);
    error[i] = rc::util::mean_relative_error(film.pixels(), reference);
    std::printf("sppm %2d iterations: mean relative error %.4f (reference noise %.4f), mean radius %.3g\n",
                iterations[i], error[i], noise, stats.mean_final_radius);
  }
  // Least-squares slope of log error on log iterations.
  double mx = 0, my = 0;
  for (int i = 0; i < 3; ++i) mx += std::log(iterations[i]) / 3, my += std::log(error[i]) / 3;
  double sxy = 0, sxx = 0;
  for (int i = 0; i < 3; ++i) {
    sxy += (std::log(iterations[i]) - mx) * (std::log(error[i]) - my);
    sxx += (std::log(iterations[i]) - mx) * (std::log(iterations[i]) - mx);
  }
  const double slope = sxy / sxx;
  std::printf("fitted slope of log error against log iterations: %.3f\n", slope);
  RecordProperty("fitted_slope", std::to_string(slope));
  for (int i = 0; i < 3; ++i) RecordProperty("error_" + std::to_string(iterations[i]), std::to_string(error[i]));
  EXPECT_LT(error[1], error[0] - noise);
  EXPECT_LT(error[2], error[1] - noise);
  EXPECT_LT(slope, 0.0);
}

// Inside a closed, tessellated sphere of radius 1 (an icosphere of 1,280 facets, about 7° apart)
// lit by a point light at its centre, with a large gather radius, 0.7: the disk reaches facets
// whose normals turn by up to 41°, all on the same smooth surface, and there is no edge to lose
// photons past. A visible point that turned away the photons of the facets around it while
// counting their area was dark: the 25° test SPPM had before gave 0.943 of the path tracer's
// mean here (bench/README.md, "Šibenik under sun and sky"), 60° gave 0.987; the same 25° test,
// now that the disk's coverage counts only the facets that pass it, gives 0.992.
// Tolerance: 4 standard errors of the difference of the two means (four independent seeds of
// each), plus 3 % for the disk's own bias on a curved surface, which vanishes with the radius:
// - the facets' area within the ball is π r² to 0.2 % (sampled numerically at 20 facets; a
//   sphere's is exactly π r²);
// - a photon on a facet turned by β arrives from below the visible point's tangent plane, where
//   the BSDF is zero, with probability (β − sin β cos β) / π for cosine-distributed directions:
//   about 3 % of the flux over the initial disk (β up to 41°), less as the radius shrinks.
TEST(Sppm, KeepsThePhotonsOfACurvedSurface) {
  rc::scene::Scene scene = lit_sphere_room(rc::Vec3(0.0f));
  scene.commit();
  rc::scene::Camera camera;
  camera.look_from = rc::Vec3(0.0f, 0.0f, 0.5f);
  camera.look_at = rc::Vec3(0.0f, 0.0f, -1.0f);
  camera.vfov_degrees = 60.0f;

  const MeanComparison c = compare_means(scene, camera, 40, 50, 16, 0.7f);
  EXPECT_NEAR(c.sppm, c.path, 4.0 * c.standard_error + 0.03 * c.path);
}

// A plank 0.1 wide inside a closed sphere lit by a point light, seen from just above, gathered
// with an initial radius of 0.3: over the 64 iterations the gather disk holds on average 0.44
// surface, the rest empty air on either side. Dividing the plank's photons by the whole disk's
// area left its reflected light at that share: the image's mean (which also holds the exact
// direct light) came out 0.77 of the path tracer's at 16 iterations. Dividing by the share of the
// disk that the coverage probes find to hold surface (sppm.cpp, probe_coverage) gives 1.0004.
// Tolerance: 4 standard errors of the difference of the two means (four independent seeds of
// each), plus 1 % for what the probes cannot know: the reflected light varies along the ball's
// stretch of plank, and a pixel's coverage is the mean of its 64 stratified probes, whose
// reciprocal is biased up by its relative variance (at 16 iterations, 16 probes, the image came
// out 2 % bright).
TEST(Sppm, DividesByTheSurfaceTheDiskHolds) {
  rc::scene::Scene scene = lit_sphere_room(rc::Vec3(0.0f, 0.6f, 0.0f));
  rc::scene::TriangleMesh plank;
  const float w = 0.05f, l = 0.8f;
  plank.positions = {{-w, 0.0f, -l}, {-w, 0.0f, l}, {w, 0.0f, l}, {w, 0.0f, -l}};
  plank.indices = {0, 1, 2, 0, 2, 3};  // facing +y
  scene.meshes.push_back(std::move(plank));
  scene.commit();
  rc::scene::Camera camera;
  camera.look_from = rc::Vec3(0.0f, 0.3f, 0.0f);
  camera.look_at = rc::Vec3(0.0f);
  camera.up = rc::Vec3(0.0f, 0.0f, -1.0f);
  camera.vfov_degrees = 8.0f;  // ±0.021 of the plank's ±0.05: every pixel sees it

  const MeanComparison c = compare_means(scene, camera, 60, 70, 64, 0.3f);
  EXPECT_NEAR(c.sppm, c.path, 4.0 * c.standard_error + 0.01 * c.path);
}
