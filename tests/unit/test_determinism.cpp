// Same seed, any thread count: bit-identical images and files.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include "raytrace_core/util/image_io.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

namespace rc = gilt::raytrace_core;

namespace {

rc::render::Film render(const rc::scene::Scene& scene, int threads, uint64_t seed,
                rc::render::SamplerKind sampler = rc::render::SamplerKind::sobol) {
  rc::render::RenderSettings s;
  s.sampler = sampler;
  s.width = 48;
  s.height = 40;
  s.spp = 8;
  s.seed = seed;
  s.threads = threads;
  s.tile_size = 8;
  s.progress = false;
  const rc::render::PathSettings path;
  return rc::render::render_image(scene, scene.effective_camera(), s,
                          [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); });
}

std::string file_bytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

}  // namespace

TEST(Determinism, OneAndTwoThreadsGiveIdenticalExr) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
  const rc::render::Film one = render(scene, 1, 42), two = render(scene, 2, 42);
  const auto dir = std::filesystem::temp_directory_path() / ("gilt-determinism-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  rc::util::write_image((dir / "one.exr").string(), {one.width(), one.height(), one.pixels()});
  rc::util::write_image((dir / "two.exr").string(), {two.width(), two.height(), two.pixels()});
  const std::string a = file_bytes(dir / "one.exr"), b = file_bytes(dir / "two.exr");
  std::filesystem::remove_all(dir);
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, b) << "EXR files differ between 1 and 2 threads";
  EXPECT_TRUE(one.pixels() == two.pixels());
}

TEST(Determinism, EachSamplerIsIndependentOfThreads) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  for (rc::render::SamplerKind kind :
       {rc::render::SamplerKind::sobol, rc::render::SamplerKind::independent}) {
    EXPECT_TRUE(render(scene, 1, 5, kind).pixels() == render(scene, 2, 5, kind).pixels()) << rc::render::sampler_name(kind);
  }
  EXPECT_FALSE(render(scene, 2, 5, rc::render::SamplerKind::sobol).pixels() ==
               render(scene, 2, 5, rc::render::SamplerKind::independent).pixels());
}

TEST(Determinism, DifferentSeedsGiveDifferentImages) {
  const rc::scene::Scene scene = rc::io::load_scene("cornell");
  EXPECT_FALSE(render(scene, 2, 1).pixels() == render(scene, 2, 2).pixels());
}
