// Fuzz target for the PLY loader (ascii and both binary byte orders).

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  return gilt::fuzz::load_as(data, size, ".ply");
}
