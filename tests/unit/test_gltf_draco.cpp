// Draco-compressed glTF meshes (KHR_draco_mesh_compression): tinygltf hands each compressed
// primitive to gilt's checked decoder (raytrace_core/io/gltf_draco.cpp) while the file is read,
// and the scene loader reads the decoded accessors. The Draco data is made here with libdraco's
// encoder, from a cube whose faces each have their own vertices, with positions, normals and UVs.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <draco/compression/config/compression_shared.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>
#include <nlohmann/json.hpp>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/cli_run.h"
#include "tests/support/model_files.h"

namespace gilt::raytrace_core::io {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Quantisation and the error it allows. Draco quantises an attribute's components on one grid of
// 2^bits - 1 steps across the attribute's range (its largest extent over the components) and
// rounds to the nearest step, so a decoded component is within half a step of the source (plus a
// few float roundings, under 1e-6 here).
constexpr int kPositionBits = 14;  // cube [-1, 1]^3: range 2, error <= 1 / (2^14 - 1) ~ 6.1e-5
constexpr int kUvBits = 12;        // UVs span [0, 1]: range 1, error <= 0.5 / (2^12 - 1) ~ 1.2e-4
constexpr float kPositionTolerance = 2.0f / float((1 << kPositionBits) - 1) / 2.0f + 1e-6f;
constexpr float kUvTolerance = 1.0f / float((1 << kUvBits) - 1) / 2.0f + 1e-6f;
// Normals are stored as octahedral coordinates (s, t) in [-1, 1]^2, each rounded on a grid of
// step 2 / (2^bits - 2): a coordinate moves by at most half a step, e = 1 / (2^bits - 2), and by
// at most one more when Draco brings a rounded point back onto the octahedron, so at most 2e; the
// third component of the octahedron point |x| + |y| + |z| = 1 then moves by at most 4e, the
// point by at most sqrt(4 + 4 + 16) e, and normalising (|point| >= 1 / sqrt(3)) stretches that by
// at most sqrt(3): |error| <= sqrt(72) e ~ 8.3e-3 for 10 bits.
constexpr int kNormalBits = 10;
const float kNormalTolerance = std::sqrt(72.0f) / float((1 << kNormalBits) - 2);

/// One corner of a source triangle.
struct Corner {
  std::array<float, 3> position, normal;
  std::array<float, 2> uv;
};
using Triangle = std::array<Corner, 3>;

/// The cube [-1, 1]^3 as 48 outward triangles, each face a 2 x 2 grid of squares. Each face has
/// its own UV rectangle (together they span [0, 1]^2) and each vertex a normal tilted towards the
/// cube's corner, so no two faces share a vertex and no normal lies on an axis. The vertices at 0
/// lie half-way between two steps of the position grid: they show the largest error.
std::vector<Triangle> cube_triangles() {
  std::vector<Triangle> triangles;
  for (int face = 0; face < 6; ++face) {
    const int axis = face / 2;
    const float side = face % 2 ? 1.0f : -1.0f;
    const int b = (axis + 1) % 3, c = (axis + 2) % 3;
    const auto corner = [&](int i, int j) {  // grid point (i, j) of the face, i and j in 0..2
      Corner corner;
      const float u = float(i - 1), v = float(j - 1);
      corner.position[size_t(axis)] = side;
      // Counter-clockwise seen from outside: swap the in-face axes on the negative side.
      corner.position[size_t(b)] = side > 0 ? u : v;
      corner.position[size_t(c)] = side > 0 ? v : u;
      std::array<float, 3> n = corner.position;
      n[size_t(axis)] *= 3.0f;
      const float length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (float& x : n) x /= length;
      corner.normal = n;
      corner.uv = {(float(face) + float(i) / 2.0f) / 6.0f, float(j) / 2.0f};
      return corner;
    };
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < 2; ++j) {
        triangles.push_back({corner(i, j), corner(i + 1, j), corner(i + 1, j + 1)});
        triangles.push_back({corner(i, j), corner(i + 1, j + 1), corner(i, j + 1)});
      }
  }
  return triangles;
}

/// The cube Draco-encoded with `method` (draco::MESH_SEQUENTIAL_ENCODING or
/// MESH_EDGEBREAKER_ENCODING), with what the glTF needs to describe it.
struct Encoded {
  std::vector<char> bytes;
  uint32_t position_id = 0, normal_id = 0, uv_id = 0;  // the attributes' Draco unique ids
  size_t points = 0, faces = 0;                        // of the decoded mesh
};

Encoded encode_cube(int method) {
  const std::vector<Triangle> triangles = cube_triangles();
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(int(triangles.size()));
  const int position = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int normal = builder.AddAttribute(draco::GeometryAttribute::NORMAL, 3, draco::DT_FLOAT32);
  const int uv = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  for (size_t f = 0; f < triangles.size(); ++f) {
    const Triangle& t = triangles[f];
    const draco::FaceIndex face{uint32_t(f)};
    builder.SetAttributeValuesForFace(position, face, t[0].position.data(), t[1].position.data(),
                                      t[2].position.data());
    builder.SetAttributeValuesForFace(normal, face, t[0].normal.data(), t[1].normal.data(),
                                      t[2].normal.data());
    builder.SetAttributeValuesForFace(uv, face, t[0].uv.data(), t[1].uv.data(), t[2].uv.data());
  }
  const std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  if (!mesh) throw std::runtime_error("draco: cannot build the cube");
  Encoded e;
  e.position_id = mesh->attribute(position)->unique_id();
  e.normal_id = mesh->attribute(normal)->unique_id();
  e.uv_id = mesh->attribute(uv)->unique_id();
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, kPositionBits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, kNormalBits);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, kUvBits);
  encoder.SetEncodingMethod(method);
  draco::EncoderBuffer buffer;
  const draco::Status status = encoder.EncodeMeshToBuffer(*mesh, &buffer);
  if (!status.ok()) throw std::runtime_error("draco: " + status.error_msg_string());
  e.bytes = *buffer.buffer();
  // The accessors' counts must be the decoded mesh's (Draco may reorder and split vertices), so
  // a writer decodes its own output to fill them in, as done here.
  draco::DecoderBuffer in;
  in.Init(e.bytes.data(), e.bytes.size());
  auto decoded = draco::Decoder().DecodeMeshFromBuffer(&in);
  if (!decoded.ok()) throw std::runtime_error("draco: " + decoded.status().error_msg_string());
  e.points = decoded.value()->num_points();
  e.faces = decoded.value()->num_faces();
  return e;
}

/// The glTF of one node holding mesh "cube", whose one primitive is the Draco-compressed `e`
/// (buffer view 0, all of the binary chunk). The accessors (0 POSITION, 1 NORMAL, 2 TEXCOORD_0,
/// 3 indices of `index_type`) have no buffer view, as the extension asks of compressed-only data.
Json cube_gltf(const Encoded& e, size_t bytes, int index_type = 5125) {
  const Json primitive = {
      {"attributes", {{"POSITION", 0}, {"NORMAL", 1}, {"TEXCOORD_0", 2}}},
      {"indices", 3},
      {"mode", 4},
      {"extensions",
       {{"KHR_draco_mesh_compression",
         {{"bufferView", 0},
          {"attributes",
           {{"POSITION", e.position_id}, {"NORMAL", e.normal_id}, {"TEXCOORD_0", e.uv_id}}}}}}}};
  return {
      {"asset", {{"version", "2.0"}}},
      {"extensionsUsed", {"KHR_draco_mesh_compression"}},
      {"extensionsRequired", {"KHR_draco_mesh_compression"}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0}}}}},
      {"nodes", {{{"mesh", 0}}}},
      {"meshes", {{{"name", "cube"}, {"primitives", {primitive}}}}},
      {"accessors",
       {{{"componentType", 5126},
         {"count", e.points},
         {"type", "VEC3"},
         {"min", {-1, -1, -1}},
         {"max", {1, 1, 1}}},
        {{"componentType", 5126}, {"count", e.points}, {"type", "VEC3"}},
        {{"componentType", 5126}, {"count", e.points}, {"type", "VEC2"}},
        {{"componentType", index_type}, {"count", 3 * e.faces}, {"type", "SCALAR"}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", bytes}}}},
      {"buffers", {{{"byteLength", bytes}}}},
  };
}

/// A GLB of `gltf` with `bin` as its binary chunk.
std::string glb(const Json& gltf, const std::vector<char>& bin_bytes) {
  std::string json = gltf.dump();
  while (json.size() % 4) json += ' ';
  std::string bin(bin_bytes.begin(), bin_bytes.end());
  while (bin.size() % 4) bin += '\0';
  std::string out;
  const auto u32 = [&](uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(0x46546C67);  // "glTF"
  u32(2);
  u32(uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  u32(uint32_t(json.size()));
  u32(0x4E4F534A);  // "JSON"
  out += json;
  u32(uint32_t(bin.size()));
  u32(0x004E4942);  // "BIN\0"
  out += bin;
  return out;
}

class GltfDraco : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    dir_ = fs::temp_directory_path() /
           ("gilt_draco_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(dir_);
    cube_ = encode_cube(draco::MESH_EDGEBREAKER_ENCODING);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& content) {
    const fs::path path = dir_ / name;
    std::ofstream(path, std::ios::binary) << content;
    return path.string();
  }
  /// The cube's GLB, its glTF first passed through `edit`.
  std::string cube_glb(const std::function<void(Json&)>& edit = {}) {
    Json gltf = cube_gltf(cube_, cube_.bytes.size());
    if (edit) edit(gltf);
    return glb(gltf, cube_.bytes);
  }
  /// The InputError message loading `path` throws; a test failure when it loads or throws
  /// something else.
  static std::string load_error(const std::string& path) {
    try {
      load_scene(path);
    } catch (const InputError& e) {
      return e.what();
    } catch (const std::exception& e) {
      ADD_FAILURE() << "expected InputError, got: " << e.what();
      return {};
    }
    ADD_FAILURE() << "expected InputError, " << path << " loaded";
    return {};
  }
  fs::path dir_;
  Encoded cube_;
};

/// Expects `mesh` to be the source triangles, up to their order and a rotation of each one's
/// corners (Draco may reorder both, but keeps the winding), each attribute within its
/// quantisation error; the largest errors go to `worst` (position, normal, UV).
void expect_source_triangles(const scene::TriangleMesh& mesh, const std::vector<Triangle>& source,
                             float worst[3]) {
  ASSERT_EQ(mesh.indices.size(), 3 * source.size());
  ASSERT_EQ(mesh.normals.size(), mesh.positions.size());
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  for (uint32_t i : mesh.indices) ASSERT_LT(i, mesh.positions.size());
  std::vector<bool> used(source.size(), false);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    bool found = false;
    for (size_t s = 0; s < source.size() && !found; ++s) {
      if (used[s]) continue;
      for (int rotation = 0; rotation < 3 && !found; ++rotation) {
        float error[3] = {0, 0, 0};
        for (int k = 0; k < 3; ++k) {
          const uint32_t v = mesh.indices[3 * t + size_t((k + rotation) % 3)];
          const Corner& c = source[s][size_t(k)];
          for (int a = 0; a < 3; ++a)
            error[0] = std::max(error[0], std::abs(mesh.positions[v][a] - c.position[size_t(a)]));
          const Vec3 dn = mesh.normals[v] - Vec3(c.normal[0], c.normal[1], c.normal[2]);
          error[1] = std::max(error[1], std::sqrt(dn.x * dn.x + dn.y * dn.y + dn.z * dn.z));
          for (int a = 0; a < 2; ++a)
            error[2] = std::max(error[2], std::abs(mesh.uvs[v][a] - c.uv[size_t(a)]));
        }
        if (error[0] <= kPositionTolerance && error[1] <= kNormalTolerance && error[2] <= kUvTolerance) {
          found = used[s] = true;
          for (int k = 0; k < 3; ++k) worst[k] = std::max(worst[k], error[k]);
        }
      }
    }
    EXPECT_TRUE(found) << "decoded triangle " << t
                       << " matches no source triangle within the quantisation error";
  }
}

TEST_F(GltfDraco, DecodesPositionsNormalsUvsAndIndicesWithinTheQuantisationError) {
  const std::vector<Triangle> source = cube_triangles();
  for (const int method : {int(draco::MESH_SEQUENTIAL_ENCODING), int(draco::MESH_EDGEBREAKER_ENCODING)}) {
    const Encoded e = encode_cube(method);
    for (const int index_type : {5121, 5123, 5125}) {  // unsigned byte, short, int
      SCOPED_TRACE("encoding method " + std::to_string(method) + ", index component type " +
                   std::to_string(index_type));
      const std::string path = write("cube.glb", glb(cube_gltf(e, e.bytes.size(), index_type), e.bytes));
      const scene::Scene scene = load_scene(path);
      ASSERT_EQ(scene.meshes.size(), 1u);
      EXPECT_EQ(scene.meshes[0].positions.size(), e.points);
      float worst[3] = {0, 0, 0};
      expect_source_triangles(scene.meshes[0], source, worst);
      RecordProperty(
          "worst_position_normal_uv_error_method_" + std::to_string(method),
          std::to_string(worst[0]) + " " + std::to_string(worst[1]) + " " + std::to_string(worst[2]));
    }
  }
}

TEST_F(GltfDraco, CorruptDracoDataIsAnInputError) {
  std::vector<char> corrupt = cube_.bytes;
  // Keep Draco's header ("DRACO", version, type, method) and scramble the rest.
  for (size_t k = 11; k < corrupt.size(); ++k) corrupt[k] = char(0xA5 ^ (k * 37));
  const std::string path = write("corrupt.glb", glb(cube_gltf(cube_, corrupt.size()), corrupt));
  const std::string error = load_error(path);
  EXPECT_NE(error.find("corrupt.glb"), std::string::npos) << error;
  EXPECT_NE(error.find("mesh 'cube' primitive 0: KHR_draco_mesh_compression"), std::string::npos) << error;
}

TEST_F(GltfDraco, TruncatedAndEmptyDracoDataAreInputErrors) {
  // An empty binary chunk is refused by tinygltf before any decoding.
  EXPECT_FALSE(load_error(write("empty.glb", glb(cube_gltf(cube_, 0), {}))).empty());
  for (size_t size : {size_t(4), size_t(11), cube_.bytes.size() / 2, cube_.bytes.size() - 1}) {
    const std::vector<char> cut(cube_.bytes.begin(), cube_.bytes.begin() + std::ptrdiff_t(size));
    const std::string path = write("cut.glb", glb(cube_gltf(cube_, cut.size()), cut));
    const std::string error = load_error(path);
    EXPECT_NE(error.find("mesh 'cube' primitive 0: KHR_draco_mesh_compression"), std::string::npos)
        << size << " bytes: " << error;
  }
}

TEST_F(GltfDraco, EveryCutAndByteChangeOfTheDracoDataLoadsOrIsAnInputError) {
  // Every prefix of the compressed bytes, and every byte changed in turn (to NUL, 0xff, its
  // complement or its successor): each must decode to a mesh that loads, or be refused with an
  // InputError naming the primitive. Nothing may crash or escape as another exception.
  const std::vector<char>& seed = cube_.bytes;
  int rejected = 0, variants = 0;
  const auto check = [&](const std::vector<char>& bytes, const std::string& what) {
    const std::string path = write("variant.glb", glb(cube_gltf(cube_, bytes.size()), bytes));
    try {
      load_scene(path);
    } catch (const InputError& e) {
      ++rejected;
      const std::string message = e.what();
      if (!bytes.empty()) {
        EXPECT_NE(message.find("mesh 'cube' primitive 0: KHR_draco_mesh_compression"), std::string::npos)
            << what << ": " << message;
      }
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": " << e.what();
    }
    ++variants;
  };
  for (size_t size = 0; size < seed.size(); ++size)
    check(std::vector<char>(seed.begin(), seed.begin() + std::ptrdiff_t(size)),
          "cut at " + std::to_string(size));
  for (size_t at = 0; at < seed.size(); ++at) {
    std::vector<char> changed = seed;
    const char values[4] = {'\0', '\xff', char(~seed[at]), char(seed[at] + 1)};
    changed[at] = values[at % 4];
    if (changed != seed) check(changed, "byte " + std::to_string(at) + " changed");
  }
  std::printf("%d of %d variants of %zu Draco bytes refused, the rest loaded\n", rejected, variants,
              seed.size());
  EXPECT_GE(rejected, int(seed.size()));  // at least every cut
}

TEST_F(GltfDraco, WrongAccessorCountIsAnInputError) {
  // The extension requires the accessors' counts to be the decoded mesh's; tinygltf's own decoding
  // overwrote them with the decoded counts, so a wrong one went unnoticed.
  struct Case {
    int accessor;
    long delta;
    std::string expected;
  };
  const Case cases[] = {
      {0, +1,
       "POSITION: accessor 0 has count " + std::to_string(cube_.points + 1) +
           ", but the Draco data decodes to " + std::to_string(cube_.points) + " vertices"},
      {1, -1, "NORMAL: accessor 1 has count " + std::to_string(cube_.points - 1)},
      {2, +7, "TEXCOORD_0: accessor 2 has count " + std::to_string(cube_.points + 7)},
      {3, +3,
       "indices: accessor 3 has count " + std::to_string(3 * cube_.faces + 3) +
           ", but the Draco data decodes to " + std::to_string(cube_.faces) + " triangles"},
      {3, -3, "indices: accessor 3 has count " + std::to_string(3 * cube_.faces - 3)},
  };
  for (const Case& c : cases) {
    const std::string path = write("count.glb", cube_glb([&](Json& j) {
                                     Json& count = j["accessors"][size_t(c.accessor)]["count"];
                                     count = long(count.get<size_t>()) + c.delta;
                                   }));
    const std::string error = load_error(path);
    EXPECT_NE(error.find("mesh 'cube' primitive 0: KHR_draco_mesh_compression: " + c.expected),
              std::string::npos)
        << error;
  }
}

TEST_F(GltfDraco, TheBadPrimitiveIsNamedAmongOthers) {
  // Mesh "cube" gets a second Draco primitive, over the same data but with accessors of its own,
  // one of them with a wrong count: the message names primitive 1.
  const std::string path = write("second.glb", cube_glb([&](Json& j) {
                                   Json second = j["meshes"][0]["primitives"][0];
                                   for (int a = 0; a < 4; ++a)
                                     j["accessors"].push_back(j["accessors"][size_t(a)]);
                                   second["attributes"] = {{"POSITION", 4}, {"NORMAL", 5}, {"TEXCOORD_0", 6}};
                                   second["indices"] = 7;
                                   j["accessors"][5]["count"] = cube_.points + 2;
                                   j["meshes"][0]["primitives"].push_back(second);
                                 }));
  const std::string error = load_error(path);
  EXPECT_NE(error.find("mesh 'cube' primitive 1: KHR_draco_mesh_compression: NORMAL: accessor 5 has count"),
            std::string::npos)
      << error;
  // With both right, both load.
  const scene::Scene scene = load_scene(write(
      "two.glb",
      cube_glb([&](Json& j) { j["meshes"][0]["primitives"].push_back(j["meshes"][0]["primitives"][0]); })));
  EXPECT_EQ(scene.meshes.size(), 2u);
}

TEST_F(GltfDraco, MissingAttributesAndBadReferencesAreInputErrors) {
  struct Case {
    std::string name, expected;
    std::function<void(Json&)> edit;
  };
  const auto draco = [](Json& j) -> Json& {
    return j["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"];
  };
  const Case cases[] = {
      {"unknown id", "TEXCOORD_0: the Draco data has no attribute with id " + std::to_string(cube_.uv_id + 7),
       [&](Json& j) { draco(j)["attributes"]["TEXCOORD_0"] = cube_.uv_id + 7; }},
      {"not the primitive's", "NORMAL: not among the primitive's attributes",
       [&](Json& j) { j["meshes"][0]["primitives"][0]["attributes"].erase("NORMAL"); }},
      {"wrong type", "NORMAL: the Draco attribute has 3 components, accessor 1 2",
       [&](Json& j) { j["accessors"][1]["type"] = "VEC2"; }},
      {"no buffer view", "buffer view 9 does not exist", [&](Json& j) { draco(j)["bufferView"] = 9; }},
      {"no attributes", "attributes: expected an object", [&](Json& j) { draco(j).erase("attributes"); }},
      {"strip", "primitive mode 5 is not supported",
       [&](Json& j) { j["meshes"][0]["primitives"][0]["mode"] = 5; }},
      {"float indices", "indices: must be unsigned byte, short or int",
       [&](Json& j) { j["accessors"][3]["componentType"] = 5126; }},
  };
  for (const Case& c : cases) {
    const std::string error = load_error(write("bad.glb", cube_glb(c.edit)));
    EXPECT_NE(error.find("mesh 'cube' primitive 0: KHR_draco_mesh_compression: " + c.expected),
              std::string::npos)
        << c.name << ": " << error;
  }
  // Without POSITION the primitive decodes (NORMAL and TEXCOORD_0), and the loader refuses it.
  const std::string error =
      load_error(write("nopos.glb", cube_glb([&](Json& j) {
                         j["meshes"][0]["primitives"][0]["attributes"].erase("POSITION");
                         draco(j)["attributes"].erase("POSITION");
                       })));
  EXPECT_NE(error.find("no POSITION attribute"), std::string::npos) << error;
}

TEST_F(GltfDraco, CommandLineExitsNonZeroOnBadDracoData) {
  const std::string good = write("good.glb", cube_glb());
  test::CliResult r = test::run_command(std::string(GILT_BINARY_PATH) + " info " + test::quoted(good), dir_);
  EXPECT_EQ(r.code, 0) << r.err;
  std::vector<char> corrupt(cube_.bytes.begin(),
                            cube_.bytes.begin() + std::ptrdiff_t(cube_.bytes.size() / 2));
  const std::string bad = write("bad.glb", glb(cube_gltf(cube_, corrupt.size()), corrupt));
  r = test::run_command(std::string(GILT_BINARY_PATH) + " info " + test::quoted(bad), dir_);
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("KHR_draco_mesh_compression"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
}

TEST_F(GltfDraco, AnUnsupportedRequiredExtensionIsNamed) {
  // Compressed accessors without buffer views make tinygltf itself fail ("accessor[3] invalid
  // bufferView"); the message must say which extension the file needs.
  const std::string path = write("meshopt.glb", cube_glb([](Json& j) {
                                   j["meshes"][0]["primitives"][0].erase("extensions");
                                   j["extensionsUsed"] =
                                       j["extensionsRequired"] = {"EXT_meshopt_compression"};
                                 }));
  const std::string error = load_error(path);
  EXPECT_NE(error.find("requires extension EXT_meshopt_compression, which gilt does not support"),
            std::string::npos)
      << error;
}

TEST_F(GltfDraco, OntoInputAddsUncompressedColoursInDecodedOrder) {
  // `--onto input` edits the input's JSON: the Draco primitive keeps its compressed data and
  // gains COLOR_0 and _RADIANCE as ordinary accessors, one value per decoded vertex (the
  // extension lets a primitive mix compressed and uncompressed attributes).
  write("box.glb", cube_glb());
  const std::string scene = write("scene.json", R"({
    "meshes": [{"file": "box.glb"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
               {"type": "environment", "radiance": 0.3}]})");
  const test::CliResult r =
      test::run_command(std::string(GILT_BINARY_PATH) + " radiosity " + test::quoted(scene) +
                            " --onto input --elements 200 -q -o " + test::quoted(dir_ / "out.glb"),
                        dir_);
  ASSERT_EQ(r.code, 0) << r.err;
  const tinygltf::Model out = test::load_gltf_model(dir_ / "out.glb");
  ASSERT_EQ(out.meshes.size(), 1u);
  const tinygltf::Primitive& p = out.meshes[0].primitives.at(0);
  EXPECT_EQ(p.extensions.count("KHR_draco_mesh_compression"), 1u);
  const tinygltf::Accessor& position = out.accessors.at(size_t(p.attributes.at("POSITION")));
  for (const char* name : {"COLOR_0", "_RADIANCE"}) {
    ASSERT_EQ(p.attributes.count(name), 1u) << name;
    const tinygltf::Accessor& a = out.accessors.at(size_t(p.attributes.at(name)));
    EXPECT_EQ(a.count, position.count) << name;
    EXPECT_GE(a.bufferView, 0) << name;
  }
  float worst[3] = {0, 0, 0};
  const scene::Scene again = load_scene((dir_ / "out.glb").string());
  ASSERT_EQ(again.meshes.size(), 1u);
  expect_source_triangles(again.meshes[0], cube_triangles(), worst);
}

TEST_F(GltfDraco, LightmapWritesTheDecodedPrimitiveWhenItMakesItsOwnUvs) {
  const std::string scene = write("scene.json", R"({
    "meshes": [{"file": "box.glb"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
               {"type": "environment", "radiance": 0.3}]})");
  const auto bake = [&]() {
    const test::CliResult r =
        test::run_command(std::string(GILT_BINARY_PATH) + " radiosity " + test::quoted(scene) +
                              " --lightmap 64 --elements 200 -q -o " + test::quoted(dir_ / "out.glb"),
                          dir_);
    EXPECT_EQ(r.code, 0) << r.err;
    return test::load_gltf_model(dir_ / "out.glb");
  };
  // The cube's own UVs (a rectangle per face) can hold the lightmap: the primitive stays as it was.
  write("box.glb", cube_glb());
  tinygltf::Model out = bake();
  ASSERT_EQ(out.meshes.size(), 1u);
  EXPECT_EQ(out.meshes[0].primitives.at(0).extensions.count("KHR_draco_mesh_compression"), 1u);
  EXPECT_EQ(std::count(out.extensionsRequired.begin(), out.extensionsRequired.end(), "KHR_draco_mesh_compression"), 1);
  // Without them gilt makes an atlas and rewrites the primitive's attributes and indices from the
  // decoded data (its vertices split along the atlas's seams): it is no longer compressed.
  write("box.glb", cube_glb([](Json& j) {
          Json& primitive = j["meshes"][0]["primitives"][0];
          primitive["attributes"].erase("TEXCOORD_0");
          primitive["extensions"]["KHR_draco_mesh_compression"]["attributes"].erase("TEXCOORD_0");
        }));
  out = bake();
  ASSERT_EQ(out.meshes.size(), 1u);
  const tinygltf::Primitive& p = out.meshes[0].primitives.at(0);
  EXPECT_EQ(p.extensions.count("KHR_draco_mesh_compression"), 0u);
  // No compressed primitive is left, so the file no longer asks for a Draco decoder.
  for (const auto* list : {&out.extensionsUsed, &out.extensionsRequired})
    EXPECT_EQ(std::count(list->begin(), list->end(), "KHR_draco_mesh_compression"), 0);
  for (const auto& [name, index] : p.attributes)
    EXPECT_GE(out.accessors.at(size_t(index)).bufferView, 0) << name;
  const scene::Scene again = load_scene((dir_ / "out.glb").string());
  ASSERT_EQ(again.meshes.size(), 1u);
  EXPECT_EQ(again.meshes[0].triangle_count(), cube_triangles().size());
}

}  // namespace
}  // namespace gilt::raytrace_core::io
