// solve_within: a radiosity mesh sized to a time budget. What it chooses depends on the
// machine's speed, so these tests check the model and which solves run, not times.

#include <algorithm>
#include <gtest/gtest.h>

#include "radiosity/solver/budget.h"
#include "radiosity/mesh/mesh.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

rad::solver::SolverSettings quiet() {
  rad::solver::SolverSettings s;
  s.progress = false;
  s.subdivision_levels = 0;  // the element counts asked for are the counts meshed
  return s;
}

}  // namespace

// The cost model: n² from the pilot's point, capped, nothing without time or a pilot.
TEST(RadiosityBudget, FittedCountGrowsAsTheSquareRootOfTheTime) {
  EXPECT_DOUBLE_EQ(rad::solver::fitted_elements(1000, 0.1, 0.4, 4000.0), 2000.0);
  EXPECT_DOUBLE_EQ(rad::solver::fitted_elements(1000, 0.1, 0.025, 4000.0), 500.0);
  EXPECT_DOUBLE_EQ(rad::solver::fitted_elements(1000, 0.1, 1e6, 4000.0), 4000.0);
  EXPECT_EQ(rad::solver::fitted_elements(1000, 0.1, 0.0, 4000.0), 0.0);
  EXPECT_EQ(rad::solver::fitted_elements(1000, 0.1, -1.0, 4000.0), 0.0);
  EXPECT_EQ(rad::solver::fitted_elements(1000, 0.0, 1.0, 4000.0), 0.0);
  EXPECT_EQ(rad::solver::fitted_elements(0, 0.1, 1.0, 4000.0), 0.0);
}

// A long budget gets the default mesh, not a finer one.
TEST(RadiosityBudget, ALongBudgetGetsTheDefaultMesh) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::BudgetFit fit;
  const rad::solver::Solution fitted = rad::solver::solve_within(scene, quiet(), 1e5, &fit);
  const rad::solver::Solution plain = rad::solver::solve(scene, quiet());
  ASSERT_GT(fit.requested_elements, 0);
  EXPECT_NEAR(double(fit.requested_elements), rad::mesh::kDefaultElements, 1.0);
  EXPECT_EQ(fitted.mesh.element_count(), plain.mesh.element_count());
}

// A mesh size the user set is kept: no pilot runs.
TEST(RadiosityBudget, AMeshSizeTheUserSetIsKept) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::SolverSettings s = quiet();
  s.mesh.elements = 600;
  rad::solver::BudgetFit fit;
  const rad::solver::Solution sol = rad::solver::solve_within(scene, s, 30.0, &fit);
  EXPECT_FALSE(fit.fitted);
  EXPECT_EQ(fit.pilot_elements, 0u);
  EXPECT_TRUE(fit.note.empty());
  EXPECT_LT(sol.mesh.element_count(), 1000u);  // the 600 asked for, not the default 4,000
}

// On a scene of few triangles the pilot runs at about kPilotElements, and the solve returned is
// either the pilot (too little time for a finer mesh) or one at the count the fit asked for.
TEST(RadiosityBudget, ASmallSceneIsFittedFromAPilot) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::BudgetFit fit;
  const rad::solver::Solution sol = rad::solver::solve_within(scene, quiet(), 2.0, &fit);
  EXPECT_TRUE(fit.fitted);
  EXPECT_NEAR(double(fit.pilot_elements), rad::solver::kPilotElements, 0.2 * rad::solver::kPilotElements);
  EXPECT_FALSE(fit.note.empty());
  if (fit.requested_elements == 0) {
    EXPECT_EQ(sol.mesh.element_count(), fit.pilot_elements);
  } else {
    EXPECT_GT(fit.requested_elements, int(1.25 * double(fit.pilot_elements)) - 1);
    // The final solve meshes at the request: its mesh is the one build_mesh makes for it. (How
    // near a request the mesher lands depends on the count, as whole edges divide the walls: not
    // this test's concern, and the request itself depends on this machine's speed.)
    // Unless the final solve's meshing ran out of its share of the time (a slow build, under the
    // sanitizers): then it says so, and keeps pieces as they came.
    const bool cut_short = std::any_of(sol.mesh_report.warnings.begin(), sol.mesh_report.warnings.end(),
                                       [](const std::string& w) { return w.find("--time left no time") != std::string::npos; });
    rad::solver::SolverSettings asked = quiet();
    asked.mesh.elements = fit.requested_elements;
    if (!cut_short) {
      EXPECT_EQ(sol.mesh.element_count(), rad::mesh::build_mesh(scene, asked.mesh).element_count());
    }
  }
}

// Without a budget, or on an input whose own triangles set the element count, one solve runs.
TEST(RadiosityBudget, NoPilotWithoutABudgetOrOnALargeInput) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::BudgetFit fit;
  rad::solver::solve_within(scene, quiet(), 0.0, &fit);
  EXPECT_EQ(fit.pilot_elements, 0u);

  rc::scene::Scene fine;
  fine.materials.push_back(rc::scene::Material::make_diffuse("white", rc::Rgb(0.5f)));
  fine.materials.push_back(rc::scene::Material::make_emitter("lamp", rc::Rgb(1.0f)));
  rc::scene::TriangleMesh grid;  // a 16 × 16 floor of 512 triangles
  for (int j = 0; j <= 16; ++j)
    for (int i = 0; i <= 16; ++i) grid.positions.push_back({float(i) / 16.0f, 0.0f, float(j) / 16.0f});
  for (uint32_t j = 0; j < 16; ++j)
    for (uint32_t i = 0; i < 16; ++i) {
      const uint32_t a = j * 17 + i, b = a + 1, c = a + 18, d = a + 17;
      grid.indices.insert(grid.indices.end(), {a, d, c, a, c, b});
    }
  fine.meshes.push_back(grid);
  rc::scene::TriangleMesh lamp;
  lamp.positions = {{0.4f, 1.0f, 0.4f}, {0.6f, 1.0f, 0.4f}, {0.6f, 1.0f, 0.6f}, {0.4f, 1.0f, 0.6f}};
  lamp.indices = {0, 1, 2, 0, 2, 3};  // facing down
  lamp.material = 1;
  fine.meshes.push_back(lamp);
  fine.commit();
  ASSERT_GE(fine.triangle_count(), size_t(rad::solver::kPilotElements / 2));
  rad::solver::solve_within(fine, quiet(), 30.0, &fit);
  EXPECT_EQ(fit.pilot_elements, 0u);
  EXPECT_FALSE(fit.fitted);
}
