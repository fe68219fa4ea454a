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
    const rc::Scene scene = rc::load_scene("cornell");
    rc::RenderSettings settings;
    settings.width = settings.height = 256;
    settings.spp = spp > 0 ? spp : 64;
    const rc::PathSettings path;
    rc::RenderStats stats;
    const rc::Film film = rc::render_image(
        scene, scene.effective_camera(), settings,
        [&](const rc::Ray& ray, rc::SampleContext& ctx) { return rc::path_radiance(scene, ray, ctx, path); }, &stats);
    rc::write_image(output, {film.width(), film.height(), film.pixels()});
    std::printf("%d spp in %.2f s, %.2f Mrays/s -> %s\n", stats.spp, stats.seconds, stats.rays / stats.seconds * 1e-6,
                output.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_cornell: %s\n", e.what());
    return 1;
  }
  return 0;
}
