// Hierarchical radiosity against closed forms and against its brute-force twin, progressive
// refinement on the same mesh; its determinism; and the growth of its link count.

#include <gtest/gtest.h>

#include <cmath>

#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/rng.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

rad::solver::SolverSettings settings(rad::solver::SolverKind kind, int elements, int subdivision_levels = 2) {
  rad::solver::SolverSettings s;
  s.solver = kind;
  s.mesh.elements = elements;
  s.subdivision_levels = subdivision_levels;
  s.progress = false;
  return s;
}

/// Area-weighted mean of the vertex radiance over the elements (each element the mean of its
/// vertices), channel mean.
double mean_radiance(const rad::solver::Solution& sol) {
  double sum = 0.0, area = 0.0;
  for (size_t e = 0; e < sol.mesh.element_count(); ++e) {
    const auto& el = sol.mesh.elements[e];
    double l = 0.0;
    for (uint32_t v : el) l += sol.vertex_radiance(v).average() / 3.0;
    sum += l * sol.mesh.element_area[e];
    area += sol.mesh.element_area[e];
  }
  return sum / area;
}

/// Appends the axis-aligned box [lo, hi], its faces outwards or (inward) towards its inside.
void box(rc::scene::TriangleMesh& m, rc::Vec3 lo, rc::Vec3 hi, bool inward) {
  const rc::Vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z},
                         {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {lo.x, hi.y, hi.z}, {hi.x, hi.y, hi.z}};
  const uint32_t base = uint32_t(m.positions.size());
  for (const rc::Vec3& corner : c) m.positions.push_back(corner);
  const uint32_t quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    if (inward)
      m.indices.insert(m.indices.end(), {base + q[0], base + q[2], base + q[1], base + q[0], base + q[3], base + q[2]});
    else
      m.indices.insert(m.indices.end(), {base + q[0], base + q[1], base + q[2], base + q[0], base + q[2], base + q[3]});
  }
}

/// A closed 6 × 3 × 6 room of white (ρ = 0.7) boxes around a 0.8 × 0.8 lamp of radiance 20 facing
/// down at height `lamp_y` (just under its ceiling by default), holding `boxes` (may be empty).
rc::scene::Scene lit_room(const rc::scene::TriangleMesh& boxes, float lamp_y = 2.99f) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("white", rc::Rgb(0.7f)));
  scene.materials.push_back(rc::scene::Material::make_emitter("lamp", rc::Rgb(20.0f)));
  rc::scene::TriangleMesh room;
  box(room, {-3, 0, -3}, {3, 3, 3}, true);
  scene.meshes.push_back(room);
  if (!boxes.indices.empty()) scene.meshes.push_back(boxes);
  rc::scene::TriangleMesh lamp;
  lamp.material = 1;
  lamp.positions = {
      {-0.4f, lamp_y, -0.4f}, {0.4f, lamp_y, -0.4f}, {0.4f, lamp_y, 0.4f}, {-0.4f, lamp_y, 0.4f}};
  lamp.indices = {0, 1, 2, 0, 2, 3};
  scene.meshes.push_back(lamp);
  scene.commit();
  return scene;
}

}  // namespace

/// Worst relative error of any vertex's radiance against Le / (1 − ρ) in the furnace.
double furnace_error(float rho, const rad::solver::SolverSettings& s) {
  const float le = 0.5f;
  rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
  scene.commit();
  const rad::solver::Solution sol = rad::solver::solve(scene, s);
  EXPECT_EQ(sol.solver, rad::solver::SolverKind::hierarchical);
  EXPECT_GT(sol.links, 0u);
  EXPECT_TRUE(sol.final_gather);
  EXPECT_EQ(sol.shadow_rays, 0u) << "a convex enclosure needs no visibility rays";
  const double expected = le / (1.0 - rho);
  double worst = 0.0;
  for (size_t v = 0; v < sol.mesh.vertex_count(); ++v)
    for (int k = 0; k < 3; ++k)
      worst = std::max(worst, std::abs(sol.vertex_radiance(v)[k] - expected) / expected);
  return worst;
}

// Closed box, uniform emission Le and albedo ρ: L = Le / (1 − ρ) at every vertex. No visibility
// noise (nothing occludes), so what remains is the hierarchy's discretisation: each link may
// carry link_tolerance of the power wrongly, each cluster in the vertex gather
// gather_tolerance of the irradiance, and the interreflection factor 1 / (1 − ρ) = 10 at ρ = 0.9
// multiplies the first. The error must fall as the tolerances do: at the defaults it is 1.6 %
// at ρ = 0.9 (0.55 % at 0.5), with link_tolerance ten times and gather_tolerance forty times
// smaller 0.19 % (0.09 %). The test asks for half the error or less at the tight setting, and
// under 0.3 % there (the progressive solver's furnace bound is 0.2 %).
TEST(HierarchicalRadiosity, FurnaceGivesLeOverOneMinusRho) {
  for (float rho : {0.5f, 0.9f}) {
    rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 600);
    s.tolerance = 1e-5;
    const double loose = furnace_error(rho, s);
    s.hierarchical.gather_tolerance = 5e-4;
    s.hierarchical.link_tolerance = 2e-7;
    const double tight = furnace_error(rho, s);
    RecordProperty("worst_error_defaults_rho_" + std::to_string(int(rho * 10)), std::to_string(loose));
    RecordProperty("worst_error_tight_rho_" + std::to_string(int(rho * 10)), std::to_string(tight));
    EXPECT_LT(tight, 0.5 * loose) << "rho " << rho;
    EXPECT_LT(tight, 3e-3) << "rho " << rho;
  }
}

// Far links read the kernel cos θ cos θ' / r² at their clusters' centres, which overstates ends
// that face each other; they take its average over the two clusters instead
// (cluster_kernel_scale). Without that, the furnace's mean read 4.4 % bright at link tolerance
// 2e-4 and 1.6 % at 2e-6 (3,000 elements, vertex colours from the elements: no final gather);
// with it, 0.5 % and 0.3 % dark. There is no visibility noise, so the mean is deterministic: the
// test asks that it lie within 1 % of the answer at the coarse tolerance, and that the coarse and
// the fine means differ by less than 1 %, well inside what the centres' reading gave and well
// outside what the average gives.
TEST(HierarchicalRadiosity, CoarseLinksDoNotBrightenTheFurnace) {
  const float le = 0.5f, rho = 0.8f;
  rc::scene::Scene scene = rc::io::furnace_scene(le, rho);
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 3000, 0);
  s.tolerance = 1e-5;
  s.hierarchical.final_gather = rad::solver::FinalGather::never;
  const double expected = le / (1.0 - rho);
  s.hierarchical.link_tolerance = 2e-4;
  const double coarse = mean_radiance(rad::solver::solve(scene, s)) / expected;
  s.hierarchical.link_tolerance = 2e-6;
  const double fine = mean_radiance(rad::solver::solve(scene, s)) / expected;
  RecordProperty("coarse_mean_over_answer", std::to_string(coarse));
  RecordProperty("fine_mean_over_answer", std::to_string(fine));
  EXPECT_NEAR(coarse, 1.0, 0.01);
  EXPECT_NEAR(coarse / fine, 1.0, 0.01);
}

// Every element of a closed room gathers exactly 1 from a unit radiosity everywhere (its form
// factors sum to 1), so the links' closure (keep_closure) must read 1 by area up to what the
// cluster models approximate: in the furnace, where nothing blocks, the mean radiance B =
// Le / (1 − ρ c̄) depends on nothing else, and the test above holds that within 1 % at 2e-4;
// so does the closure here. It is the measure that found the atrium's courtyard floor at 0.70
// (bench/README.md, "The hierarchical two-pass render's 7 % shortfall").
TEST(HierarchicalRadiosity, AClosedRoomsLinksCloseToOne) {
  rc::scene::Scene scene = rc::io::furnace_scene(0.5f, 0.8f);
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 3000, 0);
  s.hierarchical.final_gather = rad::solver::FinalGather::never;
  s.hierarchical.link_tolerance = 2e-4;
  s.hierarchical.keep_closure = true;
  const rad::solver::Solution sol = rad::solver::solve(scene, s);
  ASSERT_EQ(sol.element_closure.size(), sol.mesh.element_count());
  double area = 0.0, sum = 0.0;
  for (size_t e = 0; e < sol.mesh.element_count(); ++e) {
    ASSERT_TRUE(std::isfinite(sol.element_closure[e]));
    area += sol.mesh.element_area[e];
    sum += double(sol.element_closure[e]) * sol.mesh.element_area[e];
  }
  RecordProperty("closure_by_area", std::to_string(sum / area));
  EXPECT_NEAR(sum / area, 1.0, 0.01);
  s.hierarchical.keep_closure = false;
  EXPECT_TRUE(rad::solver::solve(scene, s).element_closure.empty());
}

// In a white furnace every element sees the same, so the iteration matrix ρ·gather has the one
// eigenvalue λ = ρ that matters, and plain Jacobi steps shrink the error by ρ each: from a
// residual of 0.44 to 10⁻⁶ at ρ = 0.8 takes about ln(10⁻⁶ · 0.2 / 0.44) / ln 0.8 = 66 gathers.
// Chebyshev's iteration, once it has read β = 0.8 from the first steps' ratios, shrinks it by
// β / (1 + √(1 − β²)) = 0.5 per gather: about 3 + ln(10⁻⁶ · 0.2 / 0.12) / ln 0.5 = 22 gathers
// (measured 24). It stops at a residual r < T (1 − β), so the error r / (1 − λ) is below T:
// the solution stopped at T = 10⁻² must lie within 1 % of the converged one (measured 0.32 %),
// and take fewer gathers.
TEST(HierarchicalRadiosity, StoppedIterationKeepsItsTolerance) {
  rc::scene::Scene scene = rc::io::furnace_scene(0.5f, 0.8f);
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 600, 0);
  s.hierarchical.final_gather = rad::solver::FinalGather::never;
  s.hierarchical.link_tolerance = 2e-7;
  s.tolerance = 1e-2;
  const rad::solver::Solution stopped = rad::solver::solve(scene, s);
  s.tolerance = 1e-6;
  const rad::solver::Solution converged = rad::solver::solve(scene, s);
  EXPECT_LE(converged.iterations, 30) << "plain Jacobi steps need about 66";
  EXPECT_LT(stopped.iterations + 10, converged.iterations);
  const double ratio = mean_radiance(stopped) / mean_radiance(converged);
  RecordProperty("stopped_over_converged", std::to_string(ratio));
  EXPECT_NEAR(ratio, 1.0, 1e-2);
}

/// Mean over vertices of |b − a| / a, where a is lit.
double mean_relative_difference(const rad::solver::Solution& a, const rad::solver::Solution& b) {
  double rel = 0.0;
  size_t n = 0;
  for (size_t v = 0; v < a.mesh.vertex_count(); ++v) {
    const double x = a.vertex_radiance(v).average(), y = b.vertex_radiance(v).average();
    if (x <= 0.0) continue;
    rel += std::abs(y - x) / x;
    ++n;
  }
  return rel / double(n);
}

// The brute-force twin: progressive refinement shoots every patch to every vertex with exact
// element form factors. On the same mesh of the Cornell box (no adaptive subdivision, so the
// seed does not change the mesh) the two must agree. The yardstick is progressive refinement's
// own noise: two of its runs with different seeds differ by d (measured 2.5 % mean relative
// difference per vertex). The hierarchical solution (measured 2.9 %, mean ratio 1.0007), whose visibility
// noise is of the same kind, may differ from one of them by at most 1.5 d per vertex, and on the mean by 1 %
// (the noise plus the clusters' point-source error, which the oracle bounds).
TEST(HierarchicalRadiosity, AgreesWithProgressiveOnCornell) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::progressive, 1500, 0);
  const rad::solver::Solution p0 = rad::solver::solve(scene, s);
  s.seed = 1;
  const rad::solver::Solution p1 = rad::solver::solve(scene, s);
  s.solver = rad::solver::SolverKind::hierarchical;
  const rad::solver::Solution h = rad::solver::solve(scene, s);
  ASSERT_EQ(p0.mesh.vertex_count(), h.mesh.vertex_count()) << "the same mesh";
  ASSERT_EQ(p0.mesh.vertex_count(), p1.mesh.vertex_count());
  const double noise = mean_relative_difference(p0, p1), difference = mean_relative_difference(p0, h);
  const double ratio = mean_radiance(h) / mean_radiance(p0);
  RecordProperty("progressive_seed_difference", std::to_string(noise));
  RecordProperty("hierarchical_difference", std::to_string(difference));
  RecordProperty("mean_ratio", std::to_string(ratio));
  EXPECT_NEAR(ratio, 1.0, 0.01);
  EXPECT_LT(difference, 1.5 * noise);
}

// The same scene and settings give the same solution bit for bit, for 1 and 2 threads.
TEST(HierarchicalRadiosity, IdenticalForAnyThreadCount) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 800);
  s.threads = 1;
  const rad::solver::Solution one = rad::solver::solve(scene, s);
  s.threads = 2;
  const rad::solver::Solution two = rad::solver::solve(scene, s);
  ASSERT_EQ(one.vertex_irradiance.size(), two.vertex_irradiance.size());
  EXPECT_EQ(one.links, two.links);
  for (size_t v = 0; v < one.vertex_irradiance.size(); ++v)
    for (int k = 0; k < 3; ++k)
      ASSERT_EQ(one.vertex_irradiance[v][k], two.vertex_irradiance[v][k]) << "vertex " << v;
}

// Clustering keeps linking from being quadratic: with 8× the elements the link count may grow by
// at most n log n (8 · log 8000 / log 1000 = 10.4×); linking pairs of elements would give 64×.
// (Measured: 6.6×, the linear growth of Hanrahan et al.'s fixed-tolerance oracle.)
TEST(HierarchicalRadiosity, LinksGrowSlowerThanTheElements) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  const rad::solver::Solution small = rad::solver::solve(scene, settings(rad::solver::SolverKind::hierarchical, 1000, 0));
  const rad::solver::Solution large = rad::solver::solve(scene, settings(rad::solver::SolverKind::hierarchical, 8000, 0));
  const double elements = double(large.mesh.element_count()) / double(small.mesh.element_count());
  const double links = double(large.links) / double(small.links);
  RecordProperty("element_ratio", std::to_string(elements));
  RecordProperty("link_ratio", std::to_string(links));
  EXPECT_GT(elements, 6.0);
  const double n_log_n =
      elements * std::log(double(large.mesh.element_count())) / std::log(double(small.mesh.element_count()));
  EXPECT_LT(links, n_log_n) << small.links << " → " << large.links << " links";
}

// `automatic` picks by the element count, and says why.
TEST(HierarchicalRadiosity, AutomaticChoosesByElementCount) {
  rad::solver::SolverSettings s;
  std::string why;
  EXPECT_EQ(rad::solver::choose_solver(s, 1000, &why), rad::solver::SolverKind::progressive);
  EXPECT_FALSE(why.empty());
  EXPECT_EQ(rad::solver::choose_solver(s, rad::solver::kHierarchicalElements, &why), rad::solver::SolverKind::hierarchical);
  s.solver = rad::solver::SolverKind::progressive;
  EXPECT_EQ(rad::solver::choose_solver(s, 10 * rad::solver::kHierarchicalElements), rad::solver::SolverKind::progressive);
}

// `automatic` chooses again after the direct light's refinement: the Cornell box meshed at about
// 17,000 elements stays below kHierarchicalElements until its shadow edges are bisected, and is
// then solved hierarchically, the reason saying both counts. (Without the second choice it was
// progressive refinement on 21,000 elements, whose cost grows with their square.)
TEST(HierarchicalRadiosity, AutomaticChoosesAgainAfterRefinement) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  const rad::solver::Solution sol =
      rad::solver::solve(scene, settings(rad::solver::SolverKind::automatic, 17000));
  const size_t meshed = sol.mesh_report.elements;
  ASSERT_LT(meshed, rad::solver::kHierarchicalElements);
  ASSERT_GE(sol.mesh.element_count(), rad::solver::kHierarchicalElements);
  EXPECT_EQ(sol.solver, rad::solver::SolverKind::hierarchical) << sol.solver_reason;
  EXPECT_NE(sol.solver_reason.find("after refining"), std::string::npos) << sol.solver_reason;
  EXPECT_GT(sol.links, 0u);
  EXPECT_LT(sol.residual, 1e-2);
}

// A closed room crowded with a grid of boxes, lit by a lamp: many of the faces that turn towards
// a source are partly hidden from it by their neighbours, and a cluster link shares one visible
// fraction among all of its receiving elements that face the source. Partly visible cluster
// links are therefore refined further (on Šibenik, accepting them left the solution 18 % dark
// against the path tracer). Here, at a link tolerance a hundred times the default (where most
// links are between clusters), the reflected light must still agree with progressive
// refinement, which traces every vertex's own shadow rays, within 3 %. (At the default tolerance
// the two agree here to 0.1 %; at this one the links' own error grows to 1–2 % either way, and
// 3 % is well clear of it and well short of the 18 % a sharing error caused.) The vertex final
// gather is off, so what the links deliver is what the vertices get.
TEST(HierarchicalRadiosity, PartlyHiddenFacesAgreeWithProgressive) {
  rc::scene::TriangleMesh boxes;
  rc::util::Rng rng(17);
  for (int i = 0; i < 36; ++i) {
    // A 6 × 6 grid of boxes, jittered but apart (at most 0.8 wide on a 0.9 pitch).
    const rc::Vec3 c(-2.25f + 0.9f * float(i % 6) + 0.05f * (rng.uniform() - 0.5f), 0.0f,
                     -2.25f + 0.9f * float(i / 6) + 0.05f * (rng.uniform() - 0.5f));
    const rc::Vec3 half(0.15f + 0.25f * rng.uniform(), 0.2f + 0.8f * rng.uniform(), 0.15f + 0.25f * rng.uniform());
    box(boxes, c - rc::Vec3(half.x, 0.0f, half.z), c + half * rc::Vec3(1.0f, 2.0f, 1.0f), false);
  }
  const rc::scene::Scene scene = lit_room(boxes);

  rad::solver::SolverSettings hs = settings(rad::solver::SolverKind::hierarchical, 4000, 0);
  hs.hierarchical.final_gather = rad::solver::FinalGather::never;
  hs.hierarchical.link_tolerance = 2e-4;
  const rad::solver::Solution h = rad::solver::solve(scene, hs);
  const rad::solver::Solution p = rad::solver::solve(scene, settings(rad::solver::SolverKind::progressive, 4000, 0));
  std::printf("hierarchical: %zu links, %d iterations, residual %g\n", h.links, h.iterations, h.residual);
  ASSERT_EQ(h.mesh.vertex_count(), p.mesh.vertex_count());
  double sum_h = 0.0, sum_p = 0.0;
  for (size_t v = 0; v < h.mesh.vertex_count(); ++v) {
    if (h.mesh.vertex_material[v] != 0) continue;
    sum_h += (h.vertex_irradiance[v] - h.vertex_direct[v]).average();
    sum_p += (p.vertex_irradiance[v] - p.vertex_direct[v]).average();
  }
  std::printf("mean reflected irradiance: hierarchical %.4f, progressive %.4f (ratio %.4f)\n", sum_h, sum_p,
              sum_h / sum_p);
  EXPECT_NEAR(sum_h / sum_p, 1.0, 0.03);
}

// Sixty boxes thrown into the room, overlapping each other and lying 10⁻³ above the floor: the
// exact point-to-element factors between a box's bottom and the floor a hair below overlap, and
// the links promised some elements more light than they could reflect; the iteration grew to
// 10³³. It must converge, and no vertex that does not emit may leave more than the geometric
// series allows: B ≤ ρ / (1 − ρ) · B_lamp, with B_lamp = π · 20.
TEST(HierarchicalRadiosity, OverlappingBoxesOverTheFloorConverge) {
  rc::scene::TriangleMesh boxes;
  rc::util::Rng rng(17);
  for (int i = 0; i < 60; ++i) {
    const rc::Vec3 c(rng.uniform() * 5.0f - 2.5f, 0.0f, rng.uniform() * 5.0f - 2.5f);
    const rc::Vec3 half(0.15f + 0.25f * rng.uniform(), 0.2f + 0.8f * rng.uniform(), 0.15f + 0.25f * rng.uniform());
    box(boxes, c - rc::Vec3(half.x, -0.001f, half.z), c + half * rc::Vec3(1.0f, 2.0f, 1.0f), false);
  }
  const rc::scene::Scene scene = lit_room(boxes);
  const rad::solver::Solution sol = rad::solver::solve(scene, settings(rad::solver::SolverKind::hierarchical, 4000, 0));
  std::printf("%d iterations, residual %g\n", sol.iterations, sol.residual);
  EXPECT_LT(sol.residual, 1e-3);
  const double bound = 0.7 / (1.0 - 0.7) * rc::kPi * 20.0;
  double worst = 0.0;
  for (size_t v = 0; v < sol.mesh.vertex_count(); ++v)
    if (sol.mesh.vertex_material[v] == 0) worst = std::max(worst, double(sol.vertex_radiosity[v].max_component()));
  EXPECT_TRUE(std::isfinite(worst));
  EXPECT_LE(worst, bound);
}

// The vertex final gather: `automatic` runs it on a compact scene (its probe predicts far fewer
// rays than the links traced) and then gives what `always` gives, bit for bit; `never` leaves
// each vertex its elements' gathered mean, and every mode says what it did.
TEST(HierarchicalRadiosity, FinalGatherModes) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 1000, 0);
  const rad::solver::Solution automatic = rad::solver::solve(scene, s);
  s.hierarchical.final_gather = rad::solver::FinalGather::always;
  const rad::solver::Solution always = rad::solver::solve(scene, s);
  s.hierarchical.final_gather = rad::solver::FinalGather::never;
  const rad::solver::Solution never = rad::solver::solve(scene, s);
  EXPECT_TRUE(automatic.final_gather) << automatic.final_gather_note;
  EXPECT_EQ(automatic.final_gather_note, "at every vertex");
  EXPECT_TRUE(always.final_gather);
  EXPECT_FALSE(never.final_gather);
  EXPECT_EQ(never.final_gather_note, "not asked for");
  ASSERT_EQ(automatic.vertex_irradiance.size(), always.vertex_irradiance.size());
  size_t differ = 0;
  for (size_t v = 0; v < always.vertex_irradiance.size(); ++v) {
    for (int k = 0; k < 3; ++k) ASSERT_EQ(automatic.vertex_irradiance[v][k], always.vertex_irradiance[v][k]);
    differ += !(never.vertex_irradiance[v] == always.vertex_irradiance[v]);
  }
  EXPECT_GT(differ, always.vertex_irradiance.size() / 2) << "the gather replaces the elements' mean";
  // Both estimate the same light: their means agree within the links' error (a few per cent).
  EXPECT_NEAR(mean_radiance(never) / mean_radiance(always), 1.0, 0.05);
}

// Under a time limit the links are made coarse first and refined while time allows. With ample
// time the ladder reaches the requested tolerance, and the solution agrees with the untimed one
// (each iteration stops at a relative change of 10⁻³; with ρ ≤ 0.8 what is left is below
// 10⁻³ / (1 − 0.8) = 0.5 %, so 1 % on the mean). With no time at all it stops early and the
// result is still finite and non-negative (the direct light, and what little was gathered).
TEST(HierarchicalRadiosity, TimeLimitRefinesLinksWhileTimeAllows) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  scene.commit();
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 1500, 0);
  const rad::solver::Solution untimed = rad::solver::solve(scene, s);
  EXPECT_DOUBLE_EQ(untimed.link_tolerance, rad::solver::kDefaultLinkTolerance);
  s.time_limit = 600.0;
  const rad::solver::Solution ample = rad::solver::solve(scene, s);
  EXPECT_DOUBLE_EQ(ample.link_tolerance, rad::solver::kDefaultLinkTolerance);
  EXPECT_FALSE(ample.linking_stopped);
  // Each level of the ladder refines the pairs the last one accepted: the split decisions above
  // them are those of linking from the root, and a pair's visibility rays are keyed by the pair,
  // so the last level makes exactly the links the untimed solve makes.
  EXPECT_EQ(ample.links, untimed.links);
  EXPECT_NEAR(mean_radiance(ample) / mean_radiance(untimed), 1.0, 0.01);
  // The ladder went through all four decades, the upper levels iterated only to ten times the
  // tolerance (their residual below it: Chebyshev's stop is tolerance × (1 − β)), the last one
  // to the tolerance itself; each level split only pairs the last one had accepted.
  ASSERT_EQ(untimed.ladder.size(), 1u);
  ASSERT_EQ(ample.ladder.size(), 4u);
  for (size_t l = 0; l < ample.ladder.size(); ++l) {
    const rad::solver::LadderLevel& level = ample.ladder[l];
    EXPECT_NEAR(level.link_tolerance, rad::solver::kDefaultLinkTolerance * std::pow(10.0, 3.0 - double(l)),
                1e-6 * level.link_tolerance);
    EXPECT_LT(level.residual, (l + 1 < ample.ladder.size() ? 10.0 : 1.0) * s.hierarchical.tolerance);
    EXPECT_EQ(level.finishing_iterations, 0);
    if (l == 0) continue;
    EXPECT_LE(level.splits, level.open_pairs);
    EXPECT_GE(level.links, ample.ladder[l - 1].links);
  }
  EXPECT_EQ(ample.ladder.back().links, ample.links);
  EXPECT_EQ(untimed.ladder[0].links, untimed.links);
  s.time_limit = 1e-6;
  const rad::solver::Solution none = rad::solver::solve(scene, s);
  EXPECT_FALSE(none.final_gather);
  for (const rc::Rgb& e : none.vertex_irradiance)
    for (int k = 0; k < 3; ++k) ASSERT_TRUE(std::isfinite(e[k]) && e[k] >= 0.0f);
}

// A closed room with walls, floor and roof 0.3 thick, under a sun and a sky: no light can reach
// its inside, whatever the tolerance. Clusters of a few elements on the roof held both its
// sunlit top and the ceiling 0.3 below, with nothing between them; such a cluster faces both
// ways, so its links shared one visible fraction among both faces (the rays between them cross
// only the slab's inside, which is open), and the sun on the roof lit the ceiling. The tree now
// splits such a node by the side its elements face. The room's reflected power is measured
// against what the tolerance lets one link carry wrongly, tol × (the scene's reflected power):
// 0.73 of that before (the whole leak is about one link's allowance), 0.008 now. The test allows
// a tenth: the exact answer is zero, and a leak of one link's allowance is what it rules out.
TEST(HierarchicalRadiosity, NoLightLeaksThroughAThickRoof) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("white", rc::Rgb(0.7f)));
  rc::scene::TriangleMesh walls;
  box(walls, {-3, 0, -3}, {3, 3, 3}, true);
  box(walls, {-3.3f, -0.3f, -3.3f}, {3.3f, 3.3f, 3.3f}, false);
  scene.meshes.push_back(walls);
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = glm::normalize(rc::Vec3(0.35f, -1.0f, 0.45f));
  sun.irradiance = rc::Rgb(8.0f);
  scene.punctual_lights.push_back(sun);
  scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
  scene.commit();
  constexpr double tolerance = 2e-3;
  rad::solver::SolverSettings s = settings(rad::solver::SolverKind::hierarchical, 8000, 0);
  s.hierarchical.link_tolerance = tolerance;
  s.hierarchical.final_gather = rad::solver::FinalGather::never;
  const rad::solver::Solution sol = rad::solver::solve(scene, s);
  double inside = 0.0, total = 0.0;
  for (size_t e = 0; e < sol.mesh.element_count(); ++e) {
    const auto& el = sol.mesh.elements[e];
    const rc::Vec3 c = (sol.mesh.positions[el[0]] + sol.mesh.positions[el[1]] + sol.mesh.positions[el[2]]) / 3.0f;
    const double power = double(sol.element_radiosity[e].average()) * sol.mesh.element_area[e];
    total += power;
    if (std::fabs(c.x) < 3.001f && std::fabs(c.z) < 3.001f && c.y > -0.001f && c.y < 3.001f) inside += power;
  }
  ASSERT_GT(total, 0.0);
  const double share = inside / (tolerance * total);
  std::printf("inside %.4g of one link's allowance (%zu elements)\n", share, sol.mesh.element_count());
  EXPECT_LT(share, 0.1);
}

// A ball of 80 faces hanging in the lit room receives its reflected light through cluster links
// to the ball as a whole, whose faces look every way: the link must give each face what falls on
// its own side. Against progressive refinement's exact factors on the same mesh, area-weighted
// over each half (the faces turned up see the dim ceiling, those turned down the bright floor),
// at link tolerance 2e-4. The clamped cosine's first two spherical-harmonic bands, used before,
// read 1.052 and 1.045 (light moved onto faces turned away from their sources); a clamped
// cosine per bin of the links' directions, with no allowance for their spread within a bin,
// 0.939 and 0.946; the spread-aware clamp now used, 0.978 and 0.979 (1.014 and 1.005 at 2e-7,
// where no cluster link reaches the ball). The tolerance is the agreement the two solvers are
// allowed on the same room in PartlyHiddenFacesAgreeWithProgressive.
TEST(HierarchicalRadiosity, ABallsFacesTakeTheLightOfTheirOwnSide) {
  rc::scene::TriangleMesh ball;
  const rc::Vec3 centre(1.2f, 1.0f, 0.8f);
  constexpr int kRings = 6, kSegments = 8;
  constexpr float kRadius = 0.35f;
  for (int i = 0; i <= kRings; ++i)
    for (int j = 0; j < kSegments; ++j) {
      const float theta = 3.14159265f * float(i) / float(kRings), phi = 6.2831853f * float(j) / float(kSegments);
      ball.positions.push_back(centre + kRadius * rc::Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                           std::sin(theta) * std::sin(phi)));
    }
  for (int i = 0; i < kRings; ++i)
    for (int j = 0; j < kSegments; ++j) {
      const uint32_t a = uint32_t(i * kSegments + j), b = uint32_t(i * kSegments + (j + 1) % kSegments);
      const uint32_t c = a + kSegments, d = b + kSegments;
      if (i > 0) ball.indices.insert(ball.indices.end(), {a, b, c});
      if (i + 1 < kRings) ball.indices.insert(ball.indices.end(), {b, d, c});
    }
  const rc::scene::Scene scene = lit_room(ball);

  rad::solver::SolverSettings hs = settings(rad::solver::SolverKind::hierarchical, 4000, 0);
  hs.hierarchical.final_gather = rad::solver::FinalGather::never;
  hs.hierarchical.link_tolerance = 2e-4;
  const rad::solver::Solution h = rad::solver::solve(scene, hs);
  const rad::solver::Solution p = rad::solver::solve(scene, settings(rad::solver::SolverKind::progressive, 4000, 0));
  ASSERT_EQ(h.mesh.element_count(), p.mesh.element_count());
  // Reflected irradiance (the direct light left out) over each half of the ball, area-weighted.
  double up_h = 0.0, up_p = 0.0, down_h = 0.0, down_p = 0.0;
  for (size_t e = 0; e < h.mesh.element_count(); ++e) {
    const auto& el = h.mesh.elements[e];
    const rc::Vec3 c = (h.mesh.positions[el[0]] + h.mesh.positions[el[1]] + h.mesh.positions[el[2]]) / 3.0f;
    if (glm::distance(c, centre) > 1.01f * kRadius) continue;
    double eh = 0.0, ep = 0.0;
    for (uint32_t v : el) {
      eh += (h.vertex_irradiance[v] - h.vertex_direct[v]).average();
      ep += (p.vertex_irradiance[v] - p.vertex_direct[v]).average();
    }
    const double a = h.mesh.element_area[e];
    (h.mesh.element_normal[e].y > 0.0f ? up_h : down_h) += a * eh;
    (h.mesh.element_normal[e].y > 0.0f ? up_p : down_p) += a * ep;
  }
  std::printf("upper half: hierarchical / progressive %.4f; lower half %.4f\n", up_h / up_p, down_h / down_p);
  EXPECT_NEAR(up_h / up_p, 1.0, 0.03);
  EXPECT_NEAR(down_h / down_p, 1.0, 0.03);
}

// An emitter emits on the side its face was wound to face, as the path tracer's do. A lamp hung
// under a lit ceiling sees light on its back, so orient_sides gives it a twin facing up; the
// twin is a surface of the lamp's material but must emit nothing (it did, and the lit family's
// vaulted colonnade, hung with 432 lamps, read 1.23 of the path tracer, 0.99 with its lamps
// one-sided). The ceiling straight above the lamp sees only its back, so its direct light is
// exactly zero: every solver must read it so, whatever the shadow rays.
TEST(HierarchicalRadiosity, ALampsTwinDoesNotEmit) {
  // The lamp half a metre under the ceiling: the ceiling over it is lit by the room and sees the
  // lamp's back from a distance.
  const rc::scene::Scene scene = lit_room({}, 2.5f);
  for (auto kind : {rad::solver::SolverKind::progressive, rad::solver::SolverKind::hierarchical}) {
    const rad::solver::Solution sol = rad::solver::solve(scene, settings(kind, 3000, 0));
    size_t lamp_twins = 0;
    for (size_t e = 0; e < sol.mesh.element_count(); ++e)
      lamp_twins += sol.mesh.twin(e) && sol.mesh.element_material[e] == 1;
    ASSERT_GT(lamp_twins, 0u) << "the lamp's back sees the lit ceiling, so it has a twin";
    int above = 0;
    for (size_t v = 0; v < sol.mesh.vertex_count(); ++v) {
      const rc::Vec3 p = sol.mesh.positions[v];
      if (p.y < 2.999f || std::abs(p.x) > 0.35f || std::abs(p.z) > 0.35f) continue;
      ++above;
      EXPECT_EQ(sol.vertex_direct[v].average(), 0.0f)
          << "ceiling vertex over the lamp at " << p.x << ", " << p.z;
    }
    EXPECT_GT(above, 0);
  }
}

// A 6 × 3 × 6 room open at the top to a uniform sky, then glazed there with a 4 cm pane: the
// sky must still light the floor, through the glass. With the same mesh and seed both rooms
// trace the same directions from each vertex, so the glazed floor's direct light over the open
// one's is a mean of the pane's transmittance (1 − F)² over the directions that reach the sky,
// and lies between its values at the steepest and the most oblique of them: exactly, with no
// allowance for noise. From the floor's middle (|x|, |z| < 0.5, rays leaving from visibility
// origins up to 15 cm further out) the sky is seen up to 60° from the vertical (F = 0.089 for
// η = 1.5), so the ratio lies in (0.911², 0.96²) = (0.830, 0.9216). Before glass let the sky
// through, the glazed floor read no direct light at all.
TEST(HierarchicalRadiosity, TheSkyLightsARoomThroughItsGlazedRoof) {
  const auto room = [](bool glazed) {
    rc::scene::Scene scene;
    scene.materials.push_back(rc::scene::Material::make_diffuse("white", rc::Rgb(0.7f)));
    scene.materials.push_back(rc::scene::Material::make_dielectric("glass", 1.5f));
    rc::scene::TriangleMesh walls;
    box(walls, {-3, 0, -3}, {3, 3, 3}, true);
    walls.indices.erase(walls.indices.begin() + 18, walls.indices.begin() + 24);  // the ceiling
    scene.meshes.push_back(walls);
    if (glazed) {
      rc::scene::TriangleMesh pane;
      pane.material = 1;
      box(pane, {-3, 3, -3}, {3, 3.04f, 3}, false);
      scene.meshes.push_back(pane);
    }
    scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
    scene.commit();
    return scene;
  };
  const rc::scene::Scene open = room(false), glazed = room(true);
  const float steep = 0.96f * 0.96f;
  const float f_oblique = rc::scene::fresnel_dielectric(0.5f, 1.5f);
  const float oblique = (1.0f - f_oblique) * (1.0f - f_oblique);
  for (auto kind : {rad::solver::SolverKind::progressive, rad::solver::SolverKind::hierarchical}) {
    const rad::solver::Solution a = rad::solver::solve(open, settings(kind, 2000, 0));
    const rad::solver::Solution b = rad::solver::solve(glazed, settings(kind, 2000, 0));
    ASSERT_EQ(a.mesh.vertex_count(), b.mesh.vertex_count());
    double through_open = 0.0, through_glass = 0.0;
    for (size_t v = 0; v < a.mesh.vertex_count(); ++v) {
      const rc::Vec3 p = a.mesh.positions[v];
      // The floor's top side (its underside has a twin, which sees the sky below the room).
      if (p.y > 1e-3f || a.mesh.normals[v].y < 0.5f || std::abs(p.x) > 0.5f || std::abs(p.z) > 0.5f) continue;
      ASSERT_EQ(p, b.mesh.positions[v]);
      through_open += a.vertex_direct[v].average();
      through_glass += b.vertex_direct[v].average();
    }
    ASSERT_GT(through_open, 0.0);
    const double ratio = through_glass / through_open;
    EXPECT_GT(ratio, oblique) << "solver " << int(kind);
    EXPECT_LT(ratio, steep) << "solver " << int(kind);
  }
}
