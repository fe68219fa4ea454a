#pragma once
// Files for tests that write models and run gilt on them: a fresh folder, a path quoted for the
// shell, and a glTF read back with tinygltf (images not decoded).

#include <tiny_gltf.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace gilt::test {

/// An empty folder of its own under the system's temporary folder: `<prefix>-<name>-<pid>`.
inline std::filesystem::path fresh_dir(const std::string& prefix, const std::string& name) {
  std::string leaf = prefix;
  leaf += '-';
  leaf += name;
  leaf += '-';
  leaf += std::to_string(::getpid());
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / leaf;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

/// The path in single quotes for the shell (appended piecewise: GCC 12 warns falsely about
/// `"'" + path.string()`).
inline std::string quoted(const std::filesystem::path& p) {
  std::string s(1, '\'');
  s += p.string();
  s += '\'';
  return s;
}

inline void write_file(const std::filesystem::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

inline bool skip_images(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
                        void*) {
  return true;
}

/// The glTF or GLB at `path`; a failure to read it fails the test.
inline tinygltf::Model load_gltf_model(const std::filesystem::path& path) {
  tinygltf::Model model;
  tinygltf::TinyGLTF loader;
  loader.SetImageLoader(skip_images, nullptr);
  std::string err, warn;
  const bool ok = path.extension() == ".glb" ? loader.LoadBinaryFromFile(&model, &err, &warn, path.string())
                                             : loader.LoadASCIIFromFile(&model, &err, &warn, path.string());
  EXPECT_TRUE(ok) << path << ": " << err;
  return model;
}

}  // namespace gilt::test
