// The two-pass photon mapper's looked-up irradiance, against a closed form.
//
// Inside the white furnace (a closed cube whose inner faces all emit Le and reflect ρ), every
// point of a wall receives E = π Le / (1 − ρ): π Le straight from the walls and the rest from
// interreflection, which is what the global map holds. The photon density there is uniform, so a
// density estimate has no smoothing bias, and the coverage takes away the darkening at the
// cube's edges: PhotonMapper::irradiance must average E over points spread on the walls.
//
// It did not when irradiance was precomputed at the map's own photons (Christensen 1999): with
// k = 10 an estimate standing on a photon counts it at its kernel's peak, about k / (k − 2) of the
// interreflected part, and one that leaves it out is read through a nearest-site lookup that
// weighs each site by its Voronoi cell, large where the map happens to be sparse.
//
// Tolerance: K = 8 mappers with independent seeds each average the looked-up irradiance over the
// same M points. The mean of the K averages must lie within t · s / √K of E, s being their
// sample standard deviation and t Student's two-sided quantile at α = 1e-3 (K − 1 degrees of
// freedom), for each of the cases (Šidák-corrected over them). The seeds are fixed, so the test is
// deterministic.

#include <gtest/gtest.h>

#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <string>
#include <vector>

#include "photonmap/photon_mapper.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"

namespace rc = gilt::raytrace_core;
namespace pm = gilt::photonmap;

namespace {

constexpr int kMappers = 8;
constexpr int kPoints = 4000;
constexpr int kCases = 4;

double critical_t() {
  const double alpha_each = 1.0 - std::pow(1.0 - 1e-3, 1.0 / kCases);
  return boost::math::quantile(boost::math::complement(boost::math::students_t(kMappers - 1), alpha_each / 2.0));
}

struct WallPoint {
  rc::Vec3 p, inward;
};

/// Points on the furnace's walls where rays from the centre, uniform over directions, meet them:
/// every part of every wall, the edges and corners included.
std::vector<WallPoint> wall_points(const rc::scene::Scene& scene) {
  std::vector<WallPoint> points;
  rc::util::Rng rng = rc::util::Rng::for_item(3, 0, 0);
  while (points.size() < size_t(kPoints)) {
    const rc::Vec3 d = rc::util::sample_uniform_sphere(rng.uniform2());
    const rc::scene::Ray ray{rc::Vec3(0.0f), d, rc::kInfinity};
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    if (!hit) continue;
    const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
    points.push_back({si.p, glm::dot(si.ng, d) < 0.0f ? si.ng : -si.ng});
  }
  return points;
}

}  // namespace

struct LookupCase {
  float rho;
  int k;
};

class PhotonMapperLookup : public ::testing::TestWithParam<LookupCase> {};

TEST_P(PhotonMapperLookup, FurnaceIrradianceIsPiLeOverOneMinusRho) {
  const float le = 0.5f, rho = GetParam().rho;
  rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
  scene.commit();
  const std::vector<WallPoint> points = wall_points(scene);
  const double expected = rc::kPi * le / (1.0 - rho);

  double sum = 0.0, sum2 = 0.0;
  for (int m = 0; m < kMappers; ++m) {
    pm::PhotonMapperSettings settings;
    settings.photons.global_photons = 20000;
    settings.photons.caustic_photons = 0;
    settings.photons.seed = 40 + uint64_t(m);
    settings.k = GetParam().k;
    const pm::PhotonMapper mapper(scene, settings);
    ASSERT_GT(mapper.stats().irradiance_points, 1000u);
    double e = 0.0;
    for (size_t i = 0; i < points.size(); ++i) {
      rc::render::Sampler sampler(rc::util::Rng::for_item(settings.photons.seed, i, 0x77));
      e += mapper.irradiance(points[i].p, points[i].inward, sampler).g;
    }
    e /= double(points.size());
    sum += e;
    sum2 += e * e;
  }
  const double mean = sum / kMappers;
  const double s = std::sqrt(std::max(0.0, (sum2 - kMappers * mean * mean) / (kMappers - 1)));
  const double tolerance = critical_t() * s / std::sqrt(double(kMappers));
  EXPECT_NEAR(mean, expected, tolerance) << "rho " << rho << ", k " << GetParam().k << ": "
                                         << mean / expected << " of pi Le / (1 - rho)";
  ::testing::Test::RecordProperty("ratio", std::to_string(mean / expected));
  ::testing::Test::RecordProperty("relative_tolerance", std::to_string(tolerance / expected));
}

INSTANTIATE_TEST_SUITE_P(Furnace, PhotonMapperLookup,
                         ::testing::Values(LookupCase{0.5f, 10}, LookupCase{0.5f, 50}, LookupCase{0.8f, 10},
                                           LookupCase{0.8f, 50}),
                         [](const ::testing::TestParamInfo<LookupCase>& info) {
                           return "rho" + std::to_string(int(std::lround(100.0f * info.param.rho))) + "_k" +
                                  std::to_string(info.param.k);
                         });
