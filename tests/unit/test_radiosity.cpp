// Radiosity solver against closed forms: the white furnace, stability at high albedo, energy
// balance, and the work it skips.

#include <gtest/gtest.h>

#include <cmath>

#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

rad::solver::SolverSettings coarse(double tolerance, int elements) {
  rad::solver::SolverSettings s;
  s.tolerance = tolerance;
  s.mesh.elements = elements;
  s.progress = false;
  return s;
}

}  // namespace

// Closed box, uniform emission Le and albedo ρ: L = Le / (1 − ρ) at every vertex. The issue's
// bound is 0.2 %. Error sources: the stopping residual r (unshot power / emitted power) leaves
// at most a relative r of the answer unshot, here 1e-5; the form factors of a vertex to all
// elements of the closed box sum to 1 up to double rounding. So 0.2 % is met with room.
TEST(Radiosity, FurnaceGivesLeOverOneMinusRho) {
  for (float rho : {0.5f, 0.9f}) {
    const float le = 0.5f;
    rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
    scene.commit();
    const rad::solver::Solution sol = rad::solver::solve(scene, coarse(1e-5, 300));
    ASSERT_GT(sol.mesh.vertex_count(), 0u);
    EXPECT_TRUE(sol.convex_enclosure);
    EXPECT_EQ(sol.shadow_rays, 0u) << "a convex enclosure needs no visibility rays";
    EXPECT_LT(sol.residual, 1e-5);
    const double expected = le / (1.0 - rho);
    double worst = 0.0;
    for (size_t v = 0; v < sol.mesh.vertex_count(); ++v)
      for (int k = 0; k < 3; ++k) worst = std::max(worst, std::abs(sol.vertex_radiance(v)[k] - expected) / expected);
    EXPECT_LT(worst, 2e-3) << "rho " << rho;
  }
}

// The ambient term of a partial solution. Its premise (Cohen et al. 1988) is that the unshot
// radiosity U is spread evenly; then its eventual contribution to every vertex is
// ρU + ρ²U + … = ρ Ū / (1 − ρ), exactly the display term ρ · ambient. Progressive refinement
// leaves U uneven (the brightest patches went first), so the term is exact on average, not
// vertex by vertex: stopped early, the partial furnace lacks about the residual's share of the
// answer everywhere, and the ambient term must take the mean error down by an order of magnitude
// (the area-weighted mean of ρ · ambient equals the mean missing radiosity up to the residual
// left after the final answer's own 0.2 % bound). The exported values never include it.
TEST(Radiosity, AmbientTermCompletesAPartialFurnace) {
  const float le = 0.5f, rho = 0.8f;
  rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
  scene.commit();
  const rad::solver::Solution sol = rad::solver::solve(scene, coarse(5e-2, 300));
  ASSERT_GT(sol.residual, 1e-2);
  const double expected = le / (1.0 - rho);
  double partial_error = 0.0, display_error = 0.0, area = 0.0;
  for (size_t e = 0; e < sol.mesh.element_count(); ++e) {
    const double partial = sol.element_radiosity[e].average() / 3.14159265358979;
    const double display = partial + rho * sol.ambient.average() / 3.14159265358979;
    const double a = sol.mesh.element_area[e];
    partial_error += a * (partial - expected) / expected;
    display_error += a * (display - expected) / expected;
    area += a;
  }
  partial_error /= area, display_error /= area;
  RecordProperty("mean_partial_error", std::to_string(partial_error));
  RecordProperty("mean_display_error", std::to_string(display_error));
  EXPECT_LT(partial_error, -1e-2) << "the partial solution should visibly lack the unshot light";
  EXPECT_LT(std::abs(display_error), 0.1 * std::abs(partial_error));
}

// Albedo 0.99: no divergence, no negative or non-finite value, and the solution still heads for
// Le / (1 − ρ) = 100 Le. With a residual r the missing part is at most r of the answer.
TEST(Radiosity, StableAtAlbedo099) {
  rc::scene::Scene scene = rc::io::furnace_scene(1.0f, 0.99f);
  scene.commit();
  const rad::solver::Solution sol = rad::solver::solve(scene, coarse(1e-3, 120));
  EXPECT_LT(sol.residual, 1e-3);
  for (size_t v = 0; v < sol.mesh.vertex_count(); ++v) {
    const rc::Rgb l = sol.vertex_radiance(v);
    ASSERT_TRUE(l.is_finite());
    EXPECT_GE(l.r, 0.0f);
    EXPECT_LE(l.average(), 100.0f * (1.0f + 1e-4f)) << "above the closed-form answer: energy was created";
    EXPECT_GE(l.average(), 100.0f * (1.0f - 2e-3f)) << "more than the residual is missing";
  }
}

// Energy balance in the Cornell box closed by a front wall: with nowhere to escape, the power the
// surfaces absorb, Σ A (1 − ρ) E over elements, must equal what the light emits as the mesh
// refines. Each element's irradiance is the mean of its vertices', a first-order estimate in the
// element size h where the field bends (near the light), so the imbalance must shrink at least
// in proportion to h: with 4× the elements (h/2) it must fall to 0.6 of its value or less (first
// order gives 0.5; measured 8.1 % → 4.0 % → 1.3 % at 400, 1500, 6000 elements).
double closed_cornell_imbalance(int elements) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  rc::Bounds3 box;
  for (const auto& m : scene.meshes)
    for (const auto& p : m.positions) box.extend(p);
  rc::scene::TriangleMesh front;
  front.name = "front_wall";
  const float z = box.lo.z;
  front.positions = {{box.lo.x, box.lo.y, z}, {box.hi.x, box.lo.y, z}, {box.hi.x, box.hi.y, z}, {box.lo.x, box.hi.y, z}};
  front.indices = {0, 1, 2, 0, 2, 3};  // counter-clockwise seen from +z: faces into the box
  front.material = scene.meshes[0].material;  // the floor's white
  scene.meshes.push_back(front);
  scene.commit();
  const rad::solver::Solution sol = rad::solver::solve(scene, coarse(1e-5, elements));
  EXPECT_FALSE(sol.convex_enclosure) << "the blocks occlude";
  EXPECT_GT(sol.shadow_rays, 0u);
  double emitted = 0.0, absorbed = 0.0;
  for (size_t e = 0; e < sol.mesh.element_count(); ++e) {
    const auto& el = sol.mesh.elements[e];
    const rc::scene::Material& m = scene.materials[sol.mesh.element_material[e]];
    const rc::Rgb irradiance = (sol.vertex_irradiance[el[0]] + sol.vertex_irradiance[el[1]] +
                                sol.vertex_irradiance[el[2]]) * (1.0f / 3.0f);
    emitted += double((m.emission * rc::kPi).average()) * sol.mesh.element_area[e];
    absorbed += double(((rc::Rgb(1.0f) - m.albedo) * irradiance).average()) * sol.mesh.element_area[e];
  }
  EXPECT_GT(emitted, 0.0);
  return std::abs(1.0 - absorbed / emitted);
}

TEST(Radiosity, ClosedCornellEnergyBalanceConverges) {
  const double coarse_error = closed_cornell_imbalance(400), fine_error = closed_cornell_imbalance(1600);
  ::testing::Test::RecordProperty("imbalance_400", std::to_string(coarse_error));
  ::testing::Test::RecordProperty("imbalance_1600", std::to_string(fine_error));
  EXPECT_LT(fine_error, 0.6 * coarse_error) << "coarse " << coarse_error << ", fine " << fine_error;
  EXPECT_LT(coarse_error, 0.15) << "the coarse mesh is already off by more than first-order error explains";
}
