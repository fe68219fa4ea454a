// tinygltf's implementation, for all of gilt. Debian's libtinygltf is built without Draco, and
// tinygltf's own Draco decoding trusts the file (see gltf_draco.h), so gilt compiles the
// implementation here, with TINYGLTF_ENABLE_DRACO, from a copy of tiny_gltf.h that CMake makes
// at build time (cmake/TinyGltfDraco.cmake) in which Draco primitives go to
// decode_draco_primitive. Every other file includes the unchanged <tiny_gltf.h>: the
// declarations are the same.
//
// Images keep tinygltf's default stb_image reader and writer, as in Debian's build (gilt's scene
// loader sets its own reader, see gltf_file.cpp; tests and the exporters use the defaults). The
// stb headers come from libstb-dev, which installs them under stb/, and the code from libstb.

#include "raytrace_core/io/gltf_draco.h"  // decode_draco_primitive, called by the copy

#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#define TINYGLTF_NO_INCLUDE_STB_IMAGE
#define TINYGLTF_NO_INCLUDE_STB_IMAGE_WRITE
#define TINYGLTF_ENABLE_DRACO
#define TINYGLTF_IMPLEMENTATION
#include <tiny_gltf_draco.h>
