// Renders the caustics of the built-in `cornell-caustics` scene with the photon mapper through
// the library API, no CLI: the named passes one by one (trace photons, build the indexes and
// precompute irradiance inside PhotonMapper, then the image), and what was skipped and why.
//   render_caustics [OUT.exr] [SPP]

#include <cstdio>
#include <cstdlib>
#include <string>

#include "photonmap/photon_mapper.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/render/render.h"
#include "raytrace_core/io/scene_io.h"

int main(int argc, char** argv) {
  namespace rc = gilt::raytrace_core;
  namespace pm = gilt::photonmap;
  const std::string output = argc > 1 ? argv[1] : "caustics.exr";
  const int spp = argc > 2 ? std::atoi(argv[2]) : 8;
  try {
    const rc::scene::Scene scene = rc::io::load_scene("cornell-caustics");
    pm::PhotonMapperSettings settings;
    settings.photons.caustic_photons = 500'000;  // a sharper caustic than the default
    const pm::PhotonMapper mapper(scene, settings);
    const pm::PhotonMapperStats& stats = mapper.stats();
    std::printf("%zu caustic and %zu global photons stored in %.2f s, %zu irradiance points in %.2f s\n",
                stats.caustic_photons, stats.global_photons, stats.trace_seconds, stats.irradiance_points,
                stats.precompute_seconds);
    for (const std::string& s : stats.skipped) std::printf("skipped: %s\n", s.c_str());

    rc::render::RenderSettings render;
    render.width = render.height = 256;
    render.spp = spp > 0 ? spp : 8;
    rc::render::RenderStats rs;
    const rc::render::Film film = rc::render::render_image(
        scene, scene.effective_camera(), render,
        [&](const rc::scene::Ray& ray, rc::render::SampleContext& ctx) { return mapper.radiance(ray, ctx); },
        &rs);
    rc::util::write_image(output, {film.width(), film.height(), film.pixels()});
    std::printf("%d spp in %.2f s -> %s\n", rs.spp, rs.seconds, output.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "render_caustics: %s\n", e.what());
    return 1;
  }
  return 0;
}
