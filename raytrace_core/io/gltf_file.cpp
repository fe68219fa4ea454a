#include "raytrace_core/io/gltf_file.h"

#include <cctype>
#include <sstream>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/gltf_draco.h"
#include "raytrace_core/io/loaders.h"

namespace gilt::raytrace_core::io {
namespace {

// tinygltf hands every image's encoded bytes to this callback, which would normally decode them.
// Nothing is decoded: OpenImageIO reads textures from files when the scene is committed. Bytes
// are kept only where nothing else keeps them, a data: URI's (tinygltf drops what it decoded):
// a file's bytes are read again by OpenImageIO, and a buffer view's stay in the model's buffer.
bool keep_encoded_image(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                        const unsigned char* bytes, int size, void*) {
  if (!image->uri.empty() || image->bufferView >= 0 || !bytes || size <= 0) return true;
  image->image.assign(bytes, bytes + size);
  image->as_is = true;
  return true;
}

/// True for tinygltf's notes on an image file it could not find or read: load_gltf reports those
/// itself, with the path it resolved. (Buffers are required, so their misses are errors instead.)
bool is_image_file_note(const std::string& line) {
  return line.rfind("File not found : ", 0) == 0 || line.rfind("File read error : ", 0) == 0 ||
         line.rfind("File is empty : ", 0) == 0 ||
         line.rfind("Failed to load external 'uri' for image[", 0) == 0;
}

std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  return s;
}

}  // namespace

tinygltf::Model read_gltf_file(const std::string& file, std::vector<std::string>* warnings) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(keep_encoded_image, nullptr);
  std::string error, warning;
  bool ok = false;
  DracoLog draco;  // problems with Draco-compressed primitives, named once the meshes are read
  try {
    ok = lower_extension(file) == ".glb" ? loader.LoadBinaryFromFile(&model, &error, &warning, file)
                                         : loader.LoadASCIIFromFile(&model, &error, &warning, file);
  } catch (const std::exception& e) {
    throw InputError(file + ": " + e.what());
  }
  // A bad Draco primitive keeps its accessors without data, which tinygltf may then refuse with
  // a message of its own: the Draco problem is the one to report.
  if (const std::string problem = draco.first_problem(model); !problem.empty())
    throw InputError(file + ": " + problem);
  if (warnings) {
    std::istringstream lines(warning);
    for (std::string w; std::getline(lines, w);)
      if (!trim(w).empty() && !is_image_file_note(w))
        warnings->push_back(file + ": " + trim(w));
  }
  if (!ok) {
    // tinygltf reads extensionsRequired before the buffers and accessors: a file that needs an
    // extension gilt lacks (e.g. compressed accessors without buffer views) fails for that.
    std::vector<std::string> unsupported;
    for (const std::string& required : model.extensionsRequired)
      if (!gltf_extension_supported(required)) unsupported.push_back(required);
    const std::string why = error.empty() ? std::string("cannot read glTF file") : trim(error);
    if (!unsupported.empty()) {
      std::string names = unsupported[0];
      for (size_t i = 1; i < unsupported.size(); ++i) names += ", " + unsupported[i];
      throw InputError(file + ": requires " + (unsupported.size() > 1 ? "extensions " : "extension ") +
                       names + ", which gilt does not support (" + why + ")");
    }
    throw InputError(file + ": " + why);
  }
  return model;
}

bool gltf_extension_supported(const std::string& name) {
  return name == "KHR_lights_punctual" || name.rfind("KHR_materials_", 0) == 0 ||
         name == "KHR_texture_transform" || name == "KHR_draco_mesh_compression";
}

}  // namespace gilt::raytrace_core::io
