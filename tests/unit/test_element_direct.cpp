// The elements' direct light under a time budget: element_samples_within picks the most samples
// per element whose rays fit the time at the given rate, and element_punctual_irradiance traces
// exactly the rays it counted (so the forecast and the trace cannot drift apart).

#include <gtest/gtest.h>

#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/mesh/mesh.h"
#include "radiosity/solver/element_direct.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/scene.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

/// A mesh of `areas.size()` elements whose only meaningful field is their area (what the count of
/// samples reads).
rad::mesh::RadiosityMesh mesh_of_areas(const std::vector<float>& areas) {
  rad::mesh::RadiosityMesh mesh;
  mesh.elements.assign(areas.size(), {0u, 0u, 0u});
  mesh.element_area = areas;
  return mesh;
}

}  // namespace

// 100 equal elements and 2 lights: a side s of the grid costs s² × 200 rays; at 1,000 rays per
// second the thresholds are 3.2 s (16 samples), 1.8 s (9) and 0.8 s (4); below, one.
TEST(ElementDirect, SamplesWithinFitTheirRaysInTheTime) {
  const rad::mesh::RadiosityMesh mesh = mesh_of_areas(std::vector<float>(100, 1.0f));
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1000.0, 3.2), 16);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1000.0, 3.19), 9);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1000.0, 1.8), 9);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1000.0, 1.79), 4);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1000.0, 0.79), 1);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1000.0, 0.0), 1);
  // Never more than asked for, and a square: 10 samples are taken as a 3 × 3 grid.
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 10, 1000.0, 100.0), 9);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 1, 1000.0, 100.0), 1);
}

// A large element takes a grid (ceil √(area / mean))² times as fine: one element of area 12 among
// 99 of area 1 (mean 1.11, ratio 10.8) takes 4² = 16 times the points, so the 100 elements cost
// 99 + 16 = 115 times the grid's points per light.
TEST(ElementDirect, SamplesWithinCountLargeElementsFinerGrids) {
  std::vector<float> areas(99, 1.0f);
  areas.push_back(12.0f);
  const rad::mesh::RadiosityMesh mesh = mesh_of_areas(areas);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 1, 16, 1000.0, 16 * 115 / 1000.0), 16);
  EXPECT_EQ(rad::solver::element_samples_within(mesh, 1, 16, 1000.0, 16 * 115 / 1000.0 - 1e-3), 9);
}

// The rays element_punctual_irradiance traces are those element_samples_within counts: on the
// Cornell box's mesh lit by two point lights, for each grid side the rays equal side² × lights ×
// Σ scale², found as the rays that fit exactly.
TEST(ElementDirect, TheTraceCostsWhatTheCountForetold) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  for (float x : {-0.2f, 0.3f}) {
    rc::scene::Light point;
    point.kind = rc::scene::LightKind::point;
    point.position = rc::Vec3(x, 1.2f, 0.1f);
    point.intensity = rc::Rgb(1.0f);
    scene.punctual_lights.push_back(point);
  }
  scene.commit();
  rad::mesh::MeshSettings settings;
  settings.elements = 300;
  const rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, settings);
  const rc::scene::Scene geometry = rad::mesh::element_scene(scene, mesh);
  for (int samples : {1, 4, 9, 16}) {
    uint64_t rays = 0;
    rad::solver::element_punctual_irradiance(scene, geometry, mesh, samples, 0, rays);
    ASSERT_GT(rays, 0u);
    // At one ray per second, `rays` seconds fit `samples` and a second less fits fewer.
    EXPECT_EQ(rad::solver::element_samples_within(mesh, 2, 16, 1.0, double(rays)), samples);
    if (samples > 1) {
      EXPECT_LT(rad::solver::element_samples_within(mesh, 2, 16, 1.0, double(rays) - 1.0), samples);
    }
  }
}
