// Scale invariance of the ray core: the Cornell box translated to 1e3 and 1e5 and scaled by 1e-3
// and 1e3 renders the same image at a fixed seed.
//
// The renders share every random number, so they differ only where rounding sends a path another
// way. The bound has two parts, both measured, not tuned:
//  - the RMS difference to the untransformed render must stay below half the RMS difference
//    between two independent renders (the image's own noise): self-intersection acne or
//    speckles from lost rays would exceed it;
//  - the image means must agree within 4 standard errors of the mean, the standard error taken
//    from 8 independent renders: a light leak or a systematic darkening would exceed it.

#include <gtest/gtest.h>

#include <cmath>

#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/test_scenes.h"

namespace rc = gilt::raytrace_core;

namespace {

std::vector<rc::Rgb> render(float scale, const rc::Vec3& offset, uint64_t seed) {
  rc::scene::Scene scene = rc::io::builtin_scene("cornell");
  if (scale != 1.0f || offset != rc::Vec3(0.0f)) rc::io::transform_scene(scene, scale, offset);
  scene.commit();
  rc::render::RenderSettings s;
  s.width = s.height = 48;
  s.spp = 64;
  s.seed = seed;
  s.progress = false;
  const rc::render::PathSettings path;
  rc::render::RenderStats stats;
  const rc::render::Film film = rc::render::render_image(
      scene, scene.effective_camera(), s,
      [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); }, &stats);
  EXPECT_EQ(stats.non_finite, 0u);
  return film.pixels();
}

double mean(const std::vector<rc::Rgb>& img) {
  double s = 0.0;
  for (const rc::Rgb& c : img) s += c.average();
  return s / img.size();
}

double rms_difference(const std::vector<rc::Rgb>& a, const std::vector<rc::Rgb>& b) {
  double s = 0.0;
  for (size_t i = 0; i < a.size(); ++i)
    for (int k = 0; k < 3; ++k) s += double(a[i][k] - b[i][k]) * (a[i][k] - b[i][k]);
  return std::sqrt(s / (3.0 * a.size()));
}

struct Reference {
  std::vector<rc::Rgb> image;
  double noise_rms;      // RMS difference of two independent renders
  double mean_stderr;    // standard error of the image mean
};

const Reference& reference() {
  static const Reference ref = [] {
    Reference r;
    r.image = render(1.0f, rc::Vec3(0.0f), 1);
    r.noise_rms = rms_difference(r.image, render(1.0f, rc::Vec3(0.0f), 2));
    std::vector<double> means;
    for (uint64_t seed = 10; seed < 18; ++seed) means.push_back(mean(render(1.0f, rc::Vec3(0.0f), seed)));
    double m = 0.0, v = 0.0;
    for (double x : means) m += x / means.size();
    for (double x : means) v += (x - m) * (x - m) / (means.size() - 1);
    r.mean_stderr = std::sqrt(v);
    return r;
  }();
  return ref;
}

void expect_same_image(float scale, const rc::Vec3& offset) {
  const Reference& ref = reference();
  const std::vector<rc::Rgb> img = render(scale, offset, 1);
  const double rms = rms_difference(img, ref.image);
  EXPECT_LT(rms, 0.5 * ref.noise_rms) << "scale " << scale << ", offset " << offset.x;
  EXPECT_LT(std::abs(mean(img) - mean(ref.image)), 4.0 * ref.mean_stderr) << "scale " << scale << ", offset " << offset.x;
  ::testing::Test::RecordProperty("rms_over_noise", std::to_string(rms / ref.noise_rms));
}

}  // namespace

TEST(Scale, TranslatedTo1e3) { expect_same_image(1.0f, rc::Vec3(1e3f)); }
TEST(Scale, TranslatedTo1e5) { expect_same_image(1.0f, rc::Vec3(1e5f)); }
TEST(Scale, ScaledBy1eMinus3) { expect_same_image(1e-3f, rc::Vec3(0.0f)); }
TEST(Scale, ScaledBy1e3) { expect_same_image(1e3f, rc::Vec3(0.0f)); }
