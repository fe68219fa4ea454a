#pragma once
// Bad scene files, one thing wrong in each, for every format: shared by the command-line test
// (exit code 2, message, no output) and the in-process loader test (InputError, message).
// Built from the valid seed files of the fuzz corpus, so they stay in step with it.

#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace gilt::stress {

namespace fs = std::filesystem;

/// The seed corpus, found from this header's path (CMake compiles by absolute paths).
inline fs::path corpus_folder() { return fs::path(__FILE__).parent_path().parent_path() / "fuzz" / "corpus"; }

/// A valid seed file of the fuzz corpus, e.g. "ply/quad_ascii.ply".
inline std::string corpus_file(const std::string& relative) {
  const fs::path path = corpus_folder() / relative;
  std::ifstream in(path, std::ios::binary);
  std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  EXPECT_FALSE(bytes.empty()) << "cannot read " << path;
  return bytes;
}

/// `text` with the first `from` replaced by `to` (a test failure if there is none).
inline std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << "the seed file no longer contains '" << from << "'";
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

inline void put_u32(std::string& bytes, size_t offset, uint32_t value) {
  for (int i = 0; i < 4; ++i) bytes[offset + i] = char((value >> (8 * i)) & 0xff);
}

/// One bad file.
struct BadFile {
  std::string name;  ///< file name, extension included
  std::string bytes;
  std::string problem;   ///< words the message must contain besides the file name
  bool via_cli = false;  ///< also run through the gilt binary (a few per format: each run costs ~0.5 s)
};

/// Files the bad files may name, written next to them: a valid quad (what scene.json names) and
/// an OBJ with a bad face (what bad_mesh.json names).
inline const std::vector<std::pair<std::string, std::string>> kSideFiles = {
    {"quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"},
    {"index_zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"},
};

inline const std::string kTriangle = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

/// Every bad file.
inline std::vector<BadFile> bad_files() {
  const std::string gltf = corpus_file("gltf/lit_quad.gltf");
  const std::string glb = corpus_file("glb/lit_quad.glb");
  const std::string ply = corpus_file("ply/quad_ascii.ply");
  const std::string ply_binary = corpus_file("ply/quad_binary.ply");
  const std::string json = corpus_file("json/scene.json");
  std::string glb_long = glb, glb_chunk = glb;
  put_u32(glb_long, 8, uint32_t(glb.size() + 1000));  // header length past the end of the file
  put_u32(glb_chunk, 12, 100000);                     // JSON chunk longer than the file
  return {
      // OBJ
      {"truncated_face.obj", kTriangle + "f 1 2", "face has 2 vertices", true},
      {"truncated_number.obj", kTriangle + "f 1 2 3\nv 1e", "v needs 3"},
      {"face_index_zero.obj", kTriangle + "f 0 1 2\n", "vertex 0", true},
      {"normal_index.obj", kTriangle + "vn 0 0 1\nf 1//5 2//1 3//1\n", "normal 5"},
      {"overflow.obj", "v 1e40 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "1e40", true},
      {"nan_normal.obj", kTriangle + "vn nan 0 1\nf 1//1 2//1 3//1\n", "nan"},
      // MTL (through the OBJ naming it; written by mtl_cases below)
      // glTF
      {"truncated.gltf", gltf.substr(0, gltf.size() / 2), "parse error", true},
      {"not_json.gltf", "hello", "parse error"},
      {"empty.gltf", "{}", "too short"},
      {"buffer_length.gltf", replaced(gltf, "\"byteLength\":60", "\"byteLength\":6000"), "uri"},
      {"accessor_count.gltf", replaced(gltf, "\"count\":4", "\"count\":400"), "past the end", true},
      {"view_length.gltf",
       replaced(gltf, "\"byteOffset\":48,\"byteLength\":12", "\"byteOffset\":48,\"byteLength\":1200"),
       "past the end"},
      {"accessor_reference.gltf", replaced(gltf, "\"indices\":1", "\"indices\":7"), "out of bounds"},
      {"number_overflow.gltf", replaced(gltf, "\"translation\":[0,0,-2]", "\"translation\":[0,0,1e999]"),
       "overflow", true},
      // GLB
      {"five_bytes.glb", glb.substr(0, 5), "Too short", true},
      {"bad_magic.glb", "XXXX" + glb.substr(4), "magic"},
      {"header_length.glb", glb_long, "Invalid glTF binary"},
      {"chunk_length.glb", glb_chunk, "Invalid glTF binary", true},
      {"truncated.glb", glb.substr(0, glb.size() - 20), "Invalid glTF binary", true},
      {"half.glb", glb.substr(0, glb.size() / 2), "Invalid glTF binary"},
      // PLY
      {"empty.ply", "", "end_header"},
      {"not_ply.ply", "hello world\n", "magic"},
      {"no_end_header.ply", replaced(ply, "end_header\n", ""), "header"},
      {"truncated_body.ply", ply.substr(0, ply.find("3 0 1 2")), "ends early", true},
      {"face_index.ply", replaced(ply, "3 0 2 3", "3 0 2 99"), "vertex 99", true},
      {"negative_count.ply", replaced(ply, "element vertex 4", "element vertex -1"), "element"},
      {"huge_count.ply", replaced(ply, "element vertex 4", "element vertex 4000000000"), "values on the line", true},
      {"nan.ply", replaced(ply, "1 1 0\n", "nan 1 0\n"), "not a finite number", true},
      {"list_count.ply", replaced(ply, "3 0 2 3", "255 0 2 3"), "too few values"},
      {"ascii_as_binary.ply", replaced(ply, "format ascii 1.0", "format binary_big_endian 1.0"),
       "ends early"},
      {"truncated_binary.ply", ply_binary.substr(0, ply_binary.size() - 10), "ends early"},
      // JSON
      {"empty.json", "", "malformed JSON"},
      {"truncated.json", json.substr(0, json.size() / 2), "malformed JSON", true},
      {"array.json", "[1, 2, 3]", "expected an object"},
      {"nan.json", replaced(json, "\"radius\": 0.5", "\"radius\": NaN"), "malformed JSON"},
      {"number_overflow.json", replaced(json, "\"radius\": 0.5", "\"radius\": 1e999"), "overflow", true},
      {"wrong_type.json", replaced(json, "\"radius\": 0.5", "\"radius\": \"big\""), "/shapes/0/radius", true},
      {"negative_radius.json", replaced(json, "\"radius\": 0.5", "\"radius\": -1"), "/shapes/0/radius"},
      {"unknown_material.json", replaced(json, "\"material\": \"satin\"", "\"material\": \"nothing\""),
       "nothing"},
      {"missing_mesh.json", replaced(json, "\"file\": \"quad.obj\"", "\"file\": \"nowhere.obj\""),
       "nowhere.obj"},
      {"bad_mesh.json", replaced(json, "\"file\": \"quad.obj\"", "\"file\": \"index_zero.obj\""),
       "index_zero.obj", true},
      {"zero_scale.json", replaced(json, "\"scale\": [2, 1, 1]", "\"scale\": [0, 1, 1]"), "scale"},
      {"self.json", "{\"meshes\": [{\"file\": \"self.json\"}]}", "JSON scene cannot be used as a mesh"},
  };
}

}  // namespace gilt::stress
