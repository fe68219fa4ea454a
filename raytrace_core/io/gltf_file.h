#pragma once
// Reading a glTF 2.0 file (.gltf with its buffers, or .glb) into tinygltf's model, for the scene
// loader and for the writers that edit the user's own model (radiosity's --onto input and
// --lightmap). Images are not decoded here: the scene loader hands image files to OpenImageIO.
// What each tinygltf::Image holds afterwards:
//   - an image in a file of its own: `uri` as written in the file (not percent-decoded), no bytes;
//   - an image in a buffer view (GLB files): `bufferView`, `mimeType`, no bytes (they are in the
//     buffer already);
//   - an image in a data: URI: `uri` empty, `as_is` set and the encoded bytes (PNG, JPEG, ...) in
//     `image`, `mimeType` from the URI's header.

#include <string>
#include <vector>

#include <tiny_gltf.h>

namespace gilt::raytrace_core::io {

/// The model in `file` (.glb read as binary, anything else as text). tinygltf's warnings, one
/// per line, are appended to *warnings when given, except its notes on image files it cannot
/// find (the scene loader resolves image paths itself and names the missing ones). Primitives
/// compressed with KHR_draco_mesh_compression come decoded (see gltf_draco.h). Throws
/// InputError naming the file when it cannot be read or parsed, naming the mesh and primitive
/// whose Draco data is bad, and naming the required extensions gilt does not support when
/// tinygltf fails on a file that has any.
tinygltf::Model read_gltf_file(const std::string& file, std::vector<std::string>* warnings = nullptr);

/// True for the glTF extensions gilt reads, the ones a file may list in extensionsRequired.
bool gltf_extension_supported(const std::string& name);

}  // namespace gilt::raytrace_core::io
