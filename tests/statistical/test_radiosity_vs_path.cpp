// The radiosity render of the (all-diffuse) Cornell box against a long path-traced render of the
// same camera.
//
// Error measure: mean relative error over pixels, mean |R − P| / (P + 0.01), with P the path
// reference and R the radiosity render (ε = 0.01 keeps black pixels from dominating).
// The two solve the same equation; what separates them is the radiosity discretisation (element
// size h: irradiance estimated at vertices, linear over each element), plus the path reference's
// own noise. The bound is derived from the meshing: with first-order convergence e(h) ≈ C·h + n,
// four times the elements (h/2) must bring the error to at most 0.6 of its value (0.5 expected)
// plus the noise n of the reference; n is measured as the same error between two independent
// path renders, halved (both carry noise; the reference alone carries about half).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "raytrace_core/util/image_error.h"
#include "radiosity/solver/solver.h"
#include "radiosity/bake/view.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;

namespace {

constexpr int kSize = 40;

rc::render::RenderSettings settings(int spp, uint64_t seed) {
  rc::render::RenderSettings s;
  s.width = s.height = kSize;
  s.spp = spp;
  s.seed = seed;
  s.progress = false;
  return s;
}

std::vector<rc::Rgb> path_render(const rc::scene::Scene& scene, int spp, uint64_t seed) {
  const rc::render::PathSettings path;
  return rc::render::render_image(scene, scene.effective_camera(), settings(spp, seed),
                          [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); })
      .pixels();
}

std::vector<rc::Rgb> radiosity_render(const rc::scene::Scene& scene, int elements,
                                      rad::bake::ViewMode mode = rad::bake::ViewMode::mesh, uint64_t seed = 1, int spp = 64) {
  rad::solver::SolverSettings s;
  s.mesh.elements = elements;
  s.tolerance = 1e-4;
  s.progress = false;
  const rad::solver::Solution sol = rad::solver::solve(scene, s);
  const rad::bake::RadiosityView view(scene, sol, mode);
  // Same pixel filter and sample positions as the reference (same seed): only the radiance differs.
  return rc::render::render_image(scene, scene.effective_camera(), settings(spp, seed),
                                  [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) {
                                    return view.radiance(ray, ctx);
                                  })
      .pixels();
}

}  // namespace

TEST(RadiosityVsPath, CornellErrorFallsWithTheMesh) {
  rc::scene::Scene scene = rc::io::load_scene("cornell");
  const std::vector<rc::Rgb> reference = path_render(scene, 2048, 1);
  const double noise = 0.5 * rc::util::mean_relative_error(path_render(scene, 2048, 2), reference);
  const double coarse = rc::util::mean_relative_error(radiosity_render(scene, 400), reference);
  const double fine = rc::util::mean_relative_error(radiosity_render(scene, 1600), reference);
  std::printf("mean relative error: 400 elements %.4f, 1600 elements %.4f; reference noise %.4f\n", coarse, fine, noise);
  ::testing::Test::RecordProperty("error_400", std::to_string(coarse));
  ::testing::Test::RecordProperty("error_1600", std::to_string(fine));
  ::testing::Test::RecordProperty("reference_noise", std::to_string(noise));
  EXPECT_LT(fine, 0.6 * coarse + noise) << "the radiosity render does not converge to the path-traced one";
}

// The two-pass view takes the direct light per pixel, without bias, and only the reflected light
// from the mesh. At 1,024 samples per pixel its own noise (one light sample and one gather ray
// per pixel sample) is measured as the reference's is: half the error between two of its renders
// with different seeds. On the same 400 elements it must be closer to the path tracer than the
// mesh view by more than that noise, and it must converge with the mesh as the mesh view does
// (the bound above, with both renders' noise added).
TEST(RadiosityVsPath, TwoPassViewTakesTheDirectLightExactly) {
  rc::scene::Scene scene = rc::io::load_scene("cornell");
  const std::vector<rc::Rgb> reference = path_render(scene, 2048, 1);
  const double reference_noise = 0.5 * rc::util::mean_relative_error(path_render(scene, 2048, 2), reference);
  const std::vector<rc::Rgb> coarse_image = radiosity_render(scene, 400, rad::bake::ViewMode::two_pass, 1, 1024);
  const double own_noise =
      0.5 * rc::util::mean_relative_error(radiosity_render(scene, 400, rad::bake::ViewMode::two_pass, 2, 1024), coarse_image);
  const double mesh = rc::util::mean_relative_error(radiosity_render(scene, 400), reference);
  const double coarse = rc::util::mean_relative_error(coarse_image, reference);
  const double fine = rc::util::mean_relative_error(radiosity_render(scene, 1600, rad::bake::ViewMode::two_pass, 1, 1024), reference);
  std::printf("mean relative error: mesh view %.4f; two-pass 400 elements %.4f, 1600 elements %.4f; "
              "noise: two-pass %.4f, reference %.4f\n", mesh, coarse, fine, own_noise, reference_noise);
  EXPECT_LT(coarse + own_noise, mesh) << "the two-pass view is no closer to the path tracer than the mesh view";
  EXPECT_LT(fine, 0.6 * coarse + own_noise + reference_noise) << "the two-pass view does not converge with the mesh";
}
