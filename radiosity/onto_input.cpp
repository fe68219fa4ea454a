// `--onto input`: fitting the solution onto the model's own vertices, and choosing its writer.

#include "radiosity/onto_input.h"

#include <chrono>
#include <filesystem>

#include "radiosity/view.h"
#include "raytrace_core/error.h"
#include "raytrace_core/loaders.h"

namespace gilt::radiosity {

namespace fs = std::filesystem;
using rc::InputError;

int32_t onto_input_file(const rc::Scene& scene) {
  if (scene.model_files.empty())
    throw InputError("--onto input writes onto the model file the scene was read from, and " + scene.name +
                     " has none (a built-in scene, or a JSON scene of spheres only): use --onto elements");
  if (scene.model_files.size() > 1) {
    std::string names;
    for (const std::string& f : scene.model_files) names += (names.empty() ? "" : ", ") + f;
    throw InputError("--onto input writes onto one model file, and " + scene.name + " reads " +
                     std::to_string(scene.model_files.size()) + " (" + names +
                     "): bake each on its own, or use --onto elements");
  }
  return 0;
}

InputColours fit_input_colours(const rc::Scene& scene, const Solution& solution, VertexFit fit, Quantity quantity) {
  const auto start = std::chrono::steady_clock::now();
  InputColours out;
  out.file = onto_input_file(scene);
  out.per_mesh.resize(scene.meshes.size());
  const RadiosityView view(scene, solution, ViewMode::mesh, /*ambient=*/false);
  const SurfaceField field = [&view](const Vec3& p, const Vec3& n) { return view.irradiance(p, n); };
  const float spacing = 0.5f * solution.mesh_report.max_edge;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const rc::TriangleMesh& mesh = scene.meshes[m];
    const rc::Material& material = scene.materials[mesh.material];
    if (mesh.origin.file != out.file || material.is_specular()) continue;
    std::vector<Rgb> colours = fit_vertex_colours(mesh.positions, mesh.indices, field, fit, spacing, &out.stats);
    for (Rgb& c : colours) {
      const Rgb radiosity = material.emission * rc::kPi + material.albedo * c;
      c = quantity == Quantity::irradiance ? c : quantity == Quantity::radiosity ? radiosity : radiosity / rc::kPi;
    }
    out.per_mesh[m] = std::move(colours);
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

void check_onto_output(const std::string& path, const rc::Scene& scene) {
  const std::string& input = scene.model_files[size_t(onto_input_file(scene))];
  const std::string in_ext = rc::lower_extension(input), out_ext = rc::lower_extension(path);
  const bool in_gltf = in_ext == ".gltf" || in_ext == ".glb", out_gltf = out_ext == ".gltf" || out_ext == ".glb";
  std::error_code ec;
  if (fs::equivalent(input, path, ec))
    throw InputError("-o " + path + ": is the input model; --onto input never modifies its input");
  if (in_gltf != out_gltf || (!in_gltf && in_ext != out_ext))
    throw InputError("-o " + path + ": --onto input writes the input's own format, and the input is " + input +
                     (in_gltf ? " (use .gltf or .glb)" : " (use " + in_ext + ")"));
  if (!in_gltf)
    throw InputError("--onto input: " + in_ext + " models are not supported yet (glTF and GLB are); use --onto elements");
}

void write_onto_input(const std::string& path, const rc::Scene& scene, const InputColours& colours,
                      const ExportSettings& settings) {
  check_onto_output(path, scene);
  if (colours.file < 0 || size_t(colours.file) >= scene.model_files.size())
    throw std::logic_error("write_onto_input: no model file");
  write_onto_gltf(scene.model_files[size_t(colours.file)], path, scene, colours, settings);
}

}  // namespace gilt::radiosity
