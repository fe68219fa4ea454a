// Renders the built-in Cornell box with the path tracer through the library API, no CLI:
//   render_cornell [OUT.exr] [SPP]

#include <cstdio>
#include <cstdlib>
#include <string>

#include "raytrace_core/util/image_io.h"
#include "raytrace_core/render/path_tracer.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

int main(int argc, char** argv) {
  namespace rc = gilt::raytrace_core;
  const std::string output = argc > 1 ? argv[1] : "cornell.exr";
  const int spp = argc > 2 ? std::atoi(argv[2]) : 64;
  try {
    const rc::scene::Scene scene = rc::io::load_scene("cornell");
    rc::render::RenderSettings settings;
    settings.width = settings.height = 256;
    settings.spp = spp > 0 ? spp : 64;
    const rc::render::PathSettings path;
    rc::render::RenderStats stats;
    const rc::render::Film film = rc::render::render_image(
        scene, scene.effective_camera(), settings,
        [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return rc::render::path_radiance(scene, ray, ctx, path); }, &stats);
    rc::util::write_image(output, {film.width(), film.height(), film.pixels()});
    std::printf("%d spp in %.2f s, %.2f Mrays/s -> %s\n", stats.spp, stats.seconds, stats.rays / stats.seconds * 1e-6,
                output.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_cornell: %s\n", e.what());
    return 1;
  }
  return 0;
}
