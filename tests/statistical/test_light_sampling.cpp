// Chi-square tests of light sampling (raytrace_core/light.h): the directions sample_light draws
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
#include <optional>

#include "raytrace_core/light.h"
#include "raytrace_core/rng.h"
#include "raytrace_core/scene.h"
#include "tests/statistical/chi2.h"

namespace gilt::raytrace_core {
namespace {

constexpr int kChi2Tests = 5;  // triangle, near sphere, far sphere, sphere from inside, environment
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
      [&](Rng& rng) -> std::optional<Vec3> {
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
  Rng rng(seed);
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
  expect_light_follows_pdf(scene, ref, frame, test::theta_grid(32, 64, 1.05 * theta_bound), 11, true);
  expect_pdf_matches_sample(scene, ref, 12);
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

TEST(LightSampling, ConstantEnvironment) {
  Light env;
  env.kind = LightKind::environment;
  env.radiance = Rgb(0.5f);
  TriangleMesh far_away;  // geometry only so that the scene has bounds; never in the way
  far_away.positions = {{100.0f, 100.0f, 100.0f}, {101.0f, 100.0f, 100.0f}, {100.0f, 101.0f, 100.0f}};
  far_away.indices = {0, 1, 2};
  Scene scene;
  scene.materials = {Material::make_diffuse("grey", Rgb(0.5f))};
  scene.meshes = {far_away};
  scene.punctual_lights = {env};
  scene.commit();
  ASSERT_EQ(scene.lights().size(), 1u);
  const SurfacePoint ref = reference_point({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f});
  expect_light_follows_pdf(scene, ref, Frame{}, test::sphere_grid(32, 64), 51, false);
  Rng rng(52);
  for (int k = 0; k < 1000; ++k) {
    const LightSample ls = sample_light(scene, scene.lights()[0], ref, rng.uniform2());
    ASSERT_EQ(ls.pdf, light_pdf(scene, scene.lights()[0], ref, ls.wi, SurfacePoint{}));
    ASSERT_EQ(ls.radiance, env.radiance);
  }
}

}  // namespace
}  // namespace gilt::raytrace_core
