// Which sides of the meshed surfaces take light (radiosity/mesh/sides.h): a surface is turned
// over where light reaches only its back, given twins where light reaches both sides, and left as
// it is where light reaches its front alone or nothing at all, whatever way its input is wound.
// Each case's answer is exact (every element of a piece is decided together), so the counts are
// compared exactly.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/scene.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
using gilt::test::quad;
namespace rad = gilt::radiosity;
using rc::Rgb;
using rc::Vec3;

namespace {

/// The cube [-1, 1]³ as one closed mesh, its faces wound to face out (or in).
rc::scene::TriangleMesh cube(bool outward) {
  rc::scene::TriangleMesh m;
  for (int v = 0; v < 8; ++v) m.positions.push_back(Vec3(v & 1 ? 1 : -1, v & 2 ? 1 : -1, v & 4 ? 1 : -1));
  // Each face counter-clockwise seen from outside.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces) {
    if (outward)
      m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
    else
      m.indices.insert(m.indices.end(), {f[0], f[2], f[1], f[0], f[3], f[2]});
  }
  return m;
}

rc::scene::Light point_light(Vec3 at, float intensity) {
  rc::scene::Light l;
  l.kind = rc::scene::LightKind::point;
  l.position = at;
  l.intensity = Rgb(intensity);
  return l;
}

rad::mesh::MeshReport mesh_of(rc::scene::Scene& scene, rad::mesh::RadiosityMesh* out = nullptr) {
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", Rgb(0.5f)));
  scene.commit();
  rad::mesh::MeshSettings settings;
  settings.max_edge = 0.5f;
  rad::mesh::MeshReport report;
  rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, settings, &report);
  if (out) *out = std::move(mesh);
  return report;
}

}  // namespace

// The white furnace is a closed box lit from inside by its own faces: every front sees light,
// no back does.
TEST(Sides, AClosedFurnaceIsLeftAsItIs) {
  rc::scene::Scene scene = rc::io::furnace_scene(1.0f, 0.5f);
  scene.commit();
  rad::mesh::MeshSettings settings;
  settings.max_edge = 0.5f;
  rad::mesh::MeshReport report;
  const rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, settings, &report);
  EXPECT_GT(mesh.element_count(), 0u);
  EXPECT_EQ(report.turned_elements, 0u);
  EXPECT_EQ(report.two_sided_elements, 0u);
}

// A closed room wound outward (as many downloaded models are), lit by a lamp inside: light
// reaches only the backs, so every element is turned over to face in.
TEST(Sides, ARoomWoundOutwardIsTurnedOver) {
  rc::scene::Scene scene;
  scene.meshes.push_back(cube(/*outward=*/true));
  scene.punctual_lights.push_back(point_light(Vec3(0.1f, 0.2f, -0.1f), 1.0f));
  rad::mesh::RadiosityMesh mesh;
  const rad::mesh::MeshReport report = mesh_of(scene, &mesh);
  EXPECT_EQ(report.turned_elements, mesh.element_count());
  EXPECT_EQ(report.two_sided_elements, 0u);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const Vec3 centroid = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
    ASSERT_LT(glm::dot(mesh.element_normal[e], centroid), 0.0f) << "element " << e << " faces in";
  }
}

// The same cube outside, under a sky, is a solid block: its inside takes no light.
TEST(Sides, ASolidBlockUnderTheSkyIsLeftAsItIs) {
  rc::scene::Scene scene;
  scene.meshes.push_back(cube(/*outward=*/true));
  scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
  const rad::mesh::MeshReport report = mesh_of(scene);
  EXPECT_EQ(report.turned_elements, 0u);
  EXPECT_EQ(report.two_sided_elements, 0u);
}

// A single sheet under a sky is lit from above and below: each element gets a twin.
TEST(Sides, ASheetUnderTheSkyIsLitOnBothSides) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));
  scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
  rad::mesh::RadiosityMesh mesh;
  const rad::mesh::MeshReport report = mesh_of(scene, &mesh);
  EXPECT_EQ(report.turned_elements, 0u);
  EXPECT_EQ(2 * report.two_sided_elements, mesh.element_count());
  size_t up = 0;
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    EXPECT_TRUE(mesh.two_sided(e));
    up += mesh.element_normal[e].y > 0.99f;
  }
  EXPECT_EQ(2 * up, mesh.element_count());
}

// A wall modelled as two sheets back to back (two objects, as exporters often write them)
// already has an element on each side: neither gets a twin. (Twins there would lay two elements
// on each side, and each would send the side's light: the shed of test_radiosity_view.cpp read
// 1.2 to 1.35 times the path tracer's irradiance inside.)
TEST(Sides, SheetsBackToBackGetNoTwins) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));  // up
  scene.meshes.push_back(quad({-1, 0, -1}, {1, 0, -1}, {1, 0, 1}, {-1, 0, 1}));  // down
  scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
  rad::mesh::RadiosityMesh mesh;
  const rad::mesh::MeshReport report = mesh_of(scene, &mesh);
  EXPECT_EQ(report.turned_elements, 0u);
  EXPECT_EQ(report.two_sided_elements, 0u);
}

// Turned over, the room wound outward is the room wound inward: with elements as large as the
// input's faces (the remesher keeps them), the two meshes hold the same elements, facing the same
// way.
TEST(Sides, ARoomTurnedOverIsTheRoomWoundInward) {
  std::vector<std::array<float, 6>> elements[2];
  for (int outward = 0; outward < 2; ++outward) {
    rc::scene::Scene scene;
    scene.meshes.push_back(cube(outward == 1));
    scene.materials.push_back(rc::scene::Material::make_diffuse("grey", Rgb(0.5f)));
    scene.punctual_lights.push_back(point_light(Vec3(0.1f, 0.2f, -0.1f), 1.0f));
    scene.commit();
    rad::mesh::MeshSettings settings;
    settings.max_edge = 3.0f;
    rad::mesh::MeshReport report;
    const rad::mesh::RadiosityMesh mesh = rad::mesh::build_mesh(scene, settings, &report);
    EXPECT_EQ(report.turned_elements, outward ? mesh.element_count() : 0u);
    for (size_t e = 0; e < mesh.element_count(); ++e) {
      const auto& el = mesh.elements[e];
      const Vec3 c = (mesh.positions[el[0]] + mesh.positions[el[1]] + mesh.positions[el[2]]) / 3.0f;
      const Vec3 n = mesh.element_normal[e];
      elements[outward].push_back({c.x, c.y, c.z, n.x, n.y, n.z});
    }
    std::sort(elements[outward].begin(), elements[outward].end());
  }
  ASSERT_EQ(elements[0].size(), 12u);
  ASSERT_EQ(elements[1].size(), elements[0].size());
  for (size_t i = 0; i < elements[0].size(); ++i)
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(elements[1][i][k], elements[0][i][k], 1e-6f) << "element " << i;
}
