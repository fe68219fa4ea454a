#pragma once
// Shared by the loader fuzz targets: the loaders read files, so each input is written to a
// per-process scratch folder under the right extension and loaded (and committed) from there.
//
// The contract being fuzzed: a loader either returns a scene or throws InputError (the command
// line's exit code 2). Any other exception escapes and libFuzzer reports it, like a crash, a
// sanitizer error, a hang (-timeout) or an allocation past -rss_limit_mb.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::fuzz {

namespace fs = std::filesystem;

/// The scratch folder, created on first use and removed when the process exits.
inline const fs::path& scratch_folder() {
  static const fs::path folder = [] {
    const fs::path f = fs::temp_directory_path() / ("gilt-fuzz-" + std::to_string(::getpid()));
    fs::create_directories(f);
    std::atexit([] {
      std::error_code ec;
      fs::remove_all(fs::temp_directory_path() / ("gilt-fuzz-" + std::to_string(::getpid())), ec);
    });
    return f;
  }();
  return folder;
}

/// Writes `bytes` to `name` in the scratch folder and returns its path.
inline fs::path write_scratch(const std::string& name, std::string_view bytes) {
  const fs::path path = scratch_folder() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  return path;
}

/// Loads and commits the scene file; bad input (InputError) is an expected outcome.
inline void load(const fs::path& path) {
  try {
    raytrace_core::scene::Scene scene = raytrace_core::io::load_scene(path.string());
    (void)scene.bounds();
  } catch (const raytrace_core::InputError&) {
  }
}

/// Loads `data` as a scene file named scene<extension>.
inline int load_as(const uint8_t* data, size_t size, const std::string& extension) {
  load(write_scratch("scene" + extension, std::string_view(reinterpret_cast<const char*>(data), size)));
  return 0;
}

}  // namespace gilt::fuzz
