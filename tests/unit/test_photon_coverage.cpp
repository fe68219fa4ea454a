// The coverage of a density estimate's disk (photonmap/coverage.h): the kernel's closed-form
// integral over a triangle against a fine quadrature and against the full disk, the coverage at
// the centre, edge and corner of a lit floor, and the photon estimate at a floor's edge, which
// the coverage makes as bright as at its centre.

#include <gtest/gtest.h>

#include <cmath>

#include "photonmap/coverage.h"
#include "photonmap/photon_map.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/util/rng.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
using gilt::test::quad;
namespace pm = gilt::photonmap;

namespace {

/// ∫ (1 − |y − p|² / r2)⁺ over abc by the centroid rule on n² similar pieces (in double).
double brute_force(const rc::Vec3& a, const rc::Vec3& b, const rc::Vec3& c, const rc::Vec3& p, double r2, int n) {
  const glm::dvec3 da(a), e1 = glm::dvec3(b) - da, e2 = glm::dvec3(c) - da;
  const double piece = 0.5 * glm::length(glm::cross(e1, e2)) / (double(n) * n);
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n - i; ++j)
      for (int up = 0; up < (j < n - i - 1 ? 2 : 1); ++up) {
        // centroid of piece (i, j), upright (up = 0) or inverted
        const double u = (i + (up ? 2.0 : 1.0) / 3.0) / n, v = (j + (up ? 2.0 : 1.0) / 3.0) / n;
        const glm::dvec3 y = da + u * e1 + v * e2;
        sum += std::max(0.0, 1.0 - glm::dot(y - glm::dvec3(p), y - glm::dvec3(p)) / r2);
      }
  return sum * piece;
}

/// A 2 × 2 floor at y = 0 facing up, and a wall at x = 1 facing −x, both diffuse.
rc::scene::Scene floor_and_wall() {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));  // (b−a)×(c−a) = +y
  scene.meshes.push_back(quad({1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1}));    // −x
  return scene;
}

}  // namespace

// The closed form against the full disk (π r² / 2 for a triangle holding the whole disk, and
// π ρ⁴ / (2 r²) in a plane at height h, ρ² = r² − h²) and against the centroid rule on 400²
// pieces for 40 random triangles and balls (33 of them meet, most cut by the rim). The rule's
// error comes from the pieces the rim cuts, about the rim's length times the square of the piece
// size times the kernel's slope: of the order of 1e-5 of the triangle's area here (measured
// 1.2e-6 at worst), which is the bound.
TEST(PhotonCoverage, KernelIntegralIsExact) {
  const double kPi = 3.14159265358979323846;
  const rc::Vec3 a(-50, 0, -50), b(50, 0, -50), c(0, 0, 80);
  EXPECT_NEAR(pm::kernel_integral(a, b, c, {1, 0, 2}, 4.0f), kPi * 4.0 / 2.0, 1e-9);
  EXPECT_NEAR(pm::kernel_integral(a, c, b, {1, 0.5f, 2}, 4.0f), kPi * 3.75 * 3.75 / 8.0, 1e-9);
  EXPECT_EQ(pm::kernel_integral(a, b, c, {1, 2.5f, 2}, 4.0f), 0.0);
  rc::util::Rng rng = rc::util::Rng::for_item(3, 0, 0);
  auto point = [&] { return rc::Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0f - 1.0f; };
  for (int i = 0; i < 40; ++i) {
    const rc::Vec3 ta = point(), tb = point(), tc = point(), p = point() * 0.5f;
    const float r2 = 0.05f + rng.uniform();
    const double area = 0.5 * glm::length(glm::cross(glm::dvec3(tb - ta), glm::dvec3(tc - ta)));
    EXPECT_NEAR(pm::kernel_integral(ta, tb, tc, p, r2), brute_force(ta, tb, tc, p, r2, 400), 1e-5 * area)
        << "triangle " << i;
  }
}

// On the floor of floor_and_wall, with both sides marked as lit from above and from the room:
// a disk of radius 0.5 is whole at the floor's centre (1), half on the floor at the wall (the
// wall, at 90°, fails the 25° test) and a quarter where the wall meets the floor's open edge at
// z = 1. A floor whose lit side holds no photon covers nothing.
TEST(PhotonCoverage, CentreEdgeAndCornerOfAFloor) {
  rc::scene::Scene scene = floor_and_wall();
  scene.commit();
  pm::SurfaceSides sides(scene);
  EXPECT_EQ(pm::disk_coverage(scene, sides, {0, 0, 0}, {0, 1, 0}, 0.25f, 0.9f), 0.0);
  for (uint32_t t = 0; t < 2; ++t) {
    sides.add(scene, 0, t, {0, 1, 0});
    sides.add(scene, 1, t, {-1, 0, 0});
  }
  EXPECT_NEAR(pm::disk_coverage(scene, sides, {0, 0, 0}, {0, 1, 0}, 0.25f, 0.9f), 1.0, 1e-6);
  EXPECT_NEAR(pm::disk_coverage(scene, sides, {1, 0, 0}, {0, 1, 0}, 0.25f, 0.9f), 0.5, 1e-6);
  EXPECT_NEAR(pm::disk_coverage(scene, sides, {1, 0, 1}, {0, 1, 0}, 0.25f, 0.9f), 0.25, 1e-6);
  // The floor's underside holds nothing.
  EXPECT_EQ(pm::disk_coverage(scene, sides, {0, 0, 0}, {0, -1, 0}, 0.25f, 0.9f), 0.0);
}

// The plank test: a floor lit by a directional light straight down, photons stored where they
// land (N = 400,000 over its 2 × 2). At points on its open edge the k-nearest disk is half off the
// floor: without the coverage the estimate is about half of E, with it E. 16 points along the
// edge 0.1 apart, k = 400 (radius about 0.05, so the disks do not overlap): each estimate's
// relative standard deviation is about 1.1 / √k ≈ 5.5 %, their mean's 1.4 %; the bound on the
// mean is 5 %, over three of those.
TEST(PhotonCoverage, EstimateAtAnOpenEdgeIsAsBrightAsInside) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = {0, -1, 0};
  sun.irradiance = rc::Rgb(3.0f);
  scene.punctual_lights.push_back(sun);
  scene.commit();

  constexpr uint64_t kPhotons = 400000;
  pm::PhotonMap map;
  map.emitted = kPhotons;
  map.sides = pm::SurfaceSides(scene);
  const rc::scene::Light& light = scene.lights()[0];
  for (uint64_t i = 0; i < kPhotons; ++i) {
    rc::util::Rng rng = rc::util::Rng::for_item(9, i, 0);
    const rc::scene::EmissionSample es =
        rc::scene::sample_emission(scene, light, rng.uniform2(), rng.uniform2());
    pm::trace_photon_path(scene, es.ray, es.power / float(kPhotons), rng, 4,
                          [&](const pm::Photon& p, int depth, bool, const rc::scene::Hit& hit) {
                            if (depth == 0) {
                              map.photons.push_back(p);
                              map.sides.add(scene, hit.geom_id, hit.prim_id, pm::decode_direction(p.normal));
                            }
                            return false;
                          });
  }
  map.build_index(pm::IndexKind::kd_tree);
  pm::EstimateScratch scratch;
  double plain = 0.0, covered = 0.0;
  for (int i = 0; i < 16; ++i) {
    const pm::EstimateQuery q{{1.0f, 0.0f, -0.75f + 0.1f * float(i)}, {0, 1, 0}, 400, 0.25f};
    plain += pm::estimate_irradiance(map, q, scratch).g / 16.0;
    covered += pm::estimate_irradiance(scene, map, q, scratch).g / 16.0;
  }
  EXPECT_NEAR(plain, 0.5 * sun.irradiance.g, 0.1 * sun.irradiance.g);  // the bias the coverage removes
  EXPECT_NEAR(covered, sun.irradiance.g, 0.05 * sun.irradiance.g);
}

// A closed cube floating over a floor: light from outside reaches the floor's upper side, the
// cube's outer sides and the floor's underside (it sees the sky), never the cube's inner sides,
// whichever way the cube is wound. Every ray from an inner side meets another inner side, so
// this holds for any number of rays; 8 are the default. (Standing on the floor, the cube's
// inner sides would see the floor's triangles, coplanar with its bottom, which the sky reaches
// elsewhere: a side is reached or not as a whole.)
TEST(PhotonCoverage, OpenSidesAreThoseLightFromOutsideReaches) {
  for (const bool inside_out : {false, true}) {
    rc::scene::Scene scene;
    scene.materials.push_back(rc::scene::Material::make_diffuse("grey", rc::Rgb(0.5f)));
    scene.meshes.push_back(quad({-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}));  // floor, front +y
    rc::scene::TriangleMesh cube;
    cube.name = "cube";
    for (int i = 0; i < 8; ++i) cube.positions.push_back({float(i & 1), 0.5f + float((i >> 1) & 1), float((i >> 2) & 1)});
    // Faces wound with the front outwards: −x, +x, −y, +y, −z, +z.
    const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& f : faces) {
      const uint32_t a = f[0], b = f[1], c = f[2], d = f[3];
      if (inside_out) cube.indices.insert(cube.indices.end(), {a, c, b, a, d, c});
      else cube.indices.insert(cube.indices.end(), {a, b, c, a, c, d});
    }
    scene.meshes.push_back(cube);
    scene.commit();
    const pm::SurfaceSides sides = pm::open_sides(scene);
    for (uint32_t t = 0; t < 2; ++t) {
      EXPECT_TRUE(sides.holds(0, t, true)) << "floor, upper side";
      EXPECT_TRUE(sides.holds(0, t, false)) << "floor, underside";
    }
    for (uint32_t t = 0; t < 12; ++t) {
      // The cube's outward side is its front unless it is wound inside out.
      EXPECT_TRUE(sides.holds(1, t, !inside_out)) << "cube triangle " << t << ", outer side";
      EXPECT_FALSE(sides.holds(1, t, inside_out)) << "cube triangle " << t << ", inner side";
    }
  }
}
