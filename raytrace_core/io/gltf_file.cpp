#include "raytrace_core/io/gltf_file.h"

#include <cctype>
#include <sstream>

#include "raytrace_core/error.h"
#include "raytrace_core/io/loaders.h"

namespace gilt::raytrace_core {
namespace {

bool skip_image(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                void*) {
  return true;  // textures are not used: do not decode them
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

}  // namespace

tinygltf::Model read_gltf_file(const std::string& file, std::vector<std::string>* warnings) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_image, nullptr);
  std::string error, warning;
  bool ok = false;
  try {
    ok = lower_extension(file) == ".glb" ? loader.LoadBinaryFromFile(&model, &error, &warning, file)
                                         : loader.LoadASCIIFromFile(&model, &error, &warning, file);
  } catch (const std::exception& e) {
    throw InputError(file + ": " + e.what());
  }
  if (warnings) {
    std::istringstream lines(warning);
    for (std::string w; std::getline(lines, w);)
      if (!trim(w).empty()) warnings->push_back(file + ": " + trim(w));
  }
  if (!ok) throw InputError(file + ": " + (error.empty() ? std::string("cannot read glTF file") : trim(error)));
  return model;
}

}  // namespace gilt::raytrace_core
