// Fuzz target for the OBJ loader and the MTL file it names. The input is the OBJ text, then
// optionally a line "#---mtl---" and the MTL text, written as scene.obj and scene.mtl (the seed
// corpus's OBJ files say "mtllib scene.mtl").

#include <string_view>

#include "tests/fuzz/fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view kSeparator = "#---mtl---\n";
  const size_t split = input.find(kSeparator);
  const std::string_view obj = input.substr(0, split);
  const std::string_view mtl =
      split == std::string_view::npos ? std::string_view() : input.substr(split + kSeparator.size());
  gilt::fuzz::write_scratch("scene.mtl", mtl);
  gilt::fuzz::load(gilt::fuzz::write_scratch("scene.obj", obj));
  return 0;
}
