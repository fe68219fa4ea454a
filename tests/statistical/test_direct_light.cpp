// Next-event estimation of the direct light: estimate_direct, which samples every light of a
// scene with few, against the closed forms on an open floor.

#include <gtest/gtest.h>

#include <cmath>

#include "raytrace_core/render/direct_light.h"
#include "raytrace_core/scene/scene.h"

namespace rc = gilt::raytrace_core;
using rc::Rgb;
using rc::Vec3;

namespace {

constexpr float kAlbedo = 0.6f;

/// A white floor of 20 × 20 facing up at y = 0, under the given lights.
rc::scene::Scene open_floor(const std::vector<rc::scene::Light>& lights) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("floor", Rgb(kAlbedo)));
  rc::scene::TriangleMesh m;
  m.positions = {{-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}};
  m.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(m);
  scene.punctual_lights = lights;
  scene.commit();
  return scene;
}

/// The floor's point (0.5, 0, 0.3) seen straight from above: its surface, its shading frame and
/// the direction towards the viewer in that frame.
struct FloorView {
  rc::scene::SurfaceInteraction si;
  rc::Frame frame;
  Vec3 wo;
};

FloorView view_from_above(const rc::scene::Scene& scene) {
  const rc::scene::Ray down{Vec3(0.5f, 1.0f, 0.3f), Vec3(0.0f, -1.0f, 0.0f)};
  const auto hit = scene.intersect(down);
  EXPECT_TRUE(hit.has_value());
  FloorView v;
  v.si = scene.surface(down, *hit);
  v.frame = rc::Frame::from_normal(v.si.ns);
  v.wo = v.frame.to_local(Vec3(0.0f, 1.0f, 0.0f));
  return v;
}

rc::scene::Light sun(Vec3 towards_ground, float irradiance) {
  rc::scene::Light l;
  l.kind = rc::scene::LightKind::directional;
  l.direction = glm::normalize(towards_ground);
  l.irradiance = Rgb(irradiance);
  return l;
}

rc::scene::Light constant_sky(float radiance) {
  rc::scene::Light l;
  l.kind = rc::scene::LightKind::environment;
  l.radiance = Rgb(radiance);
  return l;
}

}  // namespace

// A sun and a point light, both delta lights: each call samples both, so every estimate is the
// closed form ρ/π (E cos θ_sun + I cos θ_point / d²) exactly, with none of the noise of choosing
// one light by power (which would read 0 or 1/p of each light's part).
TEST(DirectLight, EveryLightOfAFewIsSampledAtEachPoint) {
  rc::scene::Light point;
  point.kind = rc::scene::LightKind::point;
  point.position = Vec3(0.5f, 2.0f, 0.3f);
  point.intensity = Rgb(3.0f);
  const Vec3 sun_travel(0.6f, -0.8f, 0.0f);
  const rc::scene::Scene scene = open_floor({sun(sun_travel, 2.0f), point});
  const FloorView v = view_from_above(scene);
  const float expected = kAlbedo / rc::kPi * (2.0f * 0.8f + 3.0f / 4.0f);
  rc::render::Sampler rng(rc::util::Rng{});
  uint64_t rays = 0;
  for (int i = 0; i < 64; ++i) {
    const Rgb e = rc::render::estimate_direct(scene, v.si, scene.materials[v.si.material], v.frame, v.wo, true, rng, rays);
    ASSERT_NEAR(e.r, expected, 1e-5f * expected) << "call " << i;
  }
  EXPECT_EQ(rays, 2u * 64u) << "one shadow ray per light and call";
}

// A sun and a constant sky, each sampled at every call. The sky is drawn by the cosine about the
// floor's lit side, so under an open sky each sample gives ρ L exactly, and every estimate is the
// closed form ρ (E cos θ / π + L), up to float rounding of the cosine. (Drawn over the sphere, as
// before, one sample had a standard deviation 1.29 times the sky's part.)
TEST(DirectLight, SunAndSkyMeanMatchesTheClosedForm) {
  const rc::scene::Scene scene = open_floor({sun(Vec3(0.0f, -1.0f, 0.0f), 4.0f), constant_sky(0.5f)});
  const FloorView v = view_from_above(scene);
  // The floor's 20 × 20 lies below the point: the whole upper hemisphere is open sky.
  const double expected = kAlbedo * (4.0 / rc::kPi + 0.5);
  rc::render::Sampler rng(rc::util::Rng(7));
  uint64_t rays = 0;
  for (int i = 0; i < 2000; ++i) {
    const double e = rc::render::estimate_direct(scene, v.si, scene.materials[v.si.material], v.frame, v.wo, true, rng, rays).r;
    ASSERT_NEAR(e, expected, 1e-5 * expected) << "call " << i;
  }
  EXPECT_EQ(rays, 2u * 2000u) << "one shadow ray per light and call";
}

// The path tracer's next-event estimation (sample_direct_mis) under a sun and a sky samples both
// at every call. The sun, a delta light, counts in full; the sky's sample, drawn by the cosine
// about the floor, has the Lambertian BSDF's own density, so the power heuristic gives it weight
// ½ (the BSDF-sampled rays that escape carry the other half). Every call is then
// ρ (E cos θ / π + L / 2), up to float rounding. Choosing one of the two by power, a call read
// the sun as 0 or 1/p times its part.
TEST(DirectLight, PathTracerSamplesBothSunAndSkyAtEveryBounce) {
  const rc::scene::Scene scene = open_floor({sun(Vec3(0.3f, -1.0f, 0.2f), 4.0f), constant_sky(0.5f)});
  ASSERT_TRUE(rc::render::samples_each_light(scene));
  const FloorView v = view_from_above(scene);
  const rc::scene::Material& m = scene.materials[v.si.material];
  const rc::scene::LightQuery query = rc::render::light_query(v.si, m, true);
  EXPECT_EQ(rc::render::light_choice_pmf(scene, query, 0), 1.0f);
  EXPECT_EQ(rc::render::light_choice_pmf(scene, query, 1), 1.0f);
  const double cos_sun = 1.0 / std::sqrt(0.3 * 0.3 + 1.0 + 0.2 * 0.2);
  const double expected = kAlbedo * (4.0 * cos_sun / rc::kPi + 0.5 / 2.0);
  rc::render::Sampler rng(rc::util::Rng(9));
  uint64_t rays = 0;
  for (int i = 0; i < 2000; ++i) {
    const double e = rc::render::sample_direct_mis(scene, v.si, m, v.frame, v.wo, true, rng, rays).r;
    ASSERT_NEAR(e, expected, 1e-5 * expected) << "call " << i;
  }
  EXPECT_EQ(rays, 2u * 2000u) << "one shadow ray per light and call";
}

// Emitting surfaces are left to the light sampler: with one emitting triangle among the lights,
// sample_direct_mis chooses one light per call, and a BSDF-sampled ray is weighed with the
// sampler's own probability of that light.
TEST(DirectLight, EmittingSurfacesAreChosenByTheLightSampler) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("floor", Rgb(kAlbedo)));
  rc::scene::Material lamp = rc::scene::Material::make_diffuse("lamp", Rgb(0.0f));
  lamp.emission = Rgb(5.0f);
  scene.materials.push_back(lamp);
  rc::scene::TriangleMesh floor;
  floor.positions = {{-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  rc::scene::TriangleMesh light;
  light.positions = {{0, 3, 0}, {1, 3, 0}, {0, 3, 1}};
  light.indices = {0, 2, 1};
  light.material = 1;
  scene.meshes = {floor, light};
  scene.punctual_lights = {sun(Vec3(0.0f, -1.0f, 0.0f), 4.0f)};
  scene.commit();
  ASSERT_EQ(scene.lights().size(), 2u);
  EXPECT_FALSE(rc::render::samples_each_light(scene));
  const FloorView v = view_from_above(scene);
  const rc::scene::Material& m = scene.materials[v.si.material];
  const rc::scene::LightQuery query = rc::render::light_query(v.si, m, true);
  for (uint32_t li = 0; li < 2; ++li)
    EXPECT_EQ(rc::render::light_choice_pmf(scene, query, li), scene.light_sampler().pmf(query, li));
  rc::render::Sampler rng(rc::util::Rng(10));
  uint64_t rays = 0;
  for (int i = 0; i < 100; ++i) rc::render::sample_direct_mis(scene, v.si, m, v.frame, v.wo, true, rng, rays);
  EXPECT_LE(rays, 100u) << "at most one shadow ray per call";
}
