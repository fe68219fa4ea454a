#pragma once
// Reading a glTF 2.0 file (.gltf with its buffers, or .glb) into tinygltf's model, for the scene
// loader and for the writers that edit the user's own model (radiosity's --onto input and
// --lightmap). Images are not decoded: nothing here uses their pixels.

#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace gilt::raytrace_core {

/// The model in `file` (.glb read as binary, anything else as text). tinygltf's warnings, one
/// per line, are appended to *warnings when given. Throws InputError naming the file when it
/// cannot be read or parsed.
tinygltf::Model read_gltf_file(const std::string& file, std::vector<std::string>* warnings = nullptr);

}  // namespace gilt::raytrace_core
