// Adaptive subdivision: longest-edge bisection keeps the mesh conforming (no vertex in the middle
// of another element's edge, which Gouraud interpolation would show as a crack), keeps area and
// orientation, and the solver refines where the direct light changes steeply.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

/// Vertices lying strictly inside an edge of an element they do not belong to: T-junctions.
/// Brute force over every vertex and edge, with a tolerance of 1e-5 of the edge's length.
size_t count_t_junctions(const rad::mesh::RadiosityMesh& mesh) {
  size_t found = 0;
  for (size_t e = 0; e < mesh.element_count(); ++e)
    for (int i = 0; i < 3; ++i) {
      const rc::Vec3 a = mesh.positions[mesh.elements[e][i]], b = mesh.positions[mesh.elements[e][(i + 1) % 3]];
      const rc::Vec3 ab = b - a;
      const float len2 = glm::dot(ab, ab);
      for (size_t v = 0; v < mesh.vertex_count(); ++v) {
        const rc::Vec3 p = mesh.positions[v];
        const float t = glm::dot(p - a, ab) / len2;
        if (!(t > 1e-4f && t < 1.0f - 1e-4f)) continue;
        const rc::Vec3 off = p - (a + t * ab);
        if (glm::dot(off, off) < 1e-10f * len2) ++found;
      }
    }
  return found;
}

double total_area(const rad::mesh::RadiosityMesh& mesh) {
  return std::accumulate(mesh.element_area.begin(), mesh.element_area.end(), 0.0);
}

rad::mesh::RadiosityMesh cornell_mesh(int elements) {
  rc::scene::Scene scene = rc::io::load_scene("cornell");
  rad::mesh::MeshSettings settings;
  settings.elements = elements;
  return rad::mesh::build_mesh(scene, settings);
}

}  // namespace

TEST(MeshRefine, BisectionStaysConformingAndKeepsArea) {
  rad::mesh::RadiosityMesh mesh = cornell_mesh(300);
  ASSERT_EQ(count_t_junctions(mesh), 0u) << "the input mesh already has T-junctions";
  const double area = total_area(mesh);
  const size_t elements = mesh.element_count();
  // Three rounds over every third element, including elements on sharp and material borders.
  for (int round = 0; round < 3; ++round) {
    std::vector<uint32_t> marked;
    for (uint32_t e = 0; e < mesh.element_count(); e += 3) marked.push_back(e);
    EXPECT_GT(rad::mesh::split_longest_edges(mesh, marked, 0.0f), 0u);
  }
  EXPECT_GT(mesh.element_count(), elements + elements / 2);
  EXPECT_EQ(count_t_junctions(mesh), 0u);
  // Area: halves sum exactly to their parent up to float rounding of the halves (1e-6 relative each).
  EXPECT_NEAR(total_area(mesh), area, 1e-5 * area);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const rc::Vec3 cross = glm::cross(mesh.positions[el[1]] - mesh.positions[el[0]],
                                      mesh.positions[el[2]] - mesh.positions[el[0]]);
    ASSERT_GT(glm::dot(cross, mesh.element_normal[e]), 0.0f) << "element " << e << " flipped";
    EXPECT_NEAR(0.5f * glm::length(cross), mesh.element_area[e], 1e-3f * mesh.element_area[e]);
    for (uint32_t v : el) EXPECT_EQ(mesh.vertex_material[v], mesh.element_material[e]);
  }
}

TEST(MeshRefine, MinimumEdgeStopsSplitting) {
  rad::mesh::RadiosityMesh mesh = cornell_mesh(300);
  std::vector<uint32_t> all(mesh.element_count());
  std::iota(all.begin(), all.end(), 0u);
  EXPECT_EQ(rad::mesh::split_longest_edges(mesh, all, 1e6f), 0u);
  EXPECT_EQ(mesh.element_count(), all.size());
}

TEST(MeshRefine, SolverRefinesShadowBoundariesAndStaysConforming) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  rad::solver::SolverSettings settings;
  settings.mesh.elements = 400;
  settings.tolerance = 1e-2;
  settings.progress = false;
  const rad::solver::Solution flat = [&] {
    rad::solver::SolverSettings s = settings;
    s.subdivision_levels = 0;
    return rad::solver::solve(scene, s);
  }();
  const rad::solver::Solution refined = rad::solver::solve(scene, settings);
  EXPECT_EQ(flat.refined_elements, 0u);
  EXPECT_GT(refined.refined_elements, 0u);
  EXPECT_GT(refined.mesh.element_count(), flat.mesh.element_count());
  EXPECT_EQ(count_t_junctions(refined.mesh), 0u);
  for (size_t v = 0; v < refined.mesh.vertex_count(); ++v) {
    ASSERT_TRUE(refined.vertex_radiosity[v].is_finite());
    ASSERT_GE(std::min({refined.vertex_radiosity[v].r, refined.vertex_radiosity[v].g, refined.vertex_radiosity[v].b}), 0.0f);
  }
}
