// The radiosity mesher and solver on meshes as real files bring them: each case is an input on
// which gilt once crashed, changed its answer from run to run, or deleted visible surface.
//   - imprinting gives the same mesh in every run and for any thread count (on Šibenik too,
//     where one piece is cut by many tools in turn);
//   - a patch of faces with collinear corners (McGuire's conference room) meshes without error;
//   - non-manifold soups are split into single fans (no half-edge library to assert on them);
//   - a finely scanned open surface standing on a floor keeps its area, and the floor loses
//     only what the surface covers;
//   - vertices on rounded edges, coarser than the rounding, still receive the light they face.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/mesh/mesh.h"
#include "radiosity/mesh/mesh_detail.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/mesh_builders.h"

namespace gilt::radiosity {
using namespace mesh;
using namespace solver;
namespace {

using rc::DVec3;
using rc::scene::Material;
using rc::Rgb;
using rc::scene::Scene;
using rc::scene::TriangleMesh;
using test::add_box;
using test::add_quad;

constexpr double kPi = 3.14159265358979323846;

/// CGAL's remesher keeps edges below 4/3 of its target, which the mesher sets 1.12 times the
/// edge asked for (mesh.cpp): an element spans at most 1.5 times the requested edge.
constexpr double kRemeshScaleBound = 1.12;

void note(const std::string& key, const std::string& value) {
  std::printf("[ measured ] %s: %s\n", key.c_str(), value.c_str());
  testing::Test::RecordProperty(key, value);
}

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0) {
  char text[256];
  std::snprintf(text, sizeof text, format, a, b, c);
  return text;
}

/// A floor with two boxes sunk into it at odd angles, all in one mesh (as an OBJ material
/// groups them), and a second mesh crossing the first: every kind of imprinting at once.
Scene contact_scene() {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.6f)));
  scene.materials.push_back(Material::make_emitter("lamp", Rgb(5.0f)));
  TriangleMesh floor;
  floor.name = "floor and boxes";
  add_quad(floor, {Vec3(-2, 0, -2), Vec3(-2, 0, 2), Vec3(2, 0, 2), Vec3(2, 0, -2)});
  add_box(floor, Vec3(-0.6f, 0.3f, 0.2f), Vec3(0.45f, 0.5f, 0.3f), 0.37f, 0.21f);
  add_box(floor, Vec3(0.7f, 0.1f, -0.4f), Vec3(0.3f, 0.6f, 0.4f), -0.83f, -0.12f);
  scene.meshes.push_back(std::move(floor));
  TriangleMesh slab;
  slab.name = "slab";
  add_box(slab, Vec3(0.1f, 0.4f, 0.9f), Vec3(1.2f, 0.08f, 0.25f), 0.11f, 0.43f);
  scene.meshes.push_back(std::move(slab));
  test::add_ceiling_lamp(scene, 1);
  scene.commit();
  return scene;
}

TEST(MeshRobust, ImprintingGivesTheSameMeshEveryRunAndThreadCount) {
  const Scene scene = contact_scene();
  MeshReport report;
  const RadiosityMesh first = build_mesh(scene, MeshSettings{.elements = 1500}, &report);
  ASSERT_GT(report.contact_edges, 0u);
  note("contact_edges", fmt("%.0f", double(report.contact_edges)));
  // Corefinement ordered its work by memory addresses: allocations between runs move them.
  std::vector<std::unique_ptr<char[]>> clutter;
  for (int run = 0; run < 4; ++run) {
    for (int k = 0; k < 50 * (run + 1); ++k) clutter.emplace_back(new char[size_t(64 + 97 * k)]);
    RadiosityMesh again;
    {
      rc::util::ThreadLimit limit(run % 2 == 0 ? 1 : 2);
      again = build_mesh(scene, MeshSettings{.elements = 1500});
    }
    EXPECT_EQ(again.positions, first.positions) << "run " << run;
    EXPECT_EQ(again.elements, first.elements) << "run " << run;
    EXPECT_EQ(again.normals, first.normals) << "run " << run;
  }
}

/// Šibenik (../shared/scenes): a piece cut by one tool after another, where a run's first cut
/// decided where the next one's points fell, gave 12,890 or 12,891 contact edges and different
/// element meshes, about one run in eight, while CGAL's corefinement imprinted them (it orders
/// its work by memory addresses); gilt's own imprinting depends on the input alone.
TEST(MeshRobust, SibeniksContactLinesAreTheSameInEveryRun) {
  const std::string path = std::string(GILT_SOURCE_DIR) + "/../shared/scenes/wrap/sibenik-lit.json";
  if (!std::ifstream(path)) GTEST_SKIP() << "no " << path;
  const Scene scene = rc::io::load_scene(path);
  MeshReport first_report;
  const RadiosityMesh first = build_mesh(scene, MeshSettings{}, &first_report);
  note("contact_edges", fmt("%.0f", double(first_report.contact_edges)));
#if defined(__SANITIZE_ADDRESS__)
  const int runs = 1;  // each run takes 40 s under AddressSanitizer: one checks the memory use
#else
  const int runs = 4;
#endif
  std::vector<std::unique_ptr<char[]>> clutter;
  for (int run = 0; run < runs; ++run) {
    for (int k = 0; k < 40 * (run + 1); ++k) clutter.emplace_back(new char[size_t(48 + 4099 * k)]);
    MeshReport report;
    RadiosityMesh again;
    {
      rc::util::ThreadLimit limit(run % 2 == 0 ? 2 : 1);
      again = build_mesh(scene, MeshSettings{}, &report);
    }
    EXPECT_EQ(report.contact_edges, first_report.contact_edges) << "run " << run;
    EXPECT_TRUE(again.positions == first.positions) << "run " << run;
    EXPECT_TRUE(again.elements == first.elements) << "run " << run;
  }
}

TEST(MeshRobust, CollinearPatchFromTheConferenceRoomMeshes) {
  const Scene scene = rc::io::load_scene(std::string(GILT_TEST_DATA_DIR) + "/conference-collinear-patch.obj");
  MeshReport report;
  RadiosityMesh mesh;
  ASSERT_NO_THROW(mesh = build_mesh(scene, MeshSettings{.elements = 1000}, &report));
  EXPECT_GT(mesh.element_count(), 0u);
  for (float a : mesh.element_area) ASSERT_GT(a, 0.0f);
  for (const Vec3& n : mesh.normals) ASSERT_NEAR(glm::length(n), 1.0f, 1e-5f);
  note("conference",
       fmt("%.0f elements, %.0f contact edges", double(mesh.element_count()), double(report.contact_edges)));
}

/// The output vertices of `surface` that belong to more than one fan: the triangles around the
/// vertex that are not connected through edges they share with it.
size_t vertices_with_several_fans(const detail::SplitSurface& surface) {
  std::map<uint32_t, std::vector<size_t>> around;
  for (size_t t = 0; t < surface.corners.size(); ++t)
    for (uint32_t v : surface.corners[t]) around[v].push_back(t);
  size_t bad = 0;
  for (const auto& [v, triangles] : around) {
    std::vector<size_t> reached{triangles[0]};
    for (size_t i = 0; i < reached.size(); ++i)
      for (size_t t : triangles) {
        if (std::find(reached.begin(), reached.end(), t) != reached.end()) continue;
        // t joins the fan if it shares an edge through v (two output vertices) with a reached one.
        size_t shared = 0;
        for (uint32_t a : surface.corners[t])
          shared += std::count(surface.corners[reached[i]].begin(), surface.corners[reached[i]].end(), a);
        if (shared >= 2) reached.push_back(t);
      }
    bad += reached.size() != triangles.size();
  }
  return bad;
}

TEST(MeshRobust, NonManifoldSoupsAreSplitIntoSingleFans) {
  detail::TriangleSoup soup;
  soup.points = {{0, 0, 0}, {1, 0, 0}, {0.5, 1, 0}, {0.5, -1, 0}, {0.5, 0, 1},  // three on edge 0–1
                 {3, 0, 0}, {4, 1, 0}, {4, -1, 0},  {2, 1, 0},    {2, -1, 0},   // bow tie at 5
                 {6, 0, 0}, {7, 0, 0}, {6.5, 1, 0}, {6.5, -1, 0}};              // wound against each other
  soup.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {5, 6, 8}, {5, 7, 9}, {10, 11, 12}, {10, 11, 13}};
  const detail::SplitSurface split = detail::split_sharp_vertices(soup, 180.0);
  ASSERT_EQ(split.corners.size(), soup.triangles.size());
  EXPECT_EQ(vertices_with_several_fans(split), 0u);
  for (size_t t = 0; t < soup.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k)
      EXPECT_EQ(split.positions[split.corners[t][k]], soup.points[soup.triangles[t][k]]);
  // The bow tie's two wings get a copy of vertex 5 each; each triangle of the three-way edge and
  // of the pair wound against each other keeps vertices of its own along that edge.
  EXPECT_NE(split.corners[3][0], split.corners[4][0]);
  EXPECT_NE(split.corners[0][0], split.corners[1][1]);
  EXPECT_NE(split.corners[0][0], split.corners[2][0]);
  EXPECT_NE(split.corners[5][0], split.corners[6][0]);
  for (const DVec3& n : split.normals) EXPECT_NEAR(glm::length(n), 1.0, 1e-12);
}

/// An open hemisphere of radius r on the floor, tessellated finely (a scan, open at its base).
TriangleMesh scanned_dome(float r, int rings, int segments) {
  TriangleMesh dome;
  dome.name = "dome";
  for (int i = 0; i <= rings; ++i) {
    const double polar = 0.5 * kPi * double(i) / rings;  // 0 at the top
    for (int j = 0; j < segments; ++j) {
      const double azimuth = 2.0 * kPi * double(j) / segments;
      // The rim lies exactly on the floor (cos(π/2) in double is 6e-17, not 0).
      const float height = i == rings ? 0.0f : float(r * std::cos(polar));
      dome.positions.emplace_back(float(r * std::sin(polar) * std::cos(azimuth)), height,
                                  float(r * std::sin(polar) * std::sin(azimuth)));
    }
  }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const uint32_t a = uint32_t(i * segments + j), b = uint32_t(i * segments + (j + 1) % segments);
      const uint32_t c = a + uint32_t(segments), d = b + uint32_t(segments);
      dome.indices.insert(dome.indices.end(), {a, b, d, a, d, c});  // outward
    }
  return dome;
}

double surface_area(const RadiosityMesh& mesh, uint32_t surface) {
  double area = 0.0;
  for (size_t e = 0; e < mesh.element_count(); ++e)
    if (mesh.element_surface[e] == surface) area += mesh.element_area[e];
  return area;
}

// Remeshed elements are chords of the fine input and lie inside it; burial used to be tested
// from them, and a scanned body saw its own input from behind everywhere (the Stanford bunny
// kept 16 % of its area). Burial must take nothing from the dome, and from the floor exactly the
// disk under it, which the dome and the floor enclose.
TEST(MeshRobust, ScannedOpenSurfaceKeepsItsAreaAndCoversTheFloorUnderIt) {
  const float r = 1.0f;
  const auto dome_scene = [&](bool commit) {
    Scene scene;
    scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.6f)));
    scene.materials.push_back(Material::make_emitter("lamp", Rgb(5.0f)));
    scene.meshes.push_back(scanned_dome(r, 48, 192));
    TriangleMesh floor;
    floor.name = "floor";
    add_quad(floor, {Vec3(-3, 0, -3), Vec3(-3, 0, 3), Vec3(3, 0, 3), Vec3(3, 0, -3)});
    scene.meshes.push_back(std::move(floor));
    test::add_ceiling_lamp(scene, 1);
    if (commit) scene.commit();
    return scene;
  };
  // Burial casts rays, so it runs only on a committed scene: the other is the same mesh unburied.
  const Scene lit = dome_scene(true), unlit = dome_scene(false);
  MeshReport report;
  const RadiosityMesh mesh = build_mesh(lit, MeshSettings{.max_edge = 0.3f}, &report);
  const RadiosityMesh whole = build_mesh(unlit, MeshSettings{.max_edge = 0.3f});
  const double dome = surface_area(mesh, 0), floor_area = surface_area(mesh, 1);
  note("dome", fmt("%.6f of the unburied dome kept; floor lost %.5f m²", dome / surface_area(whole, 0),
                   36.0 - floor_area));
  note("dome_report", fmt("buried input faces %.0f, elements %.0f, area %.5f", double(report.buried_faces),
                          double(report.buried_elements), report.buried_area));
  EXPECT_NEAR(dome, surface_area(whole, 0), 1e-6 * dome);  // float sums of the same elements
  EXPECT_NEAR(surface_area(whole, 1), 36.0, 1e-4);
  // The floor loses the 192-gon inscribed in the dome's rim: (192 / 2) sin(2π / 192) r².
  const double polygon = 96.0 * std::sin(2.0 * kPi / 192.0) * r * r;
  EXPECT_NEAR(36.0 - floor_area, polygon, 1e-4);
  EXPECT_NEAR(report.buried_area, polygon, 1e-4);
}

// An open box (no bottom, as the Cornell blocks are modelled) standing a hundred-thousandth above
// the floor touches nothing, so nothing is imprinted; the floor under it is still enclosed, and
// the flat elements there are removed after remeshing. Elements straddling the footprint's
// outline are not (some of their test points are open), so the removed area lies between the
// footprint shrunk by one element all round and the footprint itself.
TEST(MeshRobust, FloorUnderAnObjectJustAboveItIsRemovedAfterRemeshing) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.6f)));
  scene.materials.push_back(Material::make_emitter("lamp", Rgb(5.0f)));
  TriangleMesh floor;
  floor.name = "floor";
  add_quad(floor, {Vec3(-2, 0, -2), Vec3(-2, 0, 2), Vec3(2, 0, 2), Vec3(2, 0, -2)});
  scene.meshes.push_back(std::move(floor));
  TriangleMesh box;
  box.name = "open box";
  add_box(box, Vec3(0.0f, 0.50001f, 0.0f), Vec3(0.5f), 0.0f, 0.0f);
  box.indices.erase(box.indices.begin() + 12, box.indices.begin() + 18);  // its bottom goes (see add_box)
  scene.meshes.push_back(std::move(box));
  test::add_ceiling_lamp(scene, 1);
  scene.commit();
  MeshReport report;
  const float edge = 0.1f;
  const RadiosityMesh mesh = build_mesh(scene, MeshSettings{.max_edge = edge}, &report);
  const double lost = 16.0 - surface_area(mesh, 0);
  note("hovering_box", fmt("contact edges %.0f, buried elements %.0f, floor lost %.4f m²",
                           double(report.contact_edges), double(report.buried_elements), lost));
  EXPECT_EQ(report.contact_edges, 0u);
  EXPECT_GT(report.buried_elements, 0u);
  EXPECT_NEAR(lost, report.buried_area, 1e-5);
  EXPECT_LE(lost, 1.0 + 1e-5);
  const double shrunk = 1.0 - 2.0 * (4.0 / 3.0) * kRemeshScaleBound * edge;
  EXPECT_GE(lost, shrunk * shrunk);
}

/// A box of half size 1 with every edge rounded to radius `radius`, finely tessellated: each
/// face of a cube of `n`² quads per side, pushed onto the rounded box.
TriangleMesh rounded_box(float radius, int n) {
  TriangleMesh box;
  box.name = "rounded box";
  const auto rounded = [&](Vec3 p) {
    const Vec3 core = glm::clamp(p, Vec3(-1.0f + radius), Vec3(1.0f - radius));
    return core + radius * glm::normalize(p - core);
  };
  for (int axis = 0; axis < 3; ++axis)
    for (float side : {-1.0f, 1.0f}) {
      const auto base = static_cast<uint32_t>(box.positions.size());
      for (int i = 0; i <= n; ++i)
        for (int j = 0; j <= n; ++j) {
          Vec3 p(0.0f);
          p[axis] = side;
          p[(axis + 1) % 3] = -1.0f + 2.0f * float(i) / float(n);
          p[(axis + 2) % 3] = -1.0f + 2.0f * float(j) / float(n);
          box.positions.push_back(rounded(p));
        }
      for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) {
          const uint32_t a = base + uint32_t(i * (n + 1) + j), b = a + uint32_t(n + 1);
          if (side > 0)
            box.indices.insert(box.indices.end(), {a, b, b + 1, a, b + 1, a + 1});
          else
            box.indices.insert(box.indices.end(), {a, a + 1, b + 1, a, b + 1, b});
        }
    }
  return box;
}

// A receiver moved towards the centroid of a chord element across a rounded edge landed inside
// the input and saw its back: on the milk truck a ragged black band ran along the roof edge.
TEST(MeshRobust, VerticesOnRoundedEdgesReceiveTheSunTheyFace) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  scene.meshes.push_back(rounded_box(0.08f, 48));  // radius as below
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = glm::normalize(Vec3(-0.3f, -1.0f, -0.5f));
  sun.irradiance = Rgb(1.0f);
  scene.punctual_lights.push_back(sun);
  scene.commit();
  SolverSettings settings;
  settings.mesh.max_edge = 0.3f;  // almost four times the rounding radius
  settings.subdivision_levels = 0;
  settings.progress = false;
  const Solution sol = solve(scene, settings);
  // A convex box lit by the sun alone: a vertex receives E·cos θ, with θ measured from its
  // vertex normal, and nothing blocks the sun where the true surface faces it too. (The vertex
  // normal is the mean of its chords' and may lean far from the true normal where a fan
  // bridges a rounded edge; vertices where the two disagree are left out.) A receiver inside
  // the input got nothing: E·10⁻⁴ and less. Half of E·cos θ leaves room for the sun's grazing
  // rays past the rounded edge.
  const float radius = 0.08f;
  size_t lit = 0, dark = 0;
  for (size_t v = 0; v < sol.mesh.vertex_count(); ++v) {
    const Vec3 p = sol.mesh.positions[v];
    const Vec3 core = glm::clamp(p, Vec3(-1.0f + radius), Vec3(1.0f - radius));
    const float cos_true = glm::dot(glm::normalize(p - core), -sun.direction);
    const float cos_vertex = glm::dot(sol.mesh.normals[v], -sun.direction);
    if (cos_true < 0.5f || cos_vertex < 0.5f) continue;
    ++lit;
    dark += sol.vertex_irradiance[v].average() < 0.5f * cos_vertex * sun.irradiance.average();
  }
  note("rounded_box", fmt("%.0f vertices facing the sun, %.0f of them dark", double(lit), double(dark)));
  ASSERT_GT(lit, 50u);
  EXPECT_EQ(dark, 0u);
}

// Each vertex's visibility rays start from points spread over the surface it stands for: on its
// own elements' side (just above the floor, by 10⁻³ of the distance to the element's centroid),
// no farther from the vertex than half the distance to its nearest element centroid, and apart
// from each other wherever the vertex has four or more elements.
TEST(MeshRobust, VisibilityOriginsSpreadOverTheVertexsSurface) {
  Scene scene;
  scene.materials.push_back(Material::make_diffuse("grey", Rgb(0.5f)));
  TriangleMesh floor;
  add_quad(floor, {Vec3(-2, 0, -2), Vec3(-2, 0, 2), Vec3(2, 0, 2), Vec3(2, 0, -2)});
  scene.meshes.push_back(floor);
  scene.commit();
  MeshSettings settings;
  settings.max_edge = 0.25f;
  const RadiosityMesh mesh = build_mesh(scene, settings);
  const rc::scene::Scene geometry = element_scene(scene, mesh);
  const std::vector<Vec3> receivers = receiver_points(geometry, mesh);
  const std::vector<rc::scene::SurfacePoint> origins = visibility_origins(geometry, mesh, receivers);
  ASSERT_EQ(origins.size(), kVisibilityOrigins * mesh.vertex_count());
  std::vector<float> radius(mesh.vertex_count(), std::numeric_limits<float>::max());
  std::vector<int> fan(mesh.vertex_count(), 0);
  float longest = 0.0f;
  for (const auto& e : mesh.elements) {
    const Vec3 c = (mesh.positions[e[0]] + mesh.positions[e[1]] + mesh.positions[e[2]]) / 3.0f;
    for (uint32_t v : e) {
      radius[v] = std::min(radius[v], 0.5f * glm::distance(c, mesh.positions[v]));
      longest = std::max(longest, glm::distance(c, mesh.positions[v]));
      ++fan[v];
    }
  }
  size_t spread = 0, counted = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Vec3 p = mesh.positions[v];
    for (size_t k = 0; k < kVisibilityOrigins; ++k) {
      const Vec3 q = origins[kVisibilityOrigins * v + k].p;
      EXPECT_GT(q.y, 0.0f) << "vertex " << v;
      EXPECT_LE(q.y, 1.01e-3f * longest) << "vertex " << v;
      EXPECT_LE(glm::length(Vec3(q.x - p.x, 0.0f, q.z - p.z)), radius[v] * (1.0f + 1e-4f)) << "vertex " << v;
    }
    if (fan[v] < int(kVisibilityOrigins)) continue;
    ++counted;
    bool distinct = true;
    for (size_t i = 0; i < kVisibilityOrigins; ++i)
      for (size_t j = i + 1; j < kVisibilityOrigins; ++j)
        distinct &= glm::distance(origins[kVisibilityOrigins * v + i].p, origins[kVisibilityOrigins * v + j].p) > 1e-6f;
    spread += distinct;
  }
  ASSERT_GT(counted, 100u);
  EXPECT_EQ(spread, counted) << "vertices with four or more elements whose visibility origins coincide";
}

}  // namespace
}  // namespace gilt::radiosity
