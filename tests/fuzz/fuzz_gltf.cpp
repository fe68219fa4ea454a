// Fuzz target for the glTF loader, text form (.gltf; buffers as data: URIs or missing files).

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return gilt::fuzz::load_as(data, size, ".gltf");
}
