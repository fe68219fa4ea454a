// The gathered ambient term of a partial progressive solution (radiosity/solver/ambient_gather.h):
// in a closed room it is Cohen's ambient term exactly, light that leaves the scene adds nothing,
// and a surface lit on both sides is seen from below by its downward side.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include "radiosity/mesh/element_scene.h"
#include "radiosity/mesh/mesh.h"
#include "radiosity/solver/ambient_gather.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
using gilt::test::quad;
using rc::Rgb;
using rc::Vec3;

namespace {

/// The committed scene's mesh (elements of at most `max_edge`), its element scene, and a patch
/// per element.
struct Meshed {
  rad::mesh::RadiosityMesh mesh;
  rc::scene::Scene geometry;
  std::vector<uint32_t> offsets, elements;
};

Meshed mesh_of(const rc::scene::Scene& scene, float max_edge) {
  Meshed m;
  rad::mesh::MeshSettings settings;
  settings.max_edge = max_edge;
  m.mesh = rad::mesh::build_mesh(scene, settings);
  m.geometry = rad::mesh::element_scene(scene, m.mesh);
  m.elements.resize(m.mesh.element_count());
  std::iota(m.elements.begin(), m.elements.end(), 0u);
  m.offsets.resize(m.mesh.element_count() + 1);
  std::iota(m.offsets.begin(), m.offsets.end(), 0u);
  return m;
}

rad::solver::AmbientGather gather(const Meshed& m, const std::vector<Rgb>& unshot, float rho) {
  const std::vector<Rgb> albedo(m.mesh.element_count(), Rgb(rho));
  return rad::solver::gather_ambient(m.geometry, m.mesh, m.offsets, m.elements, unshot, albedo,
                                     rad::solver::kAmbientRaysPerPatch, 7);
}

/// View factor between two directly opposed parallel rectangles a × b, a distance c apart
/// (Howell's catalogue, C-11).
double parallel_rectangles(double a, double b, double c) {
  const double x = a / c, y = b / c, x2 = 1.0 + x * x, y2 = 1.0 + y * y;
  return 2.0 / (M_PI * x * y) *
         (0.5 * std::log(x2 * y2 / (x2 + y2 - 1.0)) + x * std::sqrt(y2) * std::atan(x / std::sqrt(y2)) +
          y * std::sqrt(x2) * std::atan(y / std::sqrt(x2)) - x * std::atan(x) - y * std::atan(y));
}

}  // namespace

// Inside a closed box every gather ray meets a front, so with the same unshot radiosity U on
// every element each patch gathers exactly U, and the series is Cohen's 1 / (1 − ρ): the term is
// U / (1 − ρ) at every vertex, to float rounding, with no ray escaping.
TEST(AmbientGather, IsCohensTermInAClosedRoom) {
  rc::scene::Scene scene = rc::io::furnace_scene(1.0f, 0.6f);
  scene.commit();
  const Meshed m = mesh_of(scene, 0.5f);
  const std::vector<Rgb> unshot(m.mesh.element_count(), Rgb(2.0f));
  const rad::solver::AmbientGather g = gather(m, unshot, 0.6f);
  EXPECT_EQ(g.escaped, 0.0);
  ASSERT_EQ(g.vertex_ambient.size(), m.mesh.vertex_count());
  const float expected = 2.0f / (1.0f - 0.6f);
  for (const Rgb& a : g.vertex_ambient) EXPECT_NEAR(a.average(), expected, 1e-5f * expected);
}

// A floor open to the sky sees nothing: its unshot light leaves the scene, and nothing of it
// comes back, where Cohen's term would add U / (1 − ρ) everywhere.
TEST(AmbientGather, LightThatLeavesAddsNothing) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", Rgb(0.5f)));
  scene.commit();
  const Meshed m = mesh_of(scene, 0.5f);
  const rad::solver::AmbientGather g = gather(m, std::vector<Rgb>(m.mesh.element_count(), Rgb(1.0f)), 0.5f);
  EXPECT_EQ(g.escaped, 1.0);
  for (const Rgb& a : g.vertex_ambient) EXPECT_EQ(a.average(), 0.0f);
}

// A 2 × 2 sheet one unit above a 2 × 2 floor, both open to a sky that lights them on both sides,
// so both are given twins. Only the sheet's downward side holds unshot light (1). The floor's
// upward side gathers it at the view factor between the two, whether a ray meets the sheet's
// downward twin or the upward element lying on it. The area-weighted mean over the floor's
// upward elements is a mean of 0/1 outcomes over its rays: within 4 standard errors.
TEST(AmbientGather, SeesATwoSidedSheetFromBelow) {
  rc::scene::Scene scene;
  scene.meshes.push_back(quad({-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}));  // floor, up
  scene.meshes.push_back(quad({-1, 1, -1}, {-1, 1, 1}, {1, 1, 1}, {1, 1, -1}));  // sheet, up
  scene.materials.push_back(rc::scene::Material::make_diffuse("grey", Rgb(0.5f)));
  scene.punctual_lights.push_back(gilt::test::uniform_sky(1.0f));
  scene.commit();
  const Meshed m = mesh_of(scene, 0.25f);
  size_t twins = 0;
  for (size_t e = 0; e < m.mesh.element_count(); ++e) twins += m.mesh.twin(e);
  ASSERT_GT(twins, 0u) << "the sheet and floor should be lit on both sides";
  std::vector<Rgb> unshot(m.mesh.element_count(), Rgb(0.0f));
  size_t floor_elements = 0;
  double floor_area = 0.0, floor_sum = 0.0, floor_area2 = 0.0;
  const rad::solver::AmbientGather g = [&] {
    for (size_t e = 0; e < m.mesh.element_count(); ++e) {
      const Vec3 c = m.mesh.positions[m.mesh.elements[e][0]];
      if (c.y > 0.5f && m.mesh.element_normal[e].y < -0.5f) unshot[e] = Rgb(1.0f);
    }
    return gather(m, unshot, 0.5f);
  }();
  for (size_t e = 0; e < m.mesh.element_count(); ++e) {
    const Vec3 c = m.mesh.positions[m.mesh.elements[e][0]];
    if (c.y > 0.5f || m.mesh.element_normal[e].y < 0.5f) continue;
    ++floor_elements;
    floor_area += m.mesh.element_area[e];
    floor_area2 += double(m.mesh.element_area[e]) * m.mesh.element_area[e];
    floor_sum += double(g.element_ambient[e].average() / g.series.average()) * m.mesh.element_area[e];
  }
  ASSERT_GT(floor_elements, 16u);
  const double f = parallel_rectangles(2.0, 2.0, 1.0);
  // Each element's share is a mean over its own rays; weighted by area, the variance is
  // Σ A² f (1 − f) / (rays (Σ A)²), an upper bound where f varies over the floor.
  const double standard_error =
      std::sqrt(f * (1.0 - f) / rad::solver::kAmbientRaysPerPatch * floor_area2) / floor_area;
  RecordProperty("floor_gathered", std::to_string(floor_sum / floor_area));
  RecordProperty("view_factor", std::to_string(f));
  EXPECT_NEAR(floor_sum / floor_area, f, 4.0 * standard_error) << "view factor " << f;
}

// A hierarchical solve that has no time for the reflected light (a limit of a microsecond: no
// links, no shots) says so, with a residual of 1, and gathers what it left unshot for a display.
// Each run of elements averages the unshot radiosity ρ E_direct of what its rays meet, times the
// series 1 / (1 − ρ) of a closed furnace (no ray escapes), so every vertex's term lies between
// ρ/(1 − ρ) times the least and the greatest direct irradiance of any vertex, up to float rounding.
TEST(AmbientGather, ASolveWithNoTimeGathersWhatItLeftUnshot) {
  constexpr float rho = 0.6f;
  rc::scene::Scene scene = rc::io::furnace_scene(1.0f, rho);
  scene.commit();
  rad::solver::SolverSettings s;
  s.solver = rad::solver::SolverKind::hierarchical;
  s.mesh.elements = 2000;
  s.progress = false;
  s.gather_ambient = true;
  s.time_limit = 1e-6;
  const rad::solver::Solution sol = rad::solver::solve(scene, s);
  EXPECT_EQ(sol.links, 0u);
  EXPECT_EQ(sol.shots, 0u);
  EXPECT_EQ(sol.residual, 1.0);
  EXPECT_EQ(sol.ambient_escaped, 0.0);
  ASSERT_EQ(sol.vertex_ambient.size(), sol.mesh.vertex_count());
  float least = 1e30f, most = 0.0f;
  for (const Rgb& d : sol.vertex_direct)
    least = std::min(least, d.average()), most = std::max(most, d.average());
  ASSERT_GT(least, 0.0f);
  const float series = 1.0f / (1.0f - rho);
  for (const Rgb& a : sol.vertex_ambient) {
    ASSERT_TRUE(std::isfinite(a.average()));
    EXPECT_GE(a.average(), rho * least * series * (1.0f - 1e-5f));
    EXPECT_LE(a.average(), rho * most * series * (1.0f + 1e-5f));
  }
}
