// The two-pass radiosity view's reading of the solution where a gather ray lands.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>

#include "radiosity/bake/view.h"
#include "radiosity/mesh/element_scene.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/render/path_tracer.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
using gilt::test::quad;
namespace rad = gilt::radiosity;
using rc::Rgb;
using rc::Vec3;

namespace {

/// Gives `scene` (its meshes added, all of material 0) a white diffuse material (0.8) and a sun
/// of unit irradiance travelling along `sun_direction`, commits it, and solves it with elements
/// of at most `max_edge`.
rad::solver::Solution solve_sunlit(rc::scene::Scene& scene, Vec3 sun_direction, float max_edge,
                                   bool two_sided = true) {
  scene.materials.push_back(rc::scene::Material::make_diffuse("white", Rgb(0.8f)));
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = glm::normalize(sun_direction);
  sun.irradiance = Rgb(1.0f);
  scene.punctual_lights.push_back(sun);
  scene.commit();
  rad::solver::SolverSettings settings;
  settings.mesh.max_edge = max_edge;
  settings.mesh.two_sided = two_sided;
  settings.progress = false;
  return rad::solver::solve(scene, settings);
}

}  // namespace

// A one-sided floor (front up) lit by the sun and by a sunlit wall beside it, and under it a
// one-sided plate facing down, whose upper side has no element. A gather ray that meets that
// upper side must not read the floor's light: the floor is the nearest element facing the same
// way, within the view's reach, but it lies on the other side of itself. (On Šibenik's nave,
// 7 % of gather rays met such sides, and those that read another surface's light read 15 times
// what a shadow ray found there.)
TEST(RadiosityView, DoesNotReadTheSolutionThroughASurface) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));        // floor, up
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}, {-1, 0, 1}));      // wall, +x
  scene.meshes.push_back(quad({-0.5f, -0.3f, -0.5f}, {0.5f, -0.3f, -0.5f}, {0.5f, -0.3f, 0.5f},
                              {-0.5f, -0.3f, 0.5f}));                                   // plate, down
  // Elements of 0.5: the view looks up to 1.0 away, so the floor is within reach of the plate.
  const rad::solver::Solution sol = solve_sunlit(scene, Vec3(-1.0f, -1.0f, 0.2f), 0.5f);
  const rad::bake::RadiosityView view(scene, sol, rad::bake::ViewMode::two_pass, false);

  const Vec3 up(0.0f, 1.0f, 0.0f);
  const rc::scene::SurfacePoint on_floor{Vec3(0.2f, 0.0f, 0.1f), Vec3(1e-6f), up};
  const std::optional<Rgb> floor = view.indirect_irradiance(on_floor, up);
  ASSERT_TRUE(floor.has_value());
  EXPECT_GT(floor->average(), 0.0f) << "the floor gathers the wall's light";
  // The floor's element is found for the plate's upper side (0.3 below it) ...
  const Vec3 below(0.2f, -0.3f, 0.1f);
  const auto at = view.locate(below, up);
  ASSERT_TRUE(at.has_value());
  EXPECT_NEAR(at->distance, 0.3f, 1e-4f);
  // ... but its light is not the plate's.
  EXPECT_FALSE(view.indirect_irradiance(rc::scene::SurfacePoint{below, Vec3(1e-6f), up}, up).has_value());
}

// The view and the vertex bake read the solution by the element a ray or a nearest-point query
// finds in element_scene(), so its triangle index must be the element's. An element that rounds
// to no area in float (three collinear vertices) must not renumber the elements after it, as
// Scene::commit's dropping of degenerate triangles once did: on Šibenik the bake read the light of
// an element 11 m from where its gather rays landed.
TEST(RadiosityView, ElementSceneKeepsEveryElementsIndex) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("white", Rgb(0.8f)));
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));
  scene.commit();
  rad::mesh::RadiosityMesh mesh;
  mesh.positions = {{-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {0, 0, 0}, {0.5f, 0, 0}, {1, 0, 0}};
  mesh.elements = {{4, 5, 6}, {0, 1, 2}, {0, 2, 3}};  // the first is a segment, not a triangle
  const rc::scene::Scene geometry = rad::mesh::element_scene(scene, mesh);
  ASSERT_EQ(geometry.meshes[0].triangle_count(), 3u);
  const Vec3 up(0.0f, 1.0f, 0.0f);
  const struct {
    Vec3 p;
    uint32_t element;
  } points[] = {{{-0.5f, 0.0f, 0.5f}, 1u}, {{0.5f, 0.0f, -0.5f}, 2u}};
  for (const auto& c : points) {
    const std::optional<rc::scene::Hit> hit = geometry.intersect(rc::scene::Ray{c.p + up, -up});
    ASSERT_TRUE(hit.has_value());
    EXPECT_EQ(hit->prim_id, c.element);
    const std::optional<rc::scene::Hit> near = geometry.nearest_triangle(0, c.p + 0.01f * up, 1.0f, up, 0.5f);
    ASSERT_TRUE(near.has_value());
    EXPECT_EQ(near->prim_id, c.element);
  }
}

namespace {

/// Mean and standard error of n independent samples drawn by `sample(i)`.
template <class Sample>
std::pair<double, double> mean_and_error(int n, Sample sample) {
  double sum = 0.0, squares = 0.0;
  for (int i = 0; i < n; ++i) {
    const double x = sample(i);
    sum += x;
    squares += x * x;
  }
  const double mean = sum / n;
  return {mean, std::sqrt(std::max(0.0, squares / n - mean * mean) / (n - 1))};
}

/// Irradiance at the point p facing n, from 2^15 of the view's gathered samples and from as many
/// path-traced ones (a white Lambertian probe standing in for the surface), each with its
/// standard error.
struct GatherAgainstTrace {
  double gathered, gather_error, traced, trace_error;
  /// Four standard errors of the difference, both estimated from the samples.
  double tolerance() const { return 4.0 * std::hypot(gather_error, trace_error); }
};
GatherAgainstTrace gather_against_trace(const rc::scene::Scene& scene, const rad::bake::RadiosityView& view, Vec3 p, Vec3 n) {
  static const rc::scene::Material white = rc::scene::Material::make_diffuse("irradiance probe", Rgb(1.0f));
  rc::render::PathSettings probe;
  probe.first_surface = &white;
  constexpr int kSamples = 1 << 15;
  GatherAgainstTrace g;
  std::tie(g.gathered, g.gather_error) = mean_and_error(kSamples, [&](int i) {
    rc::render::SampleContext ctx{rc::render::Sampler(rc::util::Rng::for_item(1, 0, uint64_t(i))), 0};
    return double(view.gathered_sample(rad::mesh::mesh_surface_point(p, n), ctx).g);
  });
  std::tie(g.traced, g.trace_error) = mean_and_error(kSamples, [&](int i) {
    rc::render::SampleContext ctx{rc::render::Sampler(rc::util::Rng::for_item(2, 0, uint64_t(i))), 0};
    const rc::scene::Ray in{p + 0.01f * n, -n, 0.02f};
    return double(rc::render::path_radiance(scene, in, ctx, probe).g) * rc::kPi;
  });
  return g;
}

}  // namespace

// A slab a hair above the floor, under the sun and a sky: under it the light is what slips in
// through the 5-cm gap and bounces between the two, and the elements (25 cm across) cannot
// resolve it: the slab's underside reads the sunlit floor beyond its edge across a whole element.
// A gather from under the slab meets the underside 5 cm away, closer than the element's size, and
// must trace on rather than read it (RadiosityView::gather, near hits): its irradiance then agrees
// with the path tracer's. The tolerance is four standard errors of the difference, both estimated
// from the samples. (Reading the underside where the rays land, the floor point came out
// 1.6 times the path tracer's.)
TEST(RadiosityView, AGatherUnderALowSlabAgreesWithThePathTracer) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", Rgb(0.6f)));
  scene.meshes.push_back(quad({-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}));  // floor, up
  const float s = 0.75f, lo = 0.05f, hi = 0.1f;
  scene.meshes.push_back(quad({-s, lo, -s}, {s, lo, -s}, {s, lo, s}, {-s, lo, s}));  // underside, down
  scene.meshes.push_back(quad({-s, hi, -s}, {-s, hi, s}, {s, hi, s}, {s, hi, -s}));  // top, up
  scene.meshes.push_back(quad({s, lo, -s}, {s, hi, -s}, {s, hi, s}, {s, lo, s}));    // +x
  scene.meshes.push_back(quad({-s, lo, -s}, {-s, lo, s}, {-s, hi, s}, {-s, hi, -s})); // -x
  scene.meshes.push_back(quad({-s, lo, s}, {s, lo, s}, {s, hi, s}, {-s, hi, s}));    // +z
  scene.meshes.push_back(quad({-s, lo, -s}, {-s, hi, -s}, {s, hi, -s}, {s, lo, -s})); // -z
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = glm::normalize(Vec3(0.3f, -1.0f, 0.2f));
  sun.irradiance = Rgb(2.0f);
  rc::scene::Light sky;
  sky.kind = rc::scene::LightKind::environment;
  sky.radiance = Rgb(0.3f);
  scene.punctual_lights = {sun, sky};
  scene.commit();
  rad::solver::SolverSettings settings;
  settings.mesh.max_edge = 0.25f;
  settings.progress = false;
  const rad::solver::Solution sol = rad::solver::solve(scene, settings);
  const rad::bake::RadiosityView view(scene, sol, rad::bake::ViewMode::mesh, false);

  const Vec3 up(0.0f, 1.0f, 0.0f);
  struct Case {
    Vec3 p, n;
  };
  for (const Case& c : {Case{Vec3(0.45f, 0.0f, 0.1f), up}, Case{Vec3(0.45f, lo, 0.1f), -up}}) {
    const GatherAgainstTrace g = gather_against_trace(scene, view, c.p, c.n);
    EXPECT_GT(g.traced, 0.0) << "light reaches under the slab";
    EXPECT_NEAR(g.gathered, g.traced, g.tolerance())
        << "at " << c.p.y << " facing " << c.n.y << ": the path tracer's error " << g.trace_error;
  }
}

// A shed: a floor, a wall that stands on it (its two faces coincide, so the floor is not buried
// under it: the contact line is imprinted and the floor's elements on both sides meet there),
// and a roof on the wall's inner side. The sun, from outside, lights the floor beyond the wall;
// the sky comes in at the open sides. A floor vertex on the contact line, shared by the sunlit
// elements outside and the dark ones inside, carried the sunlight into the shed by
// interpolation: gathers from the wall's inner face and the roof's underside read 1.08 and 1.16
// times the path tracer's irradiance with the progressive solver, 1.01 and 1.07 with the
// hierarchical one. The mesher now gives such vertices a copy for each side, and both solvers
// agree with the path tracer within four standard errors of the difference (both estimated from
// the samples).
TEST(RadiosityView, NoLightLeaksAcrossAContactLine) {
  rc::scene::Scene scene;
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", Rgb(0.6f)));
  scene.meshes.push_back(quad({-3, 0, -3}, {-3, 0, 3}, {3, 0, 3}, {3, 0, -3}));              // floor, up
  scene.meshes.push_back(quad({1, -0.5f, -3}, {1, 2.5f, -3}, {1, 2.5f, 3}, {1, -0.5f, 3}));  // wall, facing -x
  scene.meshes.push_back(quad({1, -0.5f, -3}, {1, -0.5f, 3}, {1, 2.5f, 3}, {1, 2.5f, -3}));  // wall, facing +x
  scene.meshes.push_back(quad({-3, 2.5f, -3}, {1, 2.5f, -3}, {1, 2.5f, 3}, {-3, 2.5f, 3}));  // roof, down
  scene.meshes.push_back(quad({-3, 2.5f, -3}, {-3, 2.5f, 3}, {1, 2.5f, 3}, {1, 2.5f, -3}));  // roof, up
  rc::scene::Light sun;
  sun.kind = rc::scene::LightKind::directional;
  sun.direction = glm::normalize(Vec3(-0.6f, -1.0f, 0.0f));
  sun.irradiance = Rgb(3.0f);
  rc::scene::Light sky;
  sky.kind = rc::scene::LightKind::environment;
  sky.radiance = Rgb(0.1f);
  scene.punctual_lights = {sun, sky};
  scene.commit();

  struct Case {
    Vec3 p, n;
  };
  const Case cases[] = {{Vec3(1.0f, 1.25f, 0.3f), Vec3(-1, 0, 0)}, {Vec3(0.0f, 2.5f, 0.3f), Vec3(0, -1, 0)}};
  for (const rad::solver::SolverKind solver : {rad::solver::SolverKind::progressive, rad::solver::SolverKind::hierarchical}) {
    rad::solver::SolverSettings settings;
    settings.mesh.max_edge = 0.5f;
    settings.subdivision_levels = 0;  // as the two-pass view solves; refinement only narrows the leak
    settings.solver = solver;
    settings.progress = false;
    const rad::solver::Solution sol = rad::solver::solve(scene, settings);
    const rad::bake::RadiosityView view(scene, sol, rad::bake::ViewMode::mesh, false);
    for (const Case& c : cases) {
      const GatherAgainstTrace g = gather_against_trace(scene, view, c.p, c.n);
      EXPECT_NEAR(g.gathered, g.traced, g.tolerance())
          << rad::solver::to_string(solver) << " at (" << c.p.x << ", " << c.p.y << "): the path tracer's error " << g.trace_error;
    }
  }
}

// A point seen from behind its input face lies on that face's unmeshed back, unless an element
// lies on it (a two-sided sheet's other half). A downward plate (a canopy, its top its back) with
// a small sunlit plate 3 cm above it facing up: the small plate's element is the nearest one that
// faces up, well within the view's bound for chords of the target edge (0.07 at an edge of 1),
// but 5 times its own sagitta away. Seen from its front the same point may read it; from behind,
// not. (In Šibenik's carved stone, rays that entered a moulding from behind read the lit face
// outside this way.)
TEST(RadiosityView, TheBackOfAFaceReadsOnlyAnElementLyingOnIt) {
  const auto build = [](rc::scene::Scene& scene) {
    scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));  // floor, up
    scene.meshes.push_back(quad({-0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, -0.5f}, {0.5f, 0.5f, 0.5f},
                                {-0.5f, 0.5f, 0.5f}));  // canopy, down
    rc::scene::TriangleMesh chip;                       // a small plate, up, its edge 0.1
    chip.positions = {{-0.05f, 0.53f, -0.05f}, {-0.05f, 0.53f, 0.05f}, {0.05f, 0.53f, 0.0f}};
    chip.indices = {0, 1, 2};
    scene.meshes.push_back(chip);
  };
  rc::scene::Scene scene;
  build(scene);
  // One-sided: the canopy's sunlit top would otherwise be given elements of its own (below).
  const rad::solver::Solution sol = solve_sunlit(scene, Vec3(-0.3f, -1.0f, 0.2f), 1.0f, /*two_sided=*/false);
  const rad::bake::RadiosityView view(scene, sol, rad::bake::ViewMode::two_pass, false);

  const Vec3 up(0.0f, 1.0f, 0.0f), down(0.0f, -1.0f, 0.0f);
  const Vec3 on_canopy(0.0f, 0.5f, 0.0f);
  const auto at = view.locate(on_canopy, up);
  ASSERT_TRUE(at.has_value());
  EXPECT_NEAR(at->distance, 0.03f, 1e-4f) << "the chip's element is the nearest facing up";
  // A point whose face normal is up reads the chip's element 3 cm away: it could lie on a curved
  // surface the element is a chord of.
  EXPECT_TRUE(view.indirect_irradiance(rc::scene::SurfacePoint{on_canopy, Vec3(1e-6f), up}, up).has_value());
  // The canopy's top, lit side up but face normal down, is its back: nothing to read there.
  EXPECT_FALSE(
      view.indirect_irradiance(rc::scene::SurfacePoint{on_canopy, Vec3(1e-6f), down}, up).has_value());

  // Two-sided (the default), the canopy's top sees the sun and the floor its bottom: the canopy is
  // given a twin facing up, and its top reads that twin, lying on it.
  rc::scene::Scene again;
  build(again);
  const rad::solver::Solution both = solve_sunlit(again, Vec3(-0.3f, -1.0f, 0.2f), 1.0f);
  const rad::bake::RadiosityView two_sided(again, both, rad::bake::ViewMode::two_pass, false);
  const auto twin = two_sided.locate(on_canopy, up);
  ASSERT_TRUE(twin.has_value());
  EXPECT_NEAR(twin->distance, 0.0f, 1e-5f);
  EXPECT_TRUE(
      two_sided.indirect_irradiance(rc::scene::SurfacePoint{on_canopy, Vec3(1e-6f), down}, up).has_value());
}

// An element lies over a point of a curved surface it is a chord of; one beside it, however
// close its plane passes, stands for another surface. A lone point 2 cm under the plane of a
// sunlit ledge that starts half a metre to its side (the only element near it that faces up)
// does not read the ledge. (Inside a solid column base on Šibenik's floor, a ray that hit the
// back of its moulding read an element of the lit outside 0.5 m away whose plane passed 4 cm
// from the hit.)
TEST(RadiosityView, AnElementBesideThePointIsNotItsChord) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({0.5f, 0.02f, -0.25f}, {0.5f, 0.02f, 0.25f}, {1.0f, 0.02f, 0.25f},
                              {1.0f, 0.02f, -0.25f}));  // ledge, up
  const rad::solver::Solution sol = solve_sunlit(scene, Vec3(-0.3f, -1.0f, 0.2f), 1.0f);  // the bound for chords: 0.07
  const rad::bake::RadiosityView view(scene, sol, rad::bake::ViewMode::two_pass, false);

  const Vec3 up(0.0f, 1.0f, 0.0f);
  const auto at = view.locate(Vec3(0.0f), up);
  ASSERT_TRUE(at.has_value());
  EXPECT_NEAR(at->distance, std::sqrt(0.25f + 0.0004f), 1e-4f);
  EXPECT_FALSE(
      view.indirect_irradiance(rc::scene::SurfacePoint{Vec3(0.0f), Vec3(1e-6f), up}, up).has_value());
  // On the ledge's own plane, over it, the point reads it.
  EXPECT_TRUE(view.indirect_irradiance(rc::scene::SurfacePoint{Vec3(0.75f, 0.0f, 0.0f), Vec3(1e-6f), up}, up).has_value());
}

// Overshooting leaves some of the unshot light negative, and the ambient term the views add for a
// partial solution with it. Light is never negative: with an ambient term far below zero, every
// vertex the mesh view reads and every indirect irradiance the two-pass view reads is zero or
// more, in every channel.
TEST(RadiosityView, ANegativeAmbientNeverMakesLightNegative) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));    // floor, up
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}, {-1, 0, 1}));  // wall, +x
  rad::solver::Solution sol = solve_sunlit(scene, Vec3(-1.0f, -1.0f, 0.2f), 0.5f);
  sol.ambient = Rgb(-100.0f);
  for (rad::bake::ViewMode mode : {rad::bake::ViewMode::mesh, rad::bake::ViewMode::two_pass}) {
    const rad::bake::RadiosityView view(scene, sol, mode, /*ambient=*/true);
    for (int i = 0; i < 64; ++i) {
      // Rays from above down onto the floor and across onto the wall.
      const float x = -0.9f + 1.8f * float(i % 8) / 7.0f, z = -0.9f + 1.8f * float(i / 8) / 7.0f;
      for (const rc::scene::Ray& ray : {rc::scene::Ray{Vec3(x, 1.5f, z), Vec3(0.0f, -1.0f, 0.0f), 10.0f},
                                        rc::scene::Ray{Vec3(0.5f, 0.1f + x + 1.0f, z), Vec3(-1.0f, 0.0f, 0.0f), 10.0f}}) {
        rc::render::SampleContext ctx{rc::render::Sampler(rc::util::Rng::for_item(3, 0, uint64_t(i))), 0};
        const Rgb l = view.radiance(ray, ctx);
        for (int k = 0; k < 3; ++k) EXPECT_GE(l[k], 0.0f) << "ray " << i << ", channel " << k;
      }
    }
  }
}
