// Bakes radiosity into vertex colours through the library API, no CLI:
//   bake_radiosity [SCENE] [OUT.ply|.obj|.gltf|.glb] [ELEMENTS]
// Solves the scene (default: the built-in Cornell box), prints the radiance at the brightest
// vertex of each material, and writes the mesh with one colour per vertex.

#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>

#include "radiosity/bake/export.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/io/scene_io.h"

int main(int argc, char** argv) {
  namespace rc = gilt::raytrace_core;
  namespace rad = gilt::radiosity;
  const std::string scene_name = argc > 1 ? argv[1] : "cornell";
  const std::string output = argc > 2 ? argv[2] : "cornell_baked.ply";
  try {
    const rc::scene::Scene scene = rc::io::load_scene(scene_name);
    rad::solver::SolverSettings settings;
    settings.mesh.elements = argc > 3 ? std::atoi(argv[3]) : 2000;
    settings.progress = false;
    const rad::solver::Solution solution = rad::solver::solve(scene, settings);

    // Per-vertex and per-element values are plain arrays on the solution.
    std::map<uint32_t, size_t> brightest;  // material → vertex
    for (size_t v = 0; v < solution.mesh.vertex_count(); ++v) {
      const uint32_t m = solution.mesh.vertex_material[v];
      const auto it = brightest.find(m);
      if (it == brightest.end() || solution.vertex_radiance(v).average() > solution.vertex_radiance(it->second).average())
        brightest[m] = v;
    }
    for (const auto& [material, v] : brightest) {
      const rc::Rgb l = solution.vertex_radiance(v);
      std::printf("%-12s brightest vertex radiance (%.4g, %.4g, %.4g) W/sr/m^2\n",
                  scene.materials[material].name.c_str(), l.r, l.g, l.b);
    }
    rad::bake::write_solution(output, scene, solution, rad::bake::ExportSettings{});
    std::printf("%zu elements, %llu shots, residual %.2g, %.2f s -> %s\n", solution.mesh.element_count(),
                static_cast<unsigned long long>(solution.shots), solution.residual, solution.seconds, output.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bake_radiosity: %s\n", e.what());
    return 1;
  }
  return 0;
}
