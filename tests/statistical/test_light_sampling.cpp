// Chi-square tests of light sampling (raytrace_core/scene/light.h): the directions sample_light draws
// from a reference point must be distributed as light_pdf says, and light_pdf must agree with the
// pdf the sample reports. Method and significance as in chi2.h: α = 0.01 Šidák-corrected over the
// kChi2Tests tests of this program, 10⁶ samples from fixed seeds.
//
// light_pdf is the density the integrator uses after a BSDF-sampled ray hits the light, so the
// density of a direction here is light_pdf at the point the scene's own ray query finds along
// it, and zero when the ray misses the light: Embree is the brute-force twin of the sampler's
// geometry. Grids are in a frame whose pole points at the light, over a cap slightly larger than
// the light's silhouette; the silhouette edge crosses cells, which are integrated adaptively.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

#include "raytrace_core/util/error.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/scene/scene.h"
#include "tests/statistical/chi2.h"

namespace gilt::raytrace_core::scene {
namespace {

// triangle (solid angle; oblique and close; tiny and far, by area), near sphere, far sphere, sphere
// from inside, environment, environment map (turned and not), environment about a receiving side
constexpr int kChi2Tests = 10;
constexpr size_t kSamples = 1000000;
// Silhouette edges cross cells: 2 × 2 sub-cells per cell, each refined adaptively 5 times, leave
// an integration error of a few 1e-6 of the total (measured against finer settings), i.e. a few
// samples in all out of 10⁶, spread over ~1000 cells whose counts fluctuate by ±sqrt(count).
constexpr int kSub = 2, kAdaptiveDepth = 5;
const double kAlpha = test::sidak_alpha(test::kFamilyAlpha, kChi2Tests);

Scene one_light_scene(std::vector<TriangleMesh> meshes, std::vector<Sphere> spheres,
                      std::vector<Light> punctual) {
  Scene scene;
  scene.name = "light-sampling";
  scene.materials = {Material::make_emitter("lamp", Rgb(4.0f, 3.0f, 2.0f))};
  scene.meshes = std::move(meshes);
  scene.spheres = std::move(spheres);
  scene.punctual_lights = std::move(punctual);
  scene.commit();
  return scene;
}

SurfacePoint reference_point(const Vec3& p, const Vec3& ng) {
  SurfacePoint ref;
  ref.p = p;
  ref.ng = glm::normalize(ng);
  return ref;
}

// Density of direction wi (world, unit) as the integrator would evaluate it after tracing a ray.
float traced_light_pdf(const Scene& scene, const Light& light, const SurfacePoint& ref, const Vec3& wi) {
  if (light.kind == LightKind::environment) return light_pdf(scene, light, ref, wi, SurfacePoint{});
  const Ray ray = spawn_ray(ref, wi);
  const std::optional<Hit> hit = scene.intersect(ray);
  if (!hit || hit->geom_id != light.geom_id || hit->prim_id != light.prim_id) return 0.0f;
  return light_pdf(scene, light, ref, wi, scene.surface(ray, *hit));
}

// Chi-square test of sample_light against traced_light_pdf on `grid`, expressed in `frame`.
// Every grid below covers the light's whole support, and sample_light never fails, so the remainder
// cell expects no samples (outside_mass = 0) rather than what the numerical integral leaves over.
void expect_light_follows_pdf(const Scene& scene, const SurfacePoint& ref, const Frame& frame,
                              const test::DirectionGrid& grid, uint64_t seed, bool adaptive) {
  ASSERT_EQ(scene.lights().size(), 1u);
  const Light& light = scene.lights()[0];
  const auto r = test::chi2_directions(
      grid, kSamples, seed,
      [&](util::Rng& rng) -> std::optional<Vec3> {
        const LightSample ls = sample_light(scene, light, ref, rng.uniform2());
        if (!(ls.pdf > 0.0f)) return std::nullopt;
        return frame.to_local(ls.wi);
      },
      [&](const Vec3& local) {
        return traced_light_pdf(scene, light, ref, glm::normalize(frame.to_world(local)));
      },
      kAlpha, adaptive ? kSub : 3, adaptive ? kAdaptiveDepth : 0, 0.0);
  test::expect_chi2_pass(r);
}

// light_pdf at the point a ray finds along the sampled direction equals the sample's pdf. Both are
// d²/(A |cos θl|) (or a constant) from points that differ by the float rounding of the hit point,
// a few ulps of coordinates ≤ 25 at distances ≥ 2, with |cos θl| ≥ 0.2 here: relative error of
// order 1e-5 at worst, so 1e-4 is a bound with margin, not a fit.
void expect_pdf_matches_sample(const Scene& scene, const SurfacePoint& ref, uint64_t seed) {
  const Light& light = scene.lights()[0];
  util::Rng rng(seed);
  int compared = 0;
  for (int k = 0; k < 20000; ++k) {
    const LightSample ls = sample_light(scene, light, ref, rng.uniform2());
    ASSERT_GT(ls.pdf, 0.0f);
    ASSERT_FALSE(ls.delta);
    ASSERT_NEAR(glm::length(ls.wi), 1.0f, 1e-5f);
    const float traced = traced_light_pdf(scene, light, ref, ls.wi);
    if (traced == 0.0f) continue;  // ray grazed past the silhouette: counted below
    ++compared;
    ASSERT_NEAR(traced / ls.pdf, 1.0f, 1e-4f) << "sample " << k;
  }
  // Misses happen only for directions within rounding of the silhouette; far fewer than 1 in 1000.
  EXPECT_GE(compared, 20000 - 20);
}

// Pole of a grid pointing from ref towards `target`.
Frame frame_towards(const SurfacePoint& ref, const Vec3& target) {
  return Frame::from_normal(glm::normalize(target - ref.p));
}

TEST(LightSampling, EmissiveTriangle) {
  TriangleMesh mesh;
  mesh.name = "lamp";
  mesh.positions = {{-1.0f, 2.0f, -0.5f}, {0.2f, 2.5f, 1.4f}, {1.5f, 2.2f, 0.3f}};
  mesh.indices = {0, 1, 2};
  const Scene scene = one_light_scene({mesh}, {}, {});
  const SurfacePoint ref = reference_point({0.1f, -0.2f, 0.05f}, {0.1f, 1.0f, 0.0f});
  const Vec3 centroid = (mesh.positions[0] + mesh.positions[1] + mesh.positions[2]) / 3.0f;
  const Frame frame = frame_towards(ref, centroid);
  double theta_bound = 0.0;  // widest vertex angle from the pole; the cap is 5% wider
  for (const Vec3& v : mesh.positions)
    theta_bound = std::max(
        theta_bound, std::acos(std::clamp(double(frame.to_local(glm::normalize(v - ref.p)).z), -1.0, 1.0)));
  ASSERT_GT(triangle_light_solid_angle(scene, scene.lights()[0], ref.p), 0.0);  // close: by solid angle
  expect_light_follows_pdf(scene, ref, frame, test::theta_grid(32, 64, 1.05 * theta_bound), 11, true);
  expect_pdf_matches_sample(scene, ref, 12);
}

/// A one-triangle light with corners `c`, tested from `p` (normal towards the triangle) by chi-square
/// and by the pdf at traced hits; `by_solid_angle` says which of light.cpp's two strategies the
/// configuration must exercise.
void triangle_light_case(const std::array<Vec3, 3>& c, const Vec3& p, bool by_solid_angle, uint64_t seed) {
  TriangleMesh mesh;
  mesh.name = "lamp";
  mesh.positions = {c[0], c[1], c[2]};
  mesh.indices = {0, 1, 2};
  const Scene scene = one_light_scene({mesh}, {}, {});
  const Vec3 centroid = (c[0] + c[1] + c[2]) / 3.0f;
  ASSERT_EQ(triangle_light_solid_angle(scene, scene.lights()[0], p) > 0.0, by_solid_angle);
  const SurfacePoint ref = reference_point(p, centroid - p);
  const Frame frame = frame_towards(ref, centroid);
  double theta_bound = 0.0;
  for (const Vec3& v : c)
    theta_bound = std::max(theta_bound, std::acos(std::clamp(double(frame.to_local(glm::normalize(v - p)).z), -1.0, 1.0)));
  expect_light_follows_pdf(scene, ref, frame, test::theta_grid(32, 64, 1.05 * theta_bound), seed, true);
  expect_pdf_matches_sample(scene, ref, seed + 1);
}

// Beside a ceiling lamp, a little below its plane: the lamp is seen nearly edge on, close by,
// where area sampling's density d²/cos θ would vary most across it.
TEST(LightSampling, EmissiveTriangleObliqueAndClose) {
  triangle_light_case({Vec3(-0.5f, 2.0f, -0.5f), Vec3(0.5f, 2.0f, -0.5f), Vec3(0.0f, 2.0f, 0.6f)}, Vec3(0.9f, 1.8f, 0.1f),
                      true, 21);
}

// Small and far: sampled by area, where the two densities agree to rounding.
TEST(LightSampling, EmissiveTriangleTinyAndFar) {
  triangle_light_case({Vec3(-0.01f, 20.0f, 0.0f), Vec3(0.01f, 20.0f, 0.0f), Vec3(0.0f, 20.0f, 0.015f)},
                      Vec3(0.3f, 0.0f, 0.2f), false, 31);
}

// Sphere light seen from outside: the cone it subtends, half-angle asin(r / d), cap 1% wider.
void sphere_from_outside(const Vec3& center, float radius, const Vec3& ref_p, uint64_t seed) {
  const Scene scene = one_light_scene({}, {Sphere{center, radius, 0}}, {});
  const SurfacePoint ref = reference_point(ref_p, center - ref_p);
  const double theta_max = std::asin(radius / glm::length(DVec3(center) - DVec3(ref_p)));
  expect_light_follows_pdf(scene, ref, frame_towards(ref, center), test::theta_grid(32, 64, 1.01 * theta_max),
                           seed, true);
  expect_pdf_matches_sample(scene, ref, seed + 1);
}

TEST(LightSampling, EmissiveSphereNear) {
  sphere_from_outside({0.5f, -3.0f, 0.8f}, 1.0f, {0.2f, 0.1f, -0.1f}, 21);
}

TEST(LightSampling, EmissiveSphereSmallAndFar) {
  // Distance 19.65, half-angle 2.5e-3 rad: 1 − cos θmax ≈ 3.2e-6, about 54 float steps below 1.
  // A sampler that takes sin θ from 1 − cos²θ in float quantises θ into ~54 rings and puts ~1% of
  // the samples exactly on the axis; sin θ must come from 1 − cos θ itself.
  sphere_from_outside({3.0f, 19.0f, -4.0f}, 0.05f, {0.0f, 0.0f, 0.0f}, 31);
}

TEST(LightSampling, EmissiveSphereFromInside) {
  const Vec3 center{0.3f, -0.2f, 0.5f};
  const Scene scene = one_light_scene({}, {Sphere{center, 2.0f, 0}}, {});
  const SurfacePoint ref = reference_point(center + Vec3(0.7f, 0.4f, -0.9f), {0.0f, 0.0f, 1.0f});
  expect_light_follows_pdf(scene, ref, Frame::from_normal({0.0f, 0.0f, 1.0f}), test::sphere_grid(32, 64), 41,
                           false);
  expect_pdf_matches_sample(scene, ref, 42);
}

// An environment map of 16 × 8 texels: a dim gradient, a bright "sun" texel, black texels (which
// must never be drawn) and one row entirely black.
std::shared_ptr<const EnvironmentMap> test_map(float rotate_degrees) {
  constexpr int kW = 16, kH = 8;
  std::vector<Rgb> texels(size_t(kW * kH));
  for (int row = 0; row < kH; ++row)
    for (int col = 0; col < kW; ++col)
      texels[size_t(row * kW + col)] = Rgb(0.1f + 0.05f * float(col), 0.2f, 0.05f * float(row + 1));
  texels[size_t(2 * kW + 11)] = Rgb(500.0f, 450.0f, 400.0f);
  for (int col = 0; col < kW; col += 3) texels[size_t(5 * kW + col)] = Rgb(0.0f);
  for (int col = 0; col < kW; ++col) texels[size_t(7 * kW + col)] = Rgb(0.0f);
  return std::make_shared<const EnvironmentMap>(kW, kH, texels, 2.0f, rotate_degrees);
}

// A scene lit by an environment light alone: constant radiance L, or a map.
Scene environment_scene(std::shared_ptr<const EnvironmentMap> map, Rgb radiance = Rgb(1.0f)) {
  Light env;
  env.kind = LightKind::environment;
  env.radiance = radiance;
  env.map = std::move(map);
  // Geometry only so that the scene has bounds, a unit cube; never in the way.
  TriangleMesh far_away;
  far_away.positions = {{100.0f, 100.0f, 100.0f}, {101.0f, 100.0f, 100.0f}, {100.0f, 101.0f, 101.0f}};
  far_away.indices = {0, 1, 2};
  Scene scene;
  scene.materials = {Material::make_diffuse("grey", Rgb(0.5f))};
  scene.meshes = {far_away};
  scene.punctual_lights = {env};
  scene.commit();
  return scene;
}

// The map's texels are cells of θ (from +y) and φ = atan2(x, −z); in the frame below (pole +y,
// local x = −z, local y = +x) they are cells of the grid's own θ and φ, and with 48 × 96 rows and
// columns every texel edge is a grid edge when the map is not turned, so the piecewise-constant
// density is integrated exactly. Turned by 30°, texel edges cross cells: adaptive integration.
const Frame kYUp{Vec3(0.0f, 0.0f, -1.0f), Vec3(1.0f, 0.0f, 0.0f), Vec3(0.0f, 1.0f, 0.0f)};

TEST(LightSampling, EnvironmentMap) {
  for (float turn : {0.0f, 30.0f}) {
    const Scene scene = environment_scene(test_map(turn));
    const Light& light = scene.lights()[0];
    const SurfacePoint ref = reference_point({0.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f});
    expect_light_follows_pdf(scene, ref, kYUp, test::theta_grid(48, 96), 61 + uint64_t(turn), turn != 0.0f);
    util::Rng rng(62);
    for (int k = 0; k < 20000; ++k) {
      const LightSample ls = sample_light(scene, light, ref, rng.uniform2());
      ASSERT_GT(ls.pdf, 0.0f);
      ASSERT_NEAR(glm::length(ls.wi), 1.0f, 1e-5f);
      // The texel a direction falls in is found again from the direction: equal, except for a
      // direction within rounding of a texel edge (a few in 10⁴ at most).
      const float pdf = light_pdf(scene, light, ref, ls.wi, SurfacePoint{});
      if (pdf != ls.pdf) continue;
      ASSERT_EQ(ls.radiance, environment_radiance(light, ls.wi));
      ASSERT_FALSE(ls.radiance.is_black()) << "a black texel was drawn";
    }
  }
}

// Photons from an environment map (sample_emission) deliver the map's irradiance: the power
// crossing a small horizontal square from above, per unit area, against ∫ L(w) max(0, w_y) dω
// by quadrature over the map (each texel's radiance times the exact integral of w_y over its
// cell). Within 4 standard errors of the photon estimate, taken from the photons' own spread.
TEST(LightSampling, EnvironmentMapPhotonsDeliverItsIrradiance) {
  const auto map = test_map(30.0f);
  const Scene scene = environment_scene(map);
  const Light& light = scene.lights()[0];
  double expected = 0.0;
  const int w = map->width(), h = map->height();
  for (int row = 0; row < h; ++row) {
    // ∫ cos θ dω over the cell, θ from +y: (sin² θ1 − sin² θ0)/2 · Δφ, zero below the horizon.
    const double t0 = std::numbers::pi * row / h, t1 = std::numbers::pi * (row + 1) / h;
    if (t0 >= 0.5 * std::numbers::pi) continue;
    const double t1c = std::min(t1, 0.5 * std::numbers::pi);
    const double cell = 0.5 * (std::pow(std::sin(t1c), 2) - std::pow(std::sin(t0), 2)) * 2.0 * std::numbers::pi / w;
    for (int col = 0; col < w; ++col) expected += double(map->texels()[size_t(row * w + col)].g) * cell;
  }
  util::Rng rng(71);
  constexpr int kN = 2000000;
  double sum = 0.0, sum_sq = 0.0;
  for (int k = 0; k < kN; ++k) {
    const EmissionSample es = sample_emission(scene, light, rng.uniform2(), rng.uniform2());
    double e = 0.0;
    // The square: 0.4 × 0.4 of the plane y = 100.5 through the scene's centre, inside its
    // bounding box, so every line through it crosses the box's outline that photons start on.
    if (es.ray.direction.y < 0.0f && es.ray.origin.y > 100.5f) {
      const float t = (100.5f - es.ray.origin.y) / es.ray.direction.y;
      const Vec3 p = es.ray.origin + t * es.ray.direction;
      if (std::fabs(p.x - 100.5f) < 0.2f && std::fabs(p.z - 100.5f) < 0.2f) e = es.power.g / 0.16;
    }
    sum += e;
    sum_sq += e * e;
  }
  const double mean = sum / kN, error = std::sqrt(std::max(0.0, sum_sq / kN - mean * mean) / (kN - 1));
  std::printf("    [photons] irradiance %.5f ± %.5f, quadrature %.5f\n", mean, error, expected);
  EXPECT_NEAR(mean, expected, 4.0 * error);
}

TEST(LightSampling, EnvironmentMapOrientation) {
  // Top row up, bottom row down, centre column along −z, u = 3/4 along +x; turning by 90° about
  // +y brings what was along −z to −x (right-handed: −z turns towards −x).
  constexpr int kW = 4, kH = 2;
  std::vector<Rgb> texels(size_t(kW * kH));
  for (int i = 0; i < kW * kH; ++i) texels[size_t(i)] = Rgb(float(i + 1));
  const EnvironmentMap map(kW, kH, texels);
  const auto at = [&](const EnvironmentMap& m, Vec3 w) { return m.radiance(glm::normalize(w)).r; };
  EXPECT_EQ(at(map, {0.1f, 1.0f, -0.1f}), 3.0f);     // upper row, u ∈ [1/2, 3/4): column 2
  EXPECT_EQ(at(map, {0.0f, 0.2f, -1.0f}) , 3.0f);    // just right of −z, upper half
  EXPECT_EQ(at(map, {-0.01f, 0.2f, -1.0f}), 2.0f);   // just left of −z: column 1
  EXPECT_EQ(at(map, {1.0f, -0.2f, 0.01f}), 8.0f);    // +x, lower half, u just past 3/4: column 3
  EXPECT_EQ(at(map, {-0.01f, -0.3f, 1.0f}), 5.0f);   // just left of +z, lower row: u ≈ 0, column 0
  EXPECT_EQ(at(map, {0.01f, -0.3f, 1.0f}), 8.0f);    // just right of +z: u ≈ 1, column 3 (the seam)
  const EnvironmentMap turned(kW, kH, texels, 1.0f, 90.0f);
  EXPECT_EQ(at(turned, {-1.0f, 0.2f, -0.01f}), 3.0f);  // just right of −z's texel, now seen towards −x
  // Mean radiance: each row's four texels have equal solid angle; the two rows are hemispheres.
  EXPECT_NEAR(map.mean_radiance().r, (1 + 2 + 3 + 4 + 5 + 6 + 7 + 8) / 8.0f, 1e-5f);
  // Black or broken maps: nothing to sample, or a clear error.
  const EnvironmentMap black(kW, kH, std::vector<Rgb>(size_t(kW * kH), Rgb(0.0f)));
  EXPECT_EQ(black.sample({0.5f, 0.5f}).pdf, 0.0f);
  EXPECT_EQ(black.pdf({0.0f, 1.0f, 0.0f}), 0.0f);
  std::vector<Rgb> nan = texels;
  nan[3] = Rgb(std::nanf(""));
  EXPECT_THROW(EnvironmentMap(kW, kH, nan), InputError);
  EXPECT_THROW(EnvironmentMap(kW, kH, texels, -1.0f), InputError);
  EXPECT_THROW(EnvironmentMap(kW, kH + 1, texels), InputError);
}

TEST(LightSampling, ConstantEnvironment) {
  const Scene scene = environment_scene(nullptr, Rgb(0.5f));
  const Light& env = scene.lights()[0];
  ASSERT_EQ(scene.lights().size(), 1u);
  const SurfacePoint ref = reference_point({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f});
  expect_light_follows_pdf(scene, ref, Frame{}, test::sphere_grid(32, 64), 51, false);
  util::Rng rng(52);
  for (int k = 0; k < 1000; ++k) {
    const LightSample ls = sample_light(scene, scene.lights()[0], ref, rng.uniform2());
    ASSERT_EQ(ls.pdf, light_pdf(scene, scene.lights()[0], ref, ls.wi, SurfacePoint{}));
    ASSERT_EQ(ls.radiance, env.radiance);
  }
}

// Given the receiving side, a constant environment is drawn by the cosine about it. Chi-square of
// the directions against light_pdf with the same side, over the whole sphere (the cells below the
// horizon expect none, and pool). Each sample then carries a Lambertian receiver's irradiance
// exactly: L cos θ / pdf = π L, up to float rounding of the cosine (relative 1e-5 is some tens of
// ulps). Without a side, sampling is over the sphere, as before.
TEST(LightSampling, ConstantEnvironmentAboutTheReceivingSide) {
  const Scene scene = environment_scene(nullptr, Rgb(0.5f));
  const Light& env = scene.lights()[0];
  ASSERT_TRUE(is_constant_environment(env));
  const Vec3 n = glm::normalize(Vec3(0.3f, -0.5f, 0.8f));
  const SurfacePoint ref = reference_point({0.0f, 0.0f, 0.0f}, n);
  const auto r = test::chi2_directions(
      test::sphere_grid(32, 64), kSamples, 53,
      [&](util::Rng& rng) -> std::optional<Vec3> {
        const LightSample ls = sample_light(scene, env, ref, rng.uniform2(), n);
        if (!(ls.pdf > 0.0f)) return std::nullopt;
        return Frame::from_normal(n).to_local(ls.wi);
      },
      [&](const Vec3& local) {
        return light_pdf(scene, env, ref, glm::normalize(Frame::from_normal(n).to_world(local)), SurfacePoint{}, n);
      },
      kAlpha, 3, 0, 0.0);
  test::expect_chi2_pass(r);
  util::Rng rng(54);
  for (int k = 0; k < 10000; ++k) {
    const LightSample ls = sample_light(scene, env, ref, rng.uniform2(), n);
    if (!(ls.pdf > 0.0f)) continue;  // on the horizon: nothing drawn
    ASSERT_EQ(ls.pdf, light_pdf(scene, env, ref, ls.wi, SurfacePoint{}, n));
    ASSERT_EQ(ls.radiance, env.radiance);
    ASSERT_NEAR(ls.radiance.g * glm::dot(ls.wi, n) / ls.pdf, kPi * env.radiance.g, 1e-5f * kPi * env.radiance.g);
  }
  const LightSample any = sample_light(scene, env, ref, Vec2(0.3f, 0.9f));
  EXPECT_EQ(any.pdf, util::uniform_sphere_pdf());
}

}  // namespace
}  // namespace gilt::raytrace_core::scene
