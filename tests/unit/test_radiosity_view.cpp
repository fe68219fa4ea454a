// The two-pass radiosity view's reading of the solution where a gather ray lands.

#include <gtest/gtest.h>

#include "radiosity/solver.h"
#include "radiosity/view.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
using rc::Rgb;
using rc::Vec3;

namespace {

/// A quad (a, b, c, d), counter-clockwise seen from its front.
rc::TriangleMesh quad(Vec3 a, Vec3 b, Vec3 c, Vec3 d) {
  rc::TriangleMesh m;
  m.positions = {a, b, c, d};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

}  // namespace

// A one-sided floor (front up) lit by the sun and by a sunlit wall beside it, and under it a
// one-sided plate facing down, whose upper side has no element. A gather ray that meets that
// upper side must not read the floor's light: the floor is the nearest element facing the same
// way, within the view's reach, but it lies on the other side of itself. (On Šibenik's nave,
// 7 % of gather rays met such sides, and those that read another surface's light read 15 times
// what a shadow ray found there.)
TEST(RadiosityView, DoesNotReadTheSolutionThroughASurface) {
  rc::Scene scene;
  scene.materials.push_back(rc::Material::make_diffuse("white", Rgb(0.8f)));
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));        // floor, up
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}, {-1, 0, 1}));      // wall, +x
  scene.meshes.push_back(quad({-0.5f, -0.3f, -0.5f}, {0.5f, -0.3f, -0.5f}, {0.5f, -0.3f, 0.5f},
                              {-0.5f, -0.3f, 0.5f}));                                   // plate, down
  rc::Light sun;
  sun.kind = rc::LightKind::directional;
  sun.direction = glm::normalize(Vec3(-1.0f, -1.0f, 0.2f));
  sun.irradiance = Rgb(1.0f);
  scene.punctual_lights.push_back(sun);
  scene.commit();
  rad::SolverSettings settings;
  settings.mesh.max_edge = 0.5f;  // the view looks up to 1.0 away: the floor is within reach of the plate
  settings.progress = false;
  const rad::Solution sol = rad::solve(scene, settings);
  const rad::RadiosityView view(scene, sol, rad::ViewMode::two_pass, false);

  const Vec3 up(0.0f, 1.0f, 0.0f);
  const rc::SurfacePoint on_floor{Vec3(0.2f, 0.0f, 0.1f), Vec3(1e-6f), up};
  const std::optional<Rgb> floor = view.indirect_irradiance(on_floor, up);
  ASSERT_TRUE(floor.has_value());
  EXPECT_GT(floor->average(), 0.0f) << "the floor gathers the wall's light";
  // The floor's element is found for the plate's upper side (0.3 below it) ...
  const Vec3 below(0.2f, -0.3f, 0.1f);
  const auto at = view.locate(below, up);
  ASSERT_TRUE(at.has_value());
  EXPECT_NEAR(at->distance, 0.3f, 1e-4f);
  // ... but its light is not the plate's.
  EXPECT_FALSE(view.indirect_irradiance(rc::SurfacePoint{below, Vec3(1e-6f), up}, up).has_value());
}
