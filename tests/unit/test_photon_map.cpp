// Photon emission and tracing against closed forms: emitted power adds up to each light's power,
// the density estimate on a uniformly lit plane gives ρE/π, a glass sphere focuses at its
// paraxial focus, the maps do not depend on the thread count, and the passes a scene does not
// need are skipped with a reason.

#include <gtest/gtest.h>

#include <cmath>
#include <numeric>

#include "photonmap/photon_map.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace pm = gilt::photonmap;

namespace {

/// A square of side 2·half in the plane y = height, facing +y (or −y), with a material.
rc::scene::TriangleMesh square(float half, float height, uint32_t material, bool up = true) {
  rc::scene::TriangleMesh m;
  m.name = "square";
  m.positions = {{-half, height, -half}, {half, height, -half}, {half, height, half}, {-half, height, half}};
  m.indices = up ? std::vector<uint32_t>{0, 2, 1, 0, 3, 2} : std::vector<uint32_t>{0, 1, 2, 0, 2, 3};
  m.material = material;
  return m;
}

/// Mean of emission samples' power over n stratified samples.
rc::Rgb mean_emitted_power(const rc::scene::Scene& scene, const rc::scene::Light& light, int n) {
  rc::Rgb sum(0.0f);
  for (int i = 0; i < n; ++i) {
    rc::util::Rng rng = rc::util::Rng::for_item(5, uint64_t(i), 0);
    sum += rc::scene::sample_emission(scene, light, rng.uniform2(), rng.uniform2()).power;
  }
  return sum / float(n);
}

}  // namespace

// Every emission sample of an area, point or directional light carries the same power, equal
// to the light's: the mean is exact up to float rounding of a sum of 10⁴ terms (1e-4 relative).
// A spot light's samples vary with the falloff inside the cone: uniform directions in the cone,
// falloff smoothstep in cos θ between the cones, whose mean over the band is ½; the standard
// error of the mean over 2·10⁵ samples is below 0.2 %, and the bound 1 % is five of them.
TEST(PhotonEmission, SamplesAddUpToTheLightsPower) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  rc::scene::Light point;
  point.kind = rc::scene::LightKind::point;
  point.position = {278, 400, 278};
  point.intensity = rc::Rgb(100, 50, 25);
  rc::scene::Light directional;
  directional.kind = rc::scene::LightKind::directional;
  directional.direction = glm::normalize(rc::Vec3(0.3f, -1.0f, 0.2f));
  directional.irradiance = rc::Rgb(2, 3, 4);
  rc::scene::Light environment;
  environment.kind = rc::scene::LightKind::environment;
  environment.radiance = rc::Rgb(0.5f);
  rc::scene::Light spot = point;
  spot.kind = rc::scene::LightKind::spot;
  spot.direction = {0, -1, 0};
  spot.cos_inner = std::cos(0.3f);
  spot.cos_outer = std::cos(0.5f);
  scene.punctual_lights = {point, directional, environment, spot};
  scene.commit();
  for (const rc::scene::Light& light : scene.lights()) {
    const rc::Rgb expected = rc::scene::light_power(scene, light);
    ASSERT_GT(expected.average(), 0.0f);
    // A constant sky's samples vary with the area of the bounding box's outline seen along
    // each: over 2·10⁵ directions their mean is as close as a spot light's.
    const bool varies =
        light.kind == rc::scene::LightKind::spot || light.kind == rc::scene::LightKind::environment;
    const rc::Rgb mean = mean_emitted_power(scene, light, varies ? 200000 : 10000);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(mean[c], expected[c], (varies ? 1e-2f : 1e-4f) * expected[c]) << "light kind " << int(light.kind);
  }
}

// Photons from a directional light start on the outline of the scene's bounding box seen along
// the light, spread uniformly over it, each carrying E times its area. Every line crosses the
// box; the share crossing a box of half the size at its centre is that box's outline area over
// the whole's, a quarter (binomial standard error below 0.2 % at 10⁵ photons; bound four of them).
TEST(PhotonEmission, DistantLightsStartOnTheBoundingBoxsOutline) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  const rc::Bounds3 b = scene.bounds();
  const rc::Vec3 c = 0.5f * (b.lo + b.hi), h = 0.5f * (b.hi - b.lo);
  // Does the line through o along w cross the box centre ± half (a slab test)?
  const auto crosses = [&](const rc::Vec3& o, const rc::Vec3& w, const rc::Vec3& half) {
    float t0 = -1e30f, t1 = 1e30f;
    for (int a = 0; a < 3; ++a) {
      if (std::fabs(w[a]) < 1e-12f) {
        if (std::fabs(o[a] - c[a]) > half[a]) return false;
        continue;
      }
      float ta = (c[a] - half[a] - o[a]) / w[a], tb = (c[a] + half[a] - o[a]) / w[a];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta), t1 = std::min(t1, tb);
    }
    return t0 <= t1 * (1.0f + 1e-5f) + 1e-3f;
  };
  for (const rc::Vec3 dir : {rc::Vec3(0.3f, -1.0f, 0.2f), rc::Vec3(1.0f, -1.0f, 1.0f), rc::Vec3(0.0f, -1.0f, 0.0f)}) {
    rc::scene::Light sun;
    sun.kind = rc::scene::LightKind::directional;
    sun.direction = glm::normalize(dir);
    sun.irradiance = rc::Rgb(2.0f);
    const rc::Vec3 w = sun.direction, d = b.hi - b.lo;
    const float area = std::fabs(w.x) * d.y * d.z + std::fabs(w.y) * d.x * d.z + std::fabs(w.z) * d.x * d.y;
    const int n = 100000;
    int inner = 0;
    for (int i = 0; i < n; ++i) {
      rc::util::Rng rng = rc::util::Rng::for_item(3, uint64_t(i), 0);
      const rc::scene::EmissionSample es =
          rc::scene::sample_emission(scene, sun, rng.uniform2(), rng.uniform2());
      ASSERT_NEAR(es.power.g, 2.0f * area, 1e-3f * 2.0f * area);
      ASSERT_TRUE(crosses(es.ray.origin, es.ray.direction, h * 1.0001f)) << i;
      inner += crosses(es.ray.origin, es.ray.direction, 0.5f * h);
    }
    EXPECT_NEAR(double(inner) / n, 0.25, 4.0 * std::sqrt(0.25 * 0.75 / n)) << dir.x << " " << dir.y << " " << dir.z;
  }
}

// A plane lit by a directional light straight down receives irradiance E everywhere; photons
// stored where they first land (N = 400,000 over the 2×2 plane) estimate the reflected radiance
// ρE/π. 64 queries on a grid 0.2 apart, each over k = 400 photons (disk radius about 0.036, so
// the disks do not overlap and the estimates are independent): each has a relative standard
// deviation of about 1.1/√k ≈ 5.5 % (Epanechnikov weights; Poisson photon counts), their mean
// 0.7 %. The bound is 2 %, about three standard deviations of the mean.
TEST(PhotonEstimate, UniformlyLitPlaneGivesRhoEOverPi) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("plane", rc::Rgb(0.5f, 0.4f, 0.3f)));
  scene.meshes.push_back(square(1.0f, 0.0f, 0));
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = {0, -1, 0};
  sun.irradiance = rc::Rgb(3.0f);
  scene.punctual_lights.push_back(sun);
  scene.commit();

  constexpr uint64_t kPhotons = 400000;
  pm::PhotonMap map;
  map.emitted = kPhotons;
  const rc::scene::Light& light = scene.lights()[0];
  for (uint64_t i = 0; i < kPhotons; ++i) {
    rc::util::Rng rng = rc::util::Rng::for_item(9, i, 0);
    const rc::scene::EmissionSample es =
        rc::scene::sample_emission(scene, light, rng.uniform2(), rng.uniform2());
    pm::trace_photon_path(scene, es.ray, es.power / float(kPhotons), rng, 4, [&](const pm::Photon& p, int depth, bool) {
      if (depth == 0) map.photons.push_back(p);
      return false;
    });
  }
  map.build_index(pm::IndexKind::kd_tree);
  const rc::scene::Material& m = scene.materials[0];
  const rc::Rgb expected = m.albedo * sun.irradiance * rc::kInvPi;
  pm::EstimateScratch scratch;
  rc::Rgb sum(0.0f);
  int n = 0;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const rc::Vec3 x(-0.7f + 0.2f * i, 0.0f, -0.7f + 0.2f * j);
      const pm::EstimateQuery q{x, {0, 1, 0}, 400, 0.25f};
      const rc::Frame frame = rc::Frame::from_normal({0, 1, 0});
      const rc::Rgb l = pm::estimate_radiance(map, q, m, frame, {0, 0, 1}, scratch);
      // Each estimate alone: within 5 standard deviations (27 %).
      EXPECT_NEAR(l.g, expected.g, 0.27f * expected.g) << "at " << x.x << ", " << x.z;
      sum += l;
      ++n;
    }
  const rc::Rgb mean = sum / float(n);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(mean[c], expected[c], 0.02f * expected[c]);
  // The irradiance estimate is the same sum without the BSDF.
  const pm::EstimateQuery centre{{0, 0, 0}, {0, 1, 0}, 400, 0.25f};
  EXPECT_NEAR(pm::estimate_irradiance(map, centre, scratch).g, sun.irradiance.g, 0.27f * sun.irradiance.g);
  // Photons arriving on the other side are not counted.
  const pm::EstimateQuery below{{0, 0, 0}, {0, -1, 0}, 400, 0.25f};
  EXPECT_EQ(pm::estimate_irradiance(map, below, scratch).g, 0.0f);
}

// A glass sphere (n = 1.5, radius 1) focuses parallel light at f = nR / (2(n − 1)) = 1.5 from its
// centre (paraxial ball-lens focus; both principal planes pass through the centre). A narrow
// beam from a spot light D = 100 above the centre is imaged at v = fD / (D − f) ≈ 1.5228.
// Caustic photons are collected on a floor placed at depths from 1.2 to 2.0, 0.05 apart: their
// spread about the axis is smallest at the floor nearest v. The beam's radius at the sphere is
// about 0.1, where spherical aberration moves the focus by under 0.01: the bound is half a step
// plus that.
TEST(PhotonCaustics, GlassSphereFocusesAtTheParaxialFocus) {
  float best_depth = 0.0f, best_spread = 1e30f;
  for (int step = 0; step <= 16; ++step) {
    const float depth = 1.2f + 0.05f * float(step);
    rc::scene::Scene scene;
    scene.materials.push_back(rc::scene::Material::make_diffuse("floor", rc::Rgb(0.5f)));
    scene.materials.push_back(rc::scene::Material::make_dielectric("glass", 1.5f));
    scene.meshes.push_back(square(3.0f, -depth, 0));
    scene.spheres.push_back({{0, 0, 0}, 1.0f, 1});
    rc::scene::Light spot;
    spot.kind = rc::scene::LightKind::spot;
    spot.position = {0, 100, 0};
    spot.direction = {0, -1, 0};
    spot.intensity = rc::Rgb(1e6f);
    spot.cos_outer = float(std::cos(std::atan(0.1 / 99.0)));
    spot.cos_inner = spot.cos_outer;
    scene.punctual_lights.push_back(spot);
    scene.commit();
    pm::PhotonSettings settings;
    settings.global_photons = 0;
    settings.caustic_photons = 20000;
    const pm::PhotonMaps maps = pm::trace_photons(scene, settings);
    ASSERT_GT(maps.caustic.photons.size(), 10000u) << "at depth " << depth;
    double spread = 0.0;
    for (const pm::Photon& p : maps.caustic.photons) spread += p.position.x * p.position.x + p.position.z * p.position.z;
    spread /= double(maps.caustic.photons.size());
    if (spread < best_spread) best_spread = float(spread), best_depth = depth;
  }
  RecordProperty("best_depth", std::to_string(best_depth));
  const float f = 1.5f * 1.0f / (2.0f * (1.5f - 1.0f)), v = f * 100.0f / (100.0f - f);
  EXPECT_NEAR(best_depth, v, 0.025f + 0.01f);
}

// Photon i draws from its own stream and the chunks are joined in order: one and two threads
// give the same maps, photon for photon.
TEST(PhotonTracing, MapsDoNotDependOnTheThreadCount) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
  pm::PhotonSettings settings;
  settings.global_photons = 20000;
  settings.caustic_photons = 20000;
  auto trace = [&](int threads) {
    const rc::util::ThreadLimit limit(threads);
    return pm::trace_photons(scene, settings);
  };
  const pm::PhotonMaps one = trace(1), two = trace(2);
  ASSERT_GT(one.global.photons.size(), 1000u);
  ASSERT_GT(one.caustic.photons.size(), 100u);
  ASSERT_EQ(one.global.photons.size(), two.global.photons.size());
  ASSERT_EQ(one.caustic.photons.size(), two.caustic.photons.size());
  for (size_t i = 0; i < one.global.photons.size(); ++i) {
    ASSERT_EQ(one.global.photons[i].position, two.global.photons[i].position) << i;
    ASSERT_EQ(one.global.photons[i].power, two.global.photons[i].power) << i;
  }
  EXPECT_TRUE(one.skipped.empty());
}

namespace {

/// A 2 × 2 floor with a 1 × 1 plate 0.5 above it, facing it, under a sun; a speck 20 away
/// widens the bounds, so most photons from the bounding box's outline miss both.
rc::scene::Scene floor_far_under_a_sun() {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("white", rc::Rgb(0.8f)));
  scene.meshes.push_back(square(1.0f, 0.0f, 0));
  scene.meshes.push_back(square(0.5f, 0.5f, 0, false));
  rc::scene::TriangleMesh speck = square(0.01f, 0.0f, 0);
  for (rc::Vec3& p : speck.positions) p.x += 20.0f;
  scene.meshes.push_back(speck);
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = glm::normalize(rc::Vec3(0.2f, -1.0f, 0.1f));
  sun.irradiance = rc::Rgb(1.0f);
  scene.punctual_lights.push_back(sun);
  scene.commit();
  return scene;
}

}  // namespace

TEST(PhotonTracing, SparseGlobalMapsTakeMoreRoundsOfTheSamePhotons) {
  // A 2 × 2 floor with a 1 × 1 plate 0.5 above it, facing it, under a sun; a speck 20 away
  // widens the bounds, so most photons from the bounding disk miss both. Global photons (after a
  // diffuse bounce) are few per round, and rounds go on until half a round's count is stored.
  // Round k traces photons k·N … (k + 1)·N − 1, so r rounds of N are one round of r·N photons,
  // their power divided by r instead of by r·N at once: the same map up to rounding.
  const rc::scene::Scene scene = floor_far_under_a_sun();
  pm::PhotonSettings rounds;
  rounds.global_photons = 4000;
  rounds.caustic_photons = 0;
  rounds.global_rounds = 6;
  const pm::PhotonMaps a = pm::trace_photons(scene, rounds);
  const uint64_t r = a.global.emitted / rounds.global_photons;
  EXPECT_GT(r, 1u);
  EXPECT_EQ(a.global.emitted % rounds.global_photons, 0u);
  EXPECT_TRUE(r == uint64_t(rounds.global_rounds) || 2 * a.global.photons.size() >= rounds.global_photons)
      << r << " rounds, " << a.global.photons.size() << " stored";
  pm::PhotonSettings once = rounds;
  once.global_photons = r * rounds.global_photons;
  once.global_rounds = 1;
  const pm::PhotonMaps b = pm::trace_photons(scene, once);
  ASSERT_EQ(b.global.emitted, a.global.emitted);
  ASSERT_EQ(a.global.photons.size(), b.global.photons.size());
  ASSERT_GT(a.global.photons.size(), 0u);
  for (size_t i = 0; i < a.global.photons.size(); ++i) {
    ASSERT_EQ(a.global.photons[i].position, b.global.photons[i].position) << i;
    ASSERT_NEAR(a.global.photons[i].power.g, b.global.photons[i].power.g, 1e-6f * b.global.photons[i].power.g) << i;
  }
}

// Under a time share (global_seconds) a map that stores fewer photons than half its paths takes
// rounds past half a round stored, up to global_time_rounds; a closed room, which stores most of its
// paths, stops after its first round. The share here never runs out, so the counts are exact.
TEST(PhotonTracing, ATimeShareAddsRoundsOnlyWhereMostPathsStoreNothing) {
  pm::PhotonSettings settings;
  settings.caustic_photons = 0;
  settings.global_time_rounds = 40;
  settings.global_seconds = 1e9;

  const rc::scene::Scene open = floor_far_under_a_sun();
  settings.global_photons = 400;
  const pm::PhotonMaps a = pm::trace_photons(open, settings);
  ASSERT_GT(a.global.photons.size(), 0u);
  EXPECT_LT(2 * a.global.photons.size(), a.global.emitted);
  EXPECT_EQ(a.global.emitted, 40u * settings.global_photons);
  pm::PhotonSettings no_share = settings;
  no_share.global_seconds = 0.0;
  EXPECT_LT(pm::trace_photons(open, no_share).global.emitted, a.global.emitted) << "half a round was stored sooner";

  const rc::scene::Scene cornell = rc::io::load_scene("cornell");
  settings.global_photons = 2000;
  const pm::PhotonMaps b = pm::trace_photons(cornell, settings);
  EXPECT_GE(2 * b.global.photons.size(), b.global.emitted);
  EXPECT_EQ(b.global.emitted, settings.global_photons);
}

TEST(PhotonTracing, SkipsWhatTheSceneDoesNotNeed) {
  // cornell has no mirror or glass: no caustic map.
  const rc::scene::Scene cornell = rc::io::load_scene("cornell");
  pm::PhotonSettings settings;
  settings.global_photons = 1000;
  settings.caustic_photons = 1000;
  const pm::PhotonMaps maps = pm::trace_photons(cornell, settings);
  EXPECT_TRUE(maps.caustic.empty());
  EXPECT_FALSE(maps.global.empty());
  ASSERT_EQ(maps.skipped.size(), 1u);
  EXPECT_NE(maps.skipped[0].find("no specular surface"), std::string::npos) << maps.skipped[0];

  // Black surfaces only: nothing to interreflect, no global map.
  rc::scene::Scene black;
  black.materials.push_back(rc::scene::Material::make_diffuse("black", rc::Rgb(0.0f)));
  black.meshes.push_back(square(1.0f, 0.0f, 0));
  rc::scene::Light point;
  point.kind = rc::scene::LightKind::point;
  point.position = {0, 1, 0};
  point.intensity = rc::Rgb(1.0f);
  black.punctual_lights.push_back(point);
  black.commit();
  const pm::PhotonMaps none = pm::trace_photons(black, settings);
  EXPECT_TRUE(none.global.empty());
  EXPECT_TRUE(none.caustic.empty());
  EXPECT_EQ(none.skipped.size(), 2u);
  EXPECT_EQ(none.paths, 0u);
}
