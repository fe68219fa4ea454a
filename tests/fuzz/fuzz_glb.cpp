// Fuzz target for the glTF loader, binary container (.glb: header, JSON chunk, BIN chunk).

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return gilt::fuzz::load_as(data, size, ".glb");
}
