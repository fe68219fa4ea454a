// `gilt radiosity --onto input` on glTF: the output is the input model with colours added. A
// model written here (a floor, a panel placed by two nodes, an animation, buffers in a .bin) and,
// when ../shared/scenes is beside the checkout, the milk truck and AnimateAll go in; the test
// compares the output's node tree, meshes, primitives, attribute sets, accessors and the bytes of
// every position and index buffer with the input's, and checks the bad cases.

#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "raytrace_core/io/ply_header.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/support/cli_run.h"
#include "tests/support/model_files.h"

namespace gilt::test {
namespace {

namespace fs = std::filesystem;
namespace rc = gilt::raytrace_core;
using Json = nlohmann::json;

const std::string kGilt = GILT_BINARY_PATH;

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("gilt-onto", name); }

tinygltf::Model load(const fs::path& path) { return load_gltf_model(path); }

/// The bytes of an accessor's elements, tightly packed.
std::string accessor_bytes(const tinygltf::Model& m, int index) {
  const tinygltf::Accessor& a = m.accessors.at(size_t(index));
  const tinygltf::BufferView& v = m.bufferViews.at(size_t(a.bufferView));
  const size_t element = size_t(tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType)) *
                                tinygltf::GetNumComponentsInType(uint32_t(a.type)));
  const size_t stride = v.byteStride ? v.byteStride : element;
  const unsigned char* base = m.buffers.at(size_t(v.buffer)).data.data() + v.byteOffset + a.byteOffset;
  std::string out;
  for (size_t i = 0; i < a.count; ++i) out.append(reinterpret_cast<const char*>(base + i * stride), element);
  return out;
}

std::vector<float> floats(const tinygltf::Model& m, int index) {
  const std::string bytes = accessor_bytes(m, index);
  std::vector<float> out(bytes.size() / 4);
  std::memcpy(out.data(), bytes.data(), out.size() * 4);
  return out;
}

/// An index accessor's values (any component type); 0, 1, … for a primitive without one.
std::vector<uint32_t> index_values(const tinygltf::Model& m, int index, size_t vertices) {
  std::vector<uint32_t> out;
  if (index < 0) {
    for (size_t v = 0; v < vertices; ++v) out.push_back(uint32_t(v));
    return out;
  }
  const std::string bytes = accessor_bytes(m, index);
  const size_t size =
      size_t(tinygltf::GetComponentSizeInBytes(uint32_t(m.accessors.at(size_t(index)).componentType)));
  for (size_t at = 0; at + size <= bytes.size(); at += size) {
    uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, size);  // little-endian
    out.push_back(v);
  }
  return out;
}

/// A primitive whose vertices the bake split (Vertices::split): the same faces in the same order,
/// each corner's vertex holding the input corner's attributes byte for byte (positions too), and
/// the input's vertices first, at their own numbers.
void expect_same_corners(const tinygltf::Model& in, const tinygltf::Primitive& pa, const tinygltf::Model& out,
                         const tinygltf::Primitive& pb) {
  const size_t in_count = in.accessors.at(size_t(pa.attributes.at("POSITION"))).count;
  const size_t out_count = out.accessors.at(size_t(pb.attributes.at("POSITION"))).count;
  EXPECT_GE(out_count, in_count);
  const std::vector<uint32_t> ia = index_values(in, pa.indices, in_count),
                              ib = index_values(out, pb.indices, out_count);
  ASSERT_EQ(ib.size(), ia.size());
  for (const auto& [name, accessor] : pa.attributes) {
    const std::string a = accessor_bytes(in, accessor), b = accessor_bytes(out, pb.attributes.at(name));
    const size_t element = a.size() / in_count;
    ASSERT_EQ(b.size(), element * out_count) << name;
    EXPECT_EQ(b.substr(0, a.size()), a) << name << ": the input's vertices keep their numbers";
    size_t differ = 0;
    for (size_t c = 0; c < ia.size(); ++c)
      differ += a.compare(element * ia[c], element, b, element * ib[c], element) != 0;
    EXPECT_EQ(differ, 0u) << name << ": corners whose vertex is not the input's";
  }
}

/// Compares an --onto input output with its input; returns how many meshes the output split off.
/// With `split`, a primitive may have its vertices split (expect_same_corners) instead of
/// keeping its index list and attributes.
size_t expect_same_structure(const tinygltf::Model& in, const tinygltf::Model& out,
                             const std::string& quantity_attr, bool allow_split = false) {
  EXPECT_EQ(out.nodes.size(), in.nodes.size());
  EXPECT_EQ(out.scenes.size(), in.scenes.size());
  EXPECT_EQ(out.materials.size(), in.materials.size());
  EXPECT_EQ(out.textures.size(), in.textures.size());
  EXPECT_EQ(out.images.size(), in.images.size());
  EXPECT_EQ(out.animations.size(), in.animations.size());
  EXPECT_EQ(out.skins.size(), in.skins.size());
  EXPECT_EQ(out.extensionsUsed, in.extensionsUsed);
  EXPECT_EQ(out.extensionsRequired, in.extensionsRequired);
  EXPECT_GE(out.meshes.size(), in.meshes.size());
  for (size_t s = 0; s < std::min(in.scenes.size(), out.scenes.size()); ++s)
    EXPECT_EQ(out.scenes[s].nodes, in.scenes[s].nodes);
  for (size_t a = 0; a < std::min(in.animations.size(), out.animations.size()); ++a) {
    EXPECT_EQ(out.animations[a].channels.size(), in.animations[a].channels.size());
    for (size_t s = 0; s < std::min(in.animations[a].samplers.size(), out.animations[a].samplers.size()); ++s) {
      EXPECT_EQ(accessor_bytes(out, out.animations[a].samplers[s].input),
                accessor_bytes(in, in.animations[a].samplers[s].input));
      EXPECT_EQ(accessor_bytes(out, out.animations[a].samplers[s].output),
                accessor_bytes(in, in.animations[a].samplers[s].output));
    }
  }
  std::set<int> split;
  for (size_t n = 0; n < std::min(in.nodes.size(), out.nodes.size()); ++n) {
    const tinygltf::Node &a = in.nodes[n], &b = out.nodes[n];
    EXPECT_EQ(b.children, a.children) << "node " << n;
    EXPECT_EQ(b.matrix, a.matrix) << "node " << n;
    EXPECT_EQ(b.translation, a.translation) << "node " << n;
    EXPECT_EQ(b.rotation, a.rotation) << "node " << n;
    EXPECT_EQ(b.scale, a.scale) << "node " << n;
    EXPECT_EQ(b.skin, a.skin) << "node " << n;
    EXPECT_EQ(b.camera, a.camera) << "node " << n;
    EXPECT_EQ(b.mesh < 0, a.mesh < 0) << "node " << n;
    if (a.mesh < 0 || b.mesh < 0) continue;
    if (b.mesh != a.mesh) {
      EXPECT_GE(size_t(b.mesh), in.meshes.size()) << "node " << n << " moved to another input mesh";
      split.insert(b.mesh);
    }
    const tinygltf::Mesh &ma = in.meshes[size_t(a.mesh)], &mb = out.meshes.at(size_t(b.mesh));
    EXPECT_EQ(mb.primitives.size(), ma.primitives.size());
    EXPECT_EQ(mb.weights, ma.weights);
    for (size_t p = 0; p < std::min(ma.primitives.size(), mb.primitives.size()); ++p) {
      const tinygltf::Primitive &pa = ma.primitives[p], &pb = mb.primitives[p];
      EXPECT_EQ(pb.material, pa.material);
      if (allow_split && pb.indices != pa.indices) {
        expect_same_corners(in, pa, out, pb);
        EXPECT_TRUE(pb.targets.empty() || pb.targets.size() == pa.targets.size());
        for (const char* name : {"COLOR_0", quantity_attr.c_str()})
          EXPECT_EQ(pb.attributes.count(name), 1u) << name;
        continue;
      }
      EXPECT_EQ(pb.mode, pa.mode);
      EXPECT_EQ(pb.indices, pa.indices);
      EXPECT_EQ(pb.targets, pa.targets);
      if (pa.indices >= 0) {
        EXPECT_EQ(accessor_bytes(out, pb.indices), accessor_bytes(in, pa.indices));
      }
      std::set<std::string> added;
      for (const auto& [name, accessor] : pb.attributes) {
        const auto it = pa.attributes.find(name);
        if (it == pa.attributes.end() || name == "COLOR_0") {
          added.insert(name);
          continue;
        }
        EXPECT_EQ(accessor, it->second) << name;
        EXPECT_EQ(accessor_bytes(out, accessor), accessor_bytes(in, it->second)) << name;  // positions included
      }
      for (const auto& [name, accessor] : pa.attributes) EXPECT_TRUE(pb.attributes.count(name)) << name;
      if (added.empty()) continue;  // a mirror or glass primitive is not baked
      EXPECT_EQ(added, (std::set<std::string>{"COLOR_0", quantity_attr})) << "node " << n << " primitive " << p;
      const size_t count = out.accessors.at(size_t(pb.attributes.at("POSITION"))).count;
      const std::vector<float> colour = floats(out, pb.attributes.at("COLOR_0"));
      const std::vector<float> hdr = floats(out, pb.attributes.at(quantity_attr));
      EXPECT_EQ(colour.size(), 3 * count);
      EXPECT_EQ(hdr.size(), 3 * count);
      for (float c : colour) EXPECT_TRUE(c >= 0.0f && c <= 1.0f) << c;
      for (float c : hdr) EXPECT_TRUE(std::isfinite(c) && c >= 0.0f) << c;
    }
  }
  EXPECT_EQ(out.meshes.size(), in.meshes.size() + split.size());
  return split.size();
}

/// A floor (mesh 0) under a panel (mesh 1) placed by two nodes, one of them animated; the
/// geometry lives in data.bin. Lit from the JSON wrapper scene.json by a sun and a sky.
fs::path write_model(const fs::path& dir) {
  std::string bin;
  const auto put = [&bin](std::initializer_list<float> xs) {
    for (float x : xs) bin.append(reinterpret_cast<const char*>(&x), 4);
  };
  put({-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2});                       // floor, 48 bytes
  put({-0.5f, 0, 0.5f, 0.5f, 0, 0.5f, 0.5f, 0, -0.5f, -0.5f, 0, -0.5f});  // panel, 48 bytes
  for (uint16_t i : {0, 1, 2, 0, 2, 3}) bin.append(reinterpret_cast<const char*>(&i), 2);  // 12 bytes
  put({0.0f, 1.0f});                                                     // animation times, 8 bytes
  put({0, 1, 0, 0, 1.5f, 0});                                            // translations, 24 bytes
  write_file(dir / "data.bin", bin);
  Json model = Json::parse(R"({
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_materials_specular"],
    "scene": 0,
    "scenes": [{"nodes": [0]}],
    "nodes": [
      {"name": "root", "children": [1, 2, 3]},
      {"name": "floor", "mesh": 0},
      {"name": "panel A", "mesh": 1, "translation": [0, 1, 0]},
      {"name": "panel B", "mesh": 1, "translation": [2.5, 1.2, 0], "scale": [0.5, 0.5, 0.5]}],
    "meshes": [
      {"name": "floor", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
      {"name": "panel", "primitives": [{"attributes": {"POSITION": 1}, "indices": 2, "material": 0}]}],
    "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0},
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}],
    "animations": [{
      "channels": [{"sampler": 0, "target": {"node": 2, "path": "translation"}}],
      "samplers": [{"input": 3, "output": 4, "interpolation": "LINEAR"}]}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]},
      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, 0, -0.5], "max": [0.5, 0, 0.5]},
      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
      {"bufferView": 3, "componentType": 5126, "count": 2, "type": "SCALAR", "min": [0], "max": [1]},
      {"bufferView": 4, "componentType": 5126, "count": 2, "type": "VEC3"}],
    "bufferViews": [
      {"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
      {"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962},
      {"buffer": 0, "byteOffset": 96, "byteLength": 12, "target": 34963},
      {"buffer": 0, "byteOffset": 108, "byteLength": 8},
      {"buffer": 0, "byteOffset": 116, "byteLength": 24}],
    "buffers": [{"uri": "data.bin"}]})");
  model["buffers"][0]["byteLength"] = bin.size();
  write_file(dir / "model.gltf", model.dump(2));
  write_file(dir / "scene.json", R"({
    "meshes": [{"file": "model.gltf"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
               {"type": "environment", "radiance": 0.3}]})");
  return dir / "scene.json";
}

std::string run(const std::string& args, const fs::path& dir) {
  const CliResult r = run_command(kGilt + " radiosity " + args + " -q", dir);
  EXPECT_EQ(r.code, 0) << args << "\n" << r.err;
  return r.out;
}

TEST(OntoInput, AWrittenModelComesBackWhole) {
  const fs::path dir = fresh_dir("model");
  const fs::path scene = write_model(dir);
  const std::string model_before = slurp(dir / "model.gltf"), bin_before = slurp(dir / "data.bin");
  fs::create_directories(dir / "out");
  for (const char* name : {"out/baked.gltf", "out/baked.glb"}) {
    run(quoted(scene) + " --onto input --elements 400 -o " + quoted(dir / name), dir);
    const tinygltf::Model in = load(dir / "model.gltf"), out = load(dir / name);
    EXPECT_EQ(expect_same_structure(in, out, "_RADIANCE"), 1u) << name;  // panel B's own copy of the panel
    EXPECT_EQ(out.nodes[2].mesh, 1);
    EXPECT_EQ(out.nodes[3].mesh, 2);
    // The two panels are lit alike from above (no occluder over either): their colours agree.
    const auto a = floats(out, out.meshes[1].primitives[0].attributes.at("_RADIANCE"));
    const auto b = floats(out, out.meshes[2].primitives[0].attributes.at("_RADIANCE"));
    // Open to the sky and the sun: L = ρ/π (E_sun cos θ + π L_sky) on the panel's top, ρ = 0.5.
    const double expected = 0.5 / M_PI * (2.0 / std::sqrt(1.0 + 0.09 + 0.04) + M_PI * 0.3);
    for (size_t k = 0; k < a.size(); ++k) {
      EXPECT_NEAR(a[k], expected, 0.02 * expected) << k;
      EXPECT_NEAR(b[k], expected, 0.02 * expected) << k;
    }
  }
  // The .glb stands alone: the input's data.bin moved into its binary chunk.
  const tinygltf::Model glb = load(dir / "out/baked.glb");
  for (const tinygltf::Buffer& b : glb.buffers) EXPECT_TRUE(b.uri.empty()) << b.uri;
  EXPECT_EQ(glb.buffers.size(), 1u);
  // The .gltf's new buffer sits beside it, and the input's buffer is reached from out/.
  EXPECT_TRUE(fs::exists(dir / "out/baked.bin"));
  const Json written = Json::parse(slurp(dir / "out/baked.gltf"));
  EXPECT_EQ(written["buffers"][0]["uri"], "../data.bin");
  EXPECT_EQ(slurp(dir / "model.gltf"), model_before);
  EXPECT_EQ(slurp(dir / "data.bin"), bin_before);
  fs::remove_all(dir);
}

TEST(OntoInput, TheSameBytesForAnyThreadCount) {
  // The fit evaluates faces in parallel into their own slots and assembles the normal equations
  // in face order; the solve is deterministic without --time.
  const fs::path dir = fresh_dir("threads");
  const fs::path scene = write_model(dir);
  std::string bytes[2];
  for (int t = 1; t <= 2; ++t) {
    const fs::path out = dir / ("baked-" + std::to_string(t) + ".glb");
    run(quoted(scene) + " --onto input --elements 400 --threads " + std::to_string(t) + " -o " + quoted(out), dir);
    bytes[t - 1] = slurp(out);
  }
  EXPECT_FALSE(bytes[0].empty());
  EXPECT_TRUE(bytes[0] == bytes[1]) << "--threads 1 and --threads 2 wrote different files";
  fs::remove_all(dir);
}

TEST(OntoInput, BadRequestsAreRefusedBeforeSolving) {
  const fs::path dir = fresh_dir("bad");
  const fs::path scene = write_model(dir);
  const std::string q = quoted(scene) + " --onto input --elements 100 -q ";
  const struct {
    std::string args, message;
  } cases[] = {
      {q + "-o " + quoted(dir / "model.gltf"), "is the input model"},
      {q + "-o " + quoted(dir / "data.gltf"), "would overwrite the input's"},
      {q + "-o " + quoted(dir / "x.obj"), "writes the input's own format"},
      {q + "-o " + quoted(dir / "x.ply"), "writes the input's own format"},
      {"cornell --onto input -o " + quoted(dir / "x.glb"), "use --onto elements"},
      {q + "--srgb8 -o " + quoted(dir / "x.glb"), "--srgb8 applies"},
      {"cornell --fit point -o " + quoted(dir / "x.ply"), "--fit applies to --onto input only"},
      {q + "--check-points " + quoted(dir / "p.csv") + " -o " + quoted(dir / "x.glb"), "give --check too"},
      {q + "--check 5 --check-points " + quoted(dir / "nowhere" / "p.csv") + " -o " + quoted(dir / "x.glb"),
       "does not exist"},
  };
  const std::string before = slurp(dir / "model.gltf"), bin = slurp(dir / "data.bin");
  for (const auto& c : cases) {
    const CliResult r = run_command(kGilt + " radiosity " + c.args, dir);
    EXPECT_NE(r.code, 0) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
  }
  EXPECT_EQ(slurp(dir / "model.gltf"), before);
  EXPECT_EQ(slurp(dir / "data.bin"), bin);
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  EXPECT_FALSE(fs::exists(dir / "p.csv"));
  fs::remove_all(dir);
}

/// The rows of a `--check-points` CSV, whose header starts with `header` and whose lines each hold
/// `columns` numbers.
void read_check_points(const fs::path& csv, const std::string& header, size_t columns,
                       std::vector<std::vector<double>>& rows) {
  std::istringstream in(slurp(csv));
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_EQ(line.rfind(header, 0), 0u) << line;
  while (std::getline(in, line)) {
    std::vector<double> row;
    std::istringstream fields(line);
    for (std::string f; std::getline(fields, f, ',');) row.push_back(std::stod(f));
    ASSERT_EQ(row.size(), columns) << line;
    rows.push_back(row);
  }
}

// `--check-points` writes every compared point, so another bake can be scored against the same
// reference: the figures recomputed from the file are the ones the run printed, the weights are
// barycentric, and the corners are the input file's vertices.
TEST(OntoInput, CheckPointsHoldWhatTheCheckCompared) {
  const fs::path dir = fresh_dir("checkpoints");
  const fs::path scene = write_model(dir);
  const fs::path csv = dir / "points.csv";
  const Json j = Json::parse(run(quoted(scene) + " --onto input --elements 400 --check 60 --check-samples 32 --json "
                                 "--check-points " + quoted(csv) + " -o " + quoted(dir / "x.glb"), dir));
  std::vector<std::vector<double>> rows;
  ASSERT_NO_FATAL_FAILURE(read_check_points(csv, "gltf_mesh,gltf_primitive,v0,v1,v2,w0,w1,w2,x,y,z,albedo_r", 23, rows));
  ASSERT_EQ(rows.size(), j["check"]["points"].get<size_t>());
  ASSERT_GT(rows.size(), 30u);
  double mean = 0.0;
  for (const auto& r : rows) {
    EXPECT_NEAR(r[5] + r[6] + r[7], 1.0, 1e-6);
    for (int k = 2; k < 5; ++k) EXPECT_LT(r[k], 4.0) << "each primitive of the model has 4 vertices";
    mean += (r[14] + r[15] + r[16]) / 3.0;
  }
  const double floor = 0.01 * mean / double(rows.size());
  double squared = 0.0, relative = 0.0;
  for (const auto& r : rows)
    for (int c = 0; c < 3; ++c) {
      const double ref = r[14 + c], d = r[20 + c] - ref;
      squared += d * d / (ref * ref + floor * floor);
      relative += std::abs(d) / (ref + floor);
    }
  // The file rounds to 9 digits; the run sums in double from floats.
  EXPECT_NEAR(squared / (3.0 * rows.size()), j["check"]["relative_mse"].get<double>(),
              1e-5 * j["check"]["relative_mse"].get<double>() + 1e-12);
  EXPECT_NEAR(relative / (3.0 * rows.size()), j["check"]["mean_relative_error"].get<double>(), 1e-6);
  fs::remove_all(dir);
}

// With --onto elements the file holds the checked vertices: the figures recomputed from it are the
// ones the run printed, and each line names a vertex of the exported mesh with its unit normal.
TEST(OntoInput, ElementCheckPointsHoldWhatTheCheckCompared) {
  const fs::path dir = fresh_dir("elementpoints");
  const fs::path csv = dir / "vertices.csv";
  const Json j = Json::parse(run("cornell --elements 400 --check 40 --check-samples 32 --json --check-points " +
                                 quoted(csv) + " -o " + quoted(dir / "x.ply"), dir));
  std::vector<std::vector<double>> rows;
  ASSERT_NO_FATAL_FAILURE(read_check_points(csv, "vertex,x,y,z,nx,ny,nz,disk_radius,reference_r", 17, rows));
  ASSERT_EQ(rows.size(), j["check"]["points"].get<size_t>());
  ASSERT_GT(rows.size(), 30u);
  const size_t vertices = j["vertices"].get<size_t>();
  double mean = 0.0;
  for (const auto& r : rows) {
    EXPECT_LT(r[0], double(vertices));
    EXPECT_NEAR(r[4] * r[4] + r[5] * r[5] + r[6] * r[6], 1.0, 1e-5);
    EXPECT_GT(r[7], 0.0);
    mean += (r[8] + r[9] + r[10]) / 3.0;
  }
  const double floor = 0.01 * mean / double(rows.size());
  double relative = 0.0, absolute = 0.0, total = 0.0;
  for (const auto& r : rows)
    for (int c = 0; c < 3; ++c) {
      const double ref = r[8 + c], d = std::abs(r[14 + c] - ref);
      relative += d / (ref + floor);
      absolute += d;
      total += ref;
    }
  // The file rounds to 9 digits; the run sums in double from floats.
  EXPECT_NEAR(relative / (3.0 * rows.size()), j["check"]["mean_relative_error"].get<double>(), 1e-6);
  EXPECT_NEAR(absolute / total, j["check"]["relative_mean_absolute_error"].get<double>(), 1e-6);
  fs::remove_all(dir);
}

/// A floor and a wall standing on its back edge, sharing the OBJ's vertices 3 and 4, in one
/// material: the sun lights the floor and not the wall (it faces away), so the crease between
/// them is a jump in the light.
fs::path write_floor_and_wall(const fs::path& dir) {
  write_file(dir / "model.obj",
             "mtllib model.mtl\nv -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nv -1 1 -1\nv 1 1 -1\n"
             "usemtl grey\nf 1 2 3\nf 1 3 4\nf 4 3 6\nf 4 6 5\n");
  write_file(dir / "model.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n");
  write_file(dir / "scene.json", R"({
    "meshes": [{"file": "model.obj"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
               {"type": "environment", "radiance": 0.1}]})");
  return dir / "scene.json";
}

TEST(OntoInput, OutputsPassTheKhronosValidator) {
  // scripts/setup.sh test installs the validator into the build folder from npm.
  const fs::path modules = fs::path(GILT_BUILD_DIR) / "gltf-validator" / "node_modules";
  if (!fs::exists(modules / "gltf-validator") || std::system("node --version >/dev/null 2>&1") != 0)
    GTEST_SKIP() << "node or the gltf-validator npm package is missing (scripts/setup.sh test installs them)";
  const fs::path dir = fresh_dir("validator");
  const fs::path scene = write_model(dir);
  std::vector<fs::path> outputs = {dir / "baked.gltf", dir / "baked.glb"};
  for (const fs::path& out : outputs) run(quoted(scene) + " --onto input --elements 400 -o " + quoted(out), dir);
  // gilt's own element mesh of the Cornell box, whose light's vertices are far brighter than 1:
  // COLOR_0 clamped, the values themselves in _RADIANCE.
  for (const char* name : {"cornell-elements.gltf", "cornell-elements.glb"}) {
    outputs.push_back(dir / name);
    run("cornell --elements 800 -o " + quoted(outputs.back()), dir);
  }
  // The furnace, every surface of which is lit far above 1 (it gave over 1,000 errors once).
  outputs.push_back(dir / "furnace.glb");
  run("furnace --elements 400 -o " + quoted(outputs.back()), dir);
  // The same model with a lightmap: vertices split, a UV set and an index buffer added.
  for (const char* name : {"lightmapped.gltf", "lightmapped.glb"}) {
    outputs.push_back(dir / name);
    run(quoted(scene) + " --lightmap 64 --elements 400 -o " + quoted(outputs.back()), dir);
  }
  // An OBJ written as glTF, its vertices split at the crease; and kept.
  const fs::path obj_dir = dir / "obj";
  fs::create_directories(obj_dir);
  const fs::path obj_scene = write_floor_and_wall(obj_dir);
  for (const char* name : {"obj-split.glb", "obj-kept.gltf"}) {
    outputs.push_back(dir / name);
    run(quoted(obj_scene) + " --onto input --elements 400 " + (name[4] == 'k' ? "--keep-vertices " : "") +
            "-o " + quoted(outputs.back()),
        dir);
  }
  const fs::path scenes = fs::path(GILT_SOURCE_DIR) / ".." / "shared" / "scenes";
  if (fs::exists(scenes / "wrap" / "truck-lit.json")) {
    outputs.push_back(dir / "truck.glb");
    run(quoted(scenes / "wrap" / "truck-lit.json") + " --onto input --elements 2000 -o " + quoted(outputs.back()), dir);
    outputs.push_back(dir / "truck-lightmap.glb");
    run(quoted(scenes / "wrap" / "truck-lit.json") + " --lightmap 256 --elements 2000 -o " + quoted(outputs.back()), dir);
  }
  std::string command = "NODE_PATH=";
  command += quoted(modules);
  command += " node ";
  command += quoted(fs::path(GILT_SOURCE_DIR) / "scripts" / "gltf_validate.js");
  for (const fs::path& out : outputs) {
    command += ' ';
    command += quoted(out);
  }
  const CliResult r = run_command(command, dir);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  for (const fs::path& out : outputs) EXPECT_NE(r.out.find(out.string() + ": 0 errors"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

/// The text's lines.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

/// Checks an --onto input OBJ against its input: the same lines, but a comment first, `mtllib`
/// rebased and `v` lines extended by a colour in [0, 1] after the input's own "v x y z" text.
/// Returns the colours' mean red.
double expect_same_obj(const std::string& in_text, const std::string& out_text, const std::string& mtllib) {
  const std::vector<std::string> in = lines_of(in_text), out = lines_of(out_text);
  EXPECT_EQ(out.size(), in.size() + 1);
  if (out.empty()) return 0.0;
  EXPECT_EQ(out[0].rfind("# ", 0), 0u);
  double red = 0.0;
  size_t vertices = 0;
  for (size_t i = 0; i < std::min(in.size(), out.size() - 1); ++i) {
    const std::string &a = in[i], &b = out[i + 1];
    if (a.rfind("v ", 0) == 0) {
      // "v x y z" as the input wrote it, spacing included.
      size_t end = 0;
      for (int k = 0; k < 4; ++k) end = a.find_first_of(" \t\r", a.find_first_not_of(" \t", end));
      const std::string prefix = a.substr(0, end) + " ";
      EXPECT_EQ(b.rfind(prefix, 0), 0u) << b;
      if (b.rfind(prefix, 0) != 0) continue;
      std::istringstream colour(b.substr(prefix.size()));
      float r = -1, g = -1, bl = -1;
      colour >> r >> g >> bl;
      EXPECT_TRUE(r >= 0 && r <= 1 && g >= 0 && g <= 1 && bl >= 0 && bl <= 1) << b;
      red += r;
      ++vertices;
    } else if (a.rfind("mtllib", 0) == 0) {
      EXPECT_EQ(b, "mtllib " + mtllib);
    } else {
      EXPECT_EQ(b, a);
    }
  }
  return vertices ? red / double(vertices) : 0.0;
}

TEST(OntoInput, AnObjComesBackLineForLine) {
  const fs::path dir = fresh_dir("obj");
  // A floor and a raised panel in two materials, with texture coordinates, normals and groups;
  // vertex 1 is shared by both materials. Coordinates are written with more digits than a float
  // keeps, so only the text itself reproduces them.
  const std::string obj =
      "# test model\nmtllib model.mtl\n"
      "v -2 0 2\nv 2.0000000001 0 2\nv 2 0 -2\nv -2 0 -2\n"
      "v -0.5 1 0.5\nv 0.5 1 0.5\nv 0.5 1 -0.5\nv -0.5 1 -0.5\n"
      "vt 0 0\nvt 1 0\nvt 1 1\nvn 0 1 0\n"
      "g floor\nusemtl grey\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/3/1\n"
      "g panel\nusemtl red\nf 5/1/1 6/2/1 7/3/1\nf 5/1/1 7/3/1 8/3/1\nf 2/1/1 6/2/1 5/3/1\n";
  write_file(dir / "model.obj", obj);
  write_file(dir / "model.mtl", "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl red\nKd 0.6 0.1 0.1\n");
  write_file(dir / "scene.json", R"({
    "meshes": [{"file": "model.obj"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
               {"type": "environment", "radiance": 0.3}]})");
  fs::create_directories(dir / "out");
  run(quoted(dir / "scene.json") + " --onto input --elements 400 -o " + quoted(dir / "out" / "baked.obj"), dir);
  const double red = expect_same_obj(obj, slurp(dir / "out" / "baked.obj"), "../model.mtl");
  EXPECT_GT(red, 0.05);  // lit: L = ρ E / π with E ≈ 2.8 is about 0.45 on the grey floor (0.70 as sRGB)
  EXPECT_FALSE(fs::exists(dir / "out" / "baked.mtl"));
  fs::remove_all(dir);
}

TEST(OntoInput, AnObjWrittenAsGltfKeepsItsFacesAndSplitsItsCrease) {
  const fs::path dir = fresh_dir("obj-gltf");
  const fs::path scene = write_floor_and_wall(dir);
  const rc::scene::Scene input = rc::io::load_scene((dir / "model.obj").string());
  ASSERT_EQ(input.meshes.size(), 1u);
  const rc::scene::TriangleMesh& mesh = input.meshes[0];
  const auto baked = [&](const std::string& name, const std::string& flags) {
    run(quoted(scene) + " --onto input --elements 400 --quantity irradiance " + flags + " -o " +
            quoted(dir / name),
        dir);
    const tinygltf::Model out = load(dir / name);
    EXPECT_EQ(out.meshes.size(), 1u);
    EXPECT_EQ(out.meshes.at(0).primitives.size(), 1u);
    return out;
  };
  // The same faces in the same order, each corner at its OBJ vertex's position bit for bit.
  const auto corners = [&](const tinygltf::Model& out) {
    const tinygltf::Primitive& p = out.meshes.at(0).primitives.at(0);
    const std::vector<float> position = floats(out, p.attributes.at("POSITION"));
    const std::vector<float> colour = floats(out, p.attributes.at("_IRRADIANCE"));
    const std::vector<uint32_t> index = index_values(out, p.indices, position.size() / 3);
    EXPECT_EQ(index.size(), mesh.indices.size());
    std::map<uint32_t, std::set<std::vector<float>>> colours_of;  // per OBJ vertex (mesh order)
    for (size_t c = 0; c < std::min(index.size(), mesh.indices.size()); ++c) {
      const rc::Vec3 want = mesh.positions[mesh.indices[c]];
      EXPECT_EQ(0, std::memcmp(&position.at(3 * size_t(index[c])), &want, 12)) << "corner " << c;
      colours_of[mesh.indices[c]].insert(
          {colour.at(3 * size_t(index[c])), colour.at(3 * size_t(index[c]) + 1)});
    }
    return std::make_pair(position.size() / 3, colours_of);
  };
  const auto [split_count, split_colours] = corners(baked("split.glb", ""));
  EXPECT_GE(split_count, mesh.positions.size() + 2);
  // The crease's two vertices carry the floor's light on the floor and the wall's on the wall:
  // the floor takes the sun (E ≈ 2 · 0.98 + sky), the wall the sky and the floor's light only.
  for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
    const rc::Vec3 p = mesh.positions[v];
    if (p.z != -1.0f || p.y != 0.0f) continue;
    ASSERT_EQ(split_colours.at(v).size(), 2u) << "vertex " << v;
    const float a = split_colours.at(v).begin()->at(0), b = split_colours.at(v).rbegin()->at(0);
    EXPECT_GT(std::max(a, b), 2.0f * std::min(a, b)) << a << " " << b;
  }
  // --keep-vertices: one vertex (and colour) per OBJ vertex.
  const auto [kept_count, kept_colours] = corners(baked("kept.gltf", "--keep-vertices"));
  EXPECT_EQ(kept_count, mesh.positions.size());
  for (const auto& [v, set] : kept_colours) EXPECT_EQ(set.size(), 1u) << "vertex " << v;
  fs::remove_all(dir);
}

TEST(OntoInput, ASunShadowSmallerThanAFaceIsFittedByItsArea) {
  // A 4 × 4 floor of two triangles under a black 1 × 1 panel, lit by the sun alone: the shadow
  // (area 1, a parallel projection of the panel) lies inside the floor and touches none of its
  // four corners, which all see the sun. Point samples see no shadow at all; the least-squares
  // fit, whose sample points take the sun by their own shadow rays, keeps the light on the floor:
  // ∫ fit dA = 15 E_sun, up to the quadrature of the shadow's edge (parts up to 0.12 wide along
  // its perimeter of 4: 2 % at most) and the 10⁻³ smoothness term.
  const fs::path dir = fresh_dir("sun");
  write_file(dir / "model.obj",
             "mtllib model.mtl\nv -2 0 2\nv 2 0 2\nv 2 0 -2\nv -2 0 -2\n"
             "v -0.5 1 0.5\nv 0.5 1 0.5\nv 0.5 1 -0.5\nv -0.5 1 -0.5\n"
             "usemtl grey\nf 1 2 3\nf 1 3 4\nusemtl black\nf 5 6 7\nf 5 7 8\n");
  write_file(dir / "model.mtl", "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl black\nKd 0 0 0\n");
  write_file(dir / "scene.json", R"({
    "meshes": [{"file": "model.obj"}],
    "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2}]})");
  const auto floor_integral = [&](const std::string& fit) {
    // --exposure -2 keeps E (about 1.9) inside the OBJ's clamped 0..1 colours, which are
    // sRGB-encoded (display values, as Blender reads them): decoded here.
    run(quoted(dir / "scene.json") + " --onto input --fit " + fit +
            " --elements 2000 --quantity irradiance --exposure -2 -o " + quoted(dir / ("baked-" + fit + ".obj")),
        dir);
    std::vector<double> e;
    for (const std::string& line : lines_of(slurp(dir / ("baked-" + fit + ".obj"))))
      if (line.rfind("v ", 0) == 0) {
        const double encoded = std::stod(rc::io::tokens_of(line).at(4));
        e.push_back(4.0 * (encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4)));
      }
    EXPECT_EQ(e.size(), 8u);
    if (e.size() < 4) return std::make_pair(0.0, 0.0);
    return std::make_pair(8.0 / 3.0 * (e[0] + e[1] + e[2]) + 8.0 / 3.0 * (e[0] + e[2] + e[3]), e[0]);
  };
  const auto [point, sun] = floor_integral("point");
  EXPECT_NEAR(point, 16.0 * sun, 1e-4 * sun);  // every corner sees the sun
  const auto [fitted, unused] = floor_integral("least-squares");
  EXPECT_NEAR(fitted, 15.0 * sun, 0.02 * 15.0 * sun);
  fs::remove_all(dir);
}

/// A PLY of a floor and a raised panel (8 vertices, 4 faces) with a `quality` property and
/// colours the bake replaces, in the given format. Positions have 4 bytes each in both formats.
std::string ply_model(const std::string& format) {
  const float p[8][3] = {{-2, 0, 2},  {2, 0, 2},  {2, 0, -2},  {-2, 0, -2},
                         {-0.5f, 1, 0.5f}, {0.5f, 1, 0.5f}, {0.5f, 1, -0.5f}, {-0.5f, 1, -0.5f}};
  const int f[4][3] = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
  std::string s = "ply\nformat " + format + " 1.0\ncomment test model\nelement vertex 8\n"
                  "property float x\nproperty float y\nproperty float z\nproperty uchar red\n"
                  "property uchar green\nproperty uchar blue\nproperty float quality\n"
                  "element face 4\nproperty list uchar int vertex_indices\nend_header\n";
  const bool big = format == "binary_big_endian";
  const auto put = [&](const void* x, size_t n) {
    std::string b(static_cast<const char*>(x), n);
    if (big) std::reverse(b.begin(), b.end());
    s += b;
  };
  for (int v = 0; v < 8; ++v) {
    const float quality = 0.25f * float(v);
    if (format == "ascii") {
      s += std::to_string(p[v][0]) + " " + std::to_string(p[v][1]) + " " + std::to_string(p[v][2]) + " 9 9 9 " +
           std::to_string(quality) + "\n";
      continue;
    }
    for (int k = 0; k < 3; ++k) put(&p[v][k], 4);
    s += std::string(3, char(9));
    put(&quality, 4);
  }
  for (const auto& face : f) {
    if (format == "ascii") {
      s += "3 " + std::to_string(face[0]) + " " + std::to_string(face[1]) + " " + std::to_string(face[2]) + "\n";
      continue;
    }
    s += char(3);
    for (int k = 0; k < 3; ++k) put(&face[k], 4);
  }
  return s;
}

TEST(OntoInput, APlyKeepsItsPropertiesAndGainsColours) {
  for (const std::string format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    const fs::path dir = fresh_dir("ply-" + format);
    const std::string in = ply_model(format);
    write_file(dir / "model.ply", in);
    write_file(dir / "scene.json", R"({
      "meshes": [{"file": "model.ply"}],
      "lights": [{"type": "directional", "direction": [0.3, -1, 0.2], "irradiance": 2},
                 {"type": "environment", "radiance": 0.3}]})");
    run(quoted(dir / "scene.json") + " --onto input --elements 400 --quantity irradiance -o " +
            quoted(dir / "baked.ply"),
        dir);
    const std::string out = slurp(dir / "baked.ply");
    const size_t in_body = in.find("end_header\n") + 11, out_body = out.find("end_header\n") + 11;
    const std::string header = out.substr(0, out_body);
    // The properties in order: the input's, less its colours, then the new ones.
    std::vector<std::string> properties;
    for (const std::string& line : lines_of(header))
      if (line.rfind("property", 0) == 0) properties.push_back(line);
    EXPECT_EQ(properties, (std::vector<std::string>{
                              "property float x", "property float y", "property float z", "property float quality",
                              "property uchar red", "property uchar green", "property uchar blue",
                              "property float irradiance_red", "property float irradiance_green",
                              "property float irradiance_blue", "property list uchar int vertex_indices"}))
        << format;
    EXPECT_NE(header.find("comment test model"), std::string::npos);
    if (format == "ascii") {
      const std::vector<std::string> a = lines_of(in.substr(in_body)), b = lines_of(out.substr(out_body));
      ASSERT_EQ(a.size(), b.size());
      for (size_t v = 0; v < 8; ++v) {
        const std::vector<std::string> ta = rc::io::tokens_of(a[v]), tb = rc::io::tokens_of(b[v]);
        ASSERT_EQ(tb.size(), 10u);
        EXPECT_EQ(std::vector<std::string>(tb.begin(), tb.begin() + 3), std::vector<std::string>(ta.begin(), ta.begin() + 3));
        EXPECT_EQ(tb[3], ta[6]);  // quality
        // Lit from above: E ≈ 2 cos θ + π 0.3 ≈ 2.8 on the tops, as float and as sRGB 255 (clamped).
        EXPECT_GT(std::stof(tb[7]), 1.0f) << b[v];
        EXPECT_EQ(tb[4], "255");
      }
      for (size_t k = 8; k < a.size(); ++k) EXPECT_EQ(b[k], a[k]);
    } else {
      // Each vertex: the input's 12 position bytes and 4 quality bytes, then 3 + 12 new bytes.
      ASSERT_EQ(out.size() - out_body, 8 * (16 + 15) + 4 * 13u);
      for (size_t v = 0; v < 8; ++v) {
        const std::string a = in.substr(in_body + v * 19, 19), b = out.substr(out_body + v * 31, 31);
        EXPECT_EQ(b.substr(0, 12), a.substr(0, 12)) << format << " vertex " << v;
        EXPECT_EQ(b.substr(12, 4), a.substr(15, 4)) << format << " vertex " << v;
      }
      EXPECT_EQ(out.substr(out_body + 8 * 31), in.substr(in_body + 8 * 19));  // faces byte for byte
    }
    fs::remove_all(dir);
  }
}

TEST(OntoInput, SharedScenesKeepTheirStructure) {
  const fs::path scenes = fs::path(GILT_SOURCE_DIR) / ".." / "shared" / "scenes";
  if (!fs::is_directory(scenes)) GTEST_SKIP() << scenes << " is not beside the checkout";
  const fs::path dir = fresh_dir("shared");
  const struct {
    fs::path scene, model;
  } cases[] = {
      {scenes / "wrap" / "truck-lit.json", scenes / "milk-truck" / "CesiumMilkTruck.gltf"},
      {scenes / "animate-all" / "24_animation_pointer.gltf", scenes / "animate-all" / "24_animation_pointer.gltf"},
  };
  // The bunny (PLY): read back by gilt's own loader (OpenMesh), the same vertices at the same
  // positions, in the same faces.
  if (fs::exists(scenes / "bunny")) {
    const fs::path out = dir / "bunny.ply";
    run(quoted(scenes / "wrap" / "bunny-lit.json") + " --onto input --elements 2000 -o " + quoted(out), dir);
    const rc::scene::Scene in_scene = rc::io::load_scene((scenes / "wrap" / "bunny-lit.json").string());
    const rc::scene::Scene out_scene = rc::io::load_scene(out.string());
    ASSERT_EQ(out_scene.meshes.size(), 1u);
    const rc::scene::TriangleMesh &a = in_scene.meshes[0], &b = out_scene.meshes[0];
    EXPECT_EQ(b.indices, a.indices);
    ASSERT_EQ(b.positions.size(), a.positions.size());
    // The wrapper may move the model: compare the output with the input file's own positions.
    const rc::scene::Scene raw = rc::io::load_scene(in_scene.model_files.at(0));
    for (size_t v = 0; v < b.positions.size(); ++v) ASSERT_EQ(b.positions[v], raw.meshes[0].positions[v]) << v;
  }
  const fs::path sibenik = scenes / "sibenik" / "sibenik.obj";
  if (fs::exists(sibenik)) {
    const fs::path out = dir / "sibenik.obj";
    // Šibenik keeps about 95,000 elements at any --elements (its input faces), and solving them
    // takes minutes; the structure does not depend on how far the solve got.
    run(quoted(scenes / "wrap" / "sibenik-lit.json") + " --onto input --time 15 -o " + quoted(out), dir);
    const fs::path mtl = (sibenik.parent_path() / "sibenik.mtl").lexically_normal().lexically_relative(dir);
    expect_same_obj(slurp(sibenik), slurp(out), mtl.generic_string());
  }
  for (const auto& c : cases) {
    if (!fs::exists(c.model)) continue;
    for (const char* ext : {".gltf", ".glb"}) {
      // Kept, every primitive is the input's; split, each face's corners are.
      const fs::path out = dir / (c.model.stem().string() + ext);
      run(quoted(c.scene) + " --onto input --keep-vertices --elements 2000 --quantity irradiance -o " +
              quoted(out),
          dir);
      expect_same_structure(load(c.model), load(out), "_IRRADIANCE");
      run(quoted(c.scene) + " --onto input --elements 2000 --quantity irradiance -o " + quoted(out), dir);
      expect_same_structure(load(c.model), load(out), "_IRRADIANCE", /*split=*/true);
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gilt::test
