// The command line's daylight (raytrace_core/scene/sun_sky.h): the sun's direction convention, its
// disk, and Preetham's sky against the paper's own zenith formula, its horizon and its sun side.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <glm/gtc/matrix_transform.hpp>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/scene/scene.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/scene/sun_sky.h"

namespace gilt::raytrace_core::scene {
namespace {

float luminance(const Rgb& c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }  // Rec.709's Y

TEST(SunSky, DirectionsFollowTheEnvironmentMapsConvention) {
  const auto near = [](Vec3 a, Vec3 b) { return glm::length(a - b) < 1e-6f; };
  EXPECT_TRUE(near(sky_direction(0.0f, 0.0f), Vec3(0.0f, 0.0f, -1.0f)));   // azimuth 0: along −z
  EXPECT_TRUE(near(sky_direction(0.0f, 90.0f), Vec3(1.0f, 0.0f, 0.0f)));   // 90: along +x
  EXPECT_TRUE(near(sky_direction(90.0f, 37.0f), Vec3(0.0f, 1.0f, 0.0f)));  // straight up
  const Vec3 d = sky_direction(30.0f, 0.0f);
  EXPECT_NEAR(d.y, 0.5f, 1e-6f);
}

TEST(SunSky, ZenithIsThePapersFormulaAndTheGroundIsBlack) {
  // Turbidity 3, sun at 30° elevation (zenith angle θs = 60°): Preetham et al. 1999, appendix A.2,
  // Y_z = (4.0453 T − 4.9710) tan χ − 0.2155 T + 2.4192 kcd/m², χ = (4/9 − T/120)(π − 2θs), in
  // gilt's unit of 100 klx. The top row's centre is 0.35° from the zenith, where F(θ, γ)/F(0, θs)
  // differs from one by less than 1e-2 (its slope in θ is of order one per radian).
  const double t = 3.0, theta_s = std::acos(0.5);
  const double chi = (4.0 / 9.0 - t / 120.0) * (std::numbers::pi - 2.0 * theta_s);
  const double zenith = ((4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192) / 100.0;
  const auto sky = preetham_sky(sky_direction(30.0f, 45.0f), 3.0f, 512);
  ASSERT_EQ(sky->width(), 512);
  ASSERT_EQ(sky->height(), 256);
  EXPECT_NEAR(luminance(sky->radiance({0.0f, 1.0f, 0.0f})), zenith, 1e-2 * zenith);
  EXPECT_EQ(sky->radiance(glm::normalize(Vec3(0.3f, -0.5f, 0.2f))), Rgb(0.0f));
  // Brighter towards the sun than away from it at the same elevation; bluer overhead than at the
  // horizon (a clear sky).
  const Rgb towards = sky->radiance(sky_direction(20.0f, 50.0f)), away = sky->radiance(sky_direction(20.0f, 230.0f));
  EXPECT_GT(luminance(towards), 1.5f * luminance(away));
  const Rgb up = sky->radiance({0.0f, 1.0f, 0.0f}), low = sky->radiance(sky_direction(3.0f, 230.0f));
  EXPECT_GT(up.b / up.r, low.b / low.r);
  EXPECT_THROW(preetham_sky({0.0f, 1.0f, 0.0f}, 1.0f), InputError);
  EXPECT_THROW(preetham_sky({0.0f, 1.0f, 0.0f}, 12.0f), InputError);
}

TEST(SunSky, SunIsADiskOfTheSunsSizeWithItsIrradiance) {
  io::ExtraLighting extra;
  extra.sun = true;
  extra.sun_elevation_degrees = 40.0f, extra.sun_azimuth_degrees = 120.0f, extra.sun_irradiance = 3.0f;
  extra.sky_turbidity = 3.0f;
  const Scene scene = io::load_scene("cornell", extra);
  const Light* sun = nullptr;
  int environments = 0;
  for (const Light& l : scene.punctual_lights) {
    if (l.kind == LightKind::directional) sun = &l;
    environments += l.kind == LightKind::environment;
  }
  ASSERT_NE(sun, nullptr);
  EXPECT_EQ(environments, 1);
  const Vec3 to_sun = sky_direction(40.0f, 120.0f);
  const float cos_radius = std::cos(kSunAngularRadiusDegrees * kPi / 180.0f);
  SurfacePoint ref;
  ref.p = Vec3(0.0f);
  ref.ng = Vec3(0.0f, 1.0f, 0.0f);
  util::Rng rng(3);
  Vec3 mean(0.0f);
  float widest = 1.0f;
  for (int k = 0; k < 4000; ++k) {
    const LightSample ls = sample_light(scene, *sun, ref, rng.uniform2());
    ASSERT_EQ(ls.radiance, Rgb(3.0f));
    ASSERT_TRUE(ls.delta);
    const float c = glm::dot(ls.wi, to_sun);
    ASSERT_GE(c, cos_radius - 1e-6f);  // inside the disk
    widest = std::min(widest, c);
    mean += ls.wi;
  }
  EXPECT_LT(widest, 1.0f - 0.5f * (1.0f - cos_radius));  // and spread over it, not a point
  EXPECT_GT(glm::dot(glm::normalize(mean), to_sun), 1.0f - 1e-6f);
  // A sky needs the sun's position; an image and a sky are one sky too many.
  io::ExtraLighting no_sun;
  no_sun.sky_turbidity = 3.0f;
  EXPECT_THROW(io::load_scene("cornell", no_sun), InputError);
}

TEST(SunSky, TheDiskIsSeenByCameraRaysAndThroughMirrors) {
  // A mirror floor and, 1 above it, a small black plate; a sun of irradiance 1 at 45° elevation
  // with a disk 10° in radius (wide, so that the test can find it by BSDF sampling). Light
  // sampling stands for the disk at the plate's underside but finds it behind the surface: the
  // only light there comes through the mirror, which a path can reach only by a BSDF sample
  // that, after the mirror, leaves through the disk. The disk's radiance is E / Ω (Ω its solid
  // angle), so the underside's irradiance is E cos 45° (1 + cos α) / 2 (the cosine over a cone
  // of radius α about a direction 45° from the normal).
  Scene scene;
  scene.materials = {Material::make_mirror("mirror"), Material::make_diffuse("black", Rgb(0.0f))};
  TriangleMesh floor, plate;
  floor.positions = {{-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}};
  floor.indices = {0, 1, 2, 0, 2, 3};
  plate.positions = {{-0.1f, 1, -0.1f}, {0.1f, 1, -0.1f}, {0.1f, 1, 0.1f}, {-0.1f, 1, 0.1f}};
  plate.indices = {0, 1, 2, 0, 2, 3};
  plate.material = 1;
  scene.meshes = {floor, plate};
  const float alpha = 10.0f * kPi / 180.0f;
  const Vec3 to_sun = glm::normalize(Vec3(1.0f, 1.0f, 0.0f));
  Light sun;
  sun.kind = LightKind::directional;
  sun.direction = -to_sun;
  sun.irradiance = Rgb(1.0f);
  sun.cos_angle = std::cos(alpha);
  scene.punctual_lights = {sun};
  scene.commit();
  const double solid_angle = 2.0 * std::numbers::pi * (1.0 - std::cos(double(alpha)));

  // A camera ray into the disk sees its radiance; one just outside it sees nothing.
  render::SampleContext ctx{render::Sampler(util::Rng(5)), 0};
  EXPECT_NEAR(render::path_radiance(scene, Ray{Vec3(0.0f, 2.0f, 0.0f), to_sun}, ctx, {}).g, 1.0 / solid_angle,
              1e-4);
  const Vec3 outside = glm::normalize(glm::rotate(glm::mat4(1.0f), 1.1f * alpha, Vec3(0, 0, 1)) * glm::vec4(to_sun, 0.0f));
  EXPECT_EQ(render::path_radiance(scene, Ray{Vec3(0.0f, 2.0f, 0.0f), outside}, ctx, {}), Rgb(0.0f));

  // The plate's underside, probed by a white Lambertian: π L is its irradiance. A sample finds
  // the disk with probability about cos 45° sin²α = 0.021 and then reads π/Ω = 32.9, so one
  // sample's standard deviation is about 4.8; 10⁶ samples give a standard error of 0.0048, and
  // the test allows four of them.
  static const Material white = Material::make_diffuse("probe", Rgb(1.0f));
  render::PathSettings probe;
  probe.first_surface = &white;
  const int n = 1000000;
  double sum = 0.0, sum2 = 0.0;
  for (int i = 0; i < n; ++i) {
    render::SampleContext c{render::Sampler(util::Rng::for_item(9, 0, uint64_t(i))), 0};
    const double e = std::numbers::pi * render::path_radiance(scene, Ray{Vec3(0.0f, 0.5f, 0.0f), Vec3(0, 1, 0)}, c, probe).g;
    sum += e, sum2 += e * e;
  }
  const double mean = sum / n, se = std::sqrt((sum2 / n - mean * mean) / n);
  const double expected = std::cos(std::numbers::pi / 4.0) * (1.0 + std::cos(double(alpha))) / 2.0;
  EXPECT_NEAR(mean, expected, 4.0 * se);
  EXPECT_LT(se, 0.01);
}

}  // namespace
}  // namespace gilt::raytrace_core::scene
