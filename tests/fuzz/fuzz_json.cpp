// Fuzz target for gilt's JSON scene format. A small valid quad.obj and quad.ply sit next to the
// scene, so inputs naming them (as the seed corpus does) reach the mesh-loading and transform
// code as well as the parser.

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool meshes_written = [] {
    gilt::fuzz::write_scratch("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    gilt::fuzz::write_scratch(
        "quad.ply",
        "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
        "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    return true;
  }();
  (void)meshes_written;
  return gilt::fuzz::load_as(data, size, ".json");
}
