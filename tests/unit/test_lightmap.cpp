// `gilt radiosity --lightmap SIZE`: the atlas's layout (every face inside [0,1]², no two faces
// sharing texels, one texel density), its values against closed forms under a sun and a sky, and
// the glTF written with it: the input's structure, its positions bit for bit on every face, the
// UV set and the EXR it names. Bad requests are refused before solving.

#include <gtest/gtest.h>
#include <tiny_gltf.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "radiosity/bake/check.h"
#include "radiosity/bake/lightmap.h"
#include "radiosity/bake/onto_input.h"
#include "radiosity/solver/solver.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/util/parallel.h"
#include "tests/support/cli_run.h"
#include "tests/support/model_files.h"

namespace gilt::test {
namespace {

namespace fs = std::filesystem;
namespace rc = gilt::raytrace_core;
namespace rad = gilt::radiosity;
using Json = nlohmann::json;
using rc::Vec2;
using rc::Vec3;

const std::string kGilt = GILT_BINARY_PATH;

fs::path fresh_dir(const std::string& name) { return test::fresh_dir("gilt-lightmap", name); }

/// A 4 × 4 floor and, 1 above it, a 1 × 1 panel placed by two nodes (so the glTF writer must
/// split the shared mesh); a box of two faces per side stands on the floor in a corner. The
/// geometry is in data.bin; the sun comes straight down (irradiance 2) and the sky has radiance 0.3.
fs::path write_model(const fs::path& dir) {
  std::string bin;
  const auto put = [&bin](std::initializer_list<float> xs) {
    for (float x : xs) bin.append(reinterpret_cast<const char*>(&x), 4);
  };
  put({-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2});                       // floor, 48 bytes
  put({-0.5f, 0, 0.5f, 0.5f, 0, 0.5f, 0.5f, 0, -0.5f, -0.5f, 0, -0.5f});  // panel, 48 bytes
  for (uint16_t i : {0, 1, 2, 0, 2, 3}) bin.append(reinterpret_cast<const char*>(&i), 2);  // 12 bytes
  write_file(dir / "data.bin", bin);
  Json model = Json::parse(R"({
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_materials_specular"],
    "scene": 0,
    "scenes": [{"nodes": [0, 1, 2]}],
    "nodes": [
      {"name": "floor", "mesh": 0},
      {"name": "panel A", "mesh": 1, "translation": [-1, 1, 0]},
      {"name": "panel B", "mesh": 1, "translation": [1, 1, 0]}],
    "meshes": [
      {"name": "floor", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0}]},
      {"name": "panel", "primitives": [{"attributes": {"POSITION": 1}, "indices": 2}]}],
    "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0},
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]},
      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, 0, -0.5], "max": [0.5, 0, 0.5]},
      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
    "bufferViews": [
      {"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
      {"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962},
      {"buffer": 0, "byteOffset": 96, "byteLength": 12, "target": 34963}],
    "buffers": [{"uri": "data.bin"}]})");
  model["buffers"][0]["byteLength"] = bin.size();
  write_file(dir / "model.gltf", model.dump(2));
  write_file(dir / "scene.json", R"({
    "meshes": [{"file": "model.gltf"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2},
               {"type": "environment", "radiance": 0.3}]})");
  return dir / "scene.json";
}

double cross2(const Vec2& a, const Vec2& b) { return double(a.x) * b.y - double(a.y) * b.x; }

/// Twice the signed area of a UV triangle.
double uv_area2(const Vec2* t) { return cross2(t[1] - t[0], t[2] - t[0]); }

/// Is point p strictly inside triangle t (by more than eps in barycentric terms)?
bool strictly_inside(const Vec2* t, const Vec2& p, double eps) {
  const double a = uv_area2(t);
  if (std::abs(a) < 1e-20) return false;
  const double b1 = cross2(t[1] - t[0], p - t[0]) / a;  // weight of t[2]
  const double b0 = cross2(p - t[0], t[2] - t[0]) / a;  // weight of t[1]
  return b0 > eps && b1 > eps && 1.0 - b0 - b1 > eps;
}

struct Solved {
  rc::scene::Scene scene;
  rad::solver::Solution solution;
};

Solved solve(const fs::path& scene_file, int elements) {
  Solved s{rc::io::load_scene(scene_file.string()), {}};
  rad::solver::SolverSettings settings;
  settings.mesh.elements = elements;
  s.solution = rad::solver::solve(s.scene, settings);
  return s;
}

TEST(Lightmap, FacesAreLaidOutApartAtOneDensity) {
  const fs::path dir = fresh_dir("layout");
  const Solved s = solve(write_model(dir), 400);
  const rad::bake::Lightmap lm = rad::bake::bake_lightmap(s.scene, s.solution, rad::bake::Quantity::irradiance, 128);
  ASSERT_EQ(lm.corner_uv.size(), s.scene.meshes.size());
  // The floor's two faces are coplanar neighbours: one chart; each panel instance is one more.
  EXPECT_EQ(lm.stats.charts, 3u);
  std::vector<std::array<Vec2, 3>> triangles;
  double largest_density = 0.0, smallest_density = 1e300;
  for (size_t m = 0; m < s.scene.meshes.size(); ++m) {
    const rc::scene::TriangleMesh& mesh = s.scene.meshes[m];
    ASSERT_EQ(lm.corner_uv[m].size(), mesh.indices.size());
    for (size_t f = 0; f < mesh.triangle_count(); ++f) {
      std::array<Vec2, 3> t;
      for (int k = 0; k < 3; ++k) {
        t[size_t(k)] = lm.corner_uv[m][3 * f + size_t(k)];
        EXPECT_TRUE(t[size_t(k)].x >= 0.0f && t[size_t(k)].x <= 1.0f && t[size_t(k)].y >= 0.0f && t[size_t(k)].y <= 1.0f);
      }
      const Vec3 &a = mesh.positions[mesh.indices[3 * f]], &b = mesh.positions[mesh.indices[3 * f + 1]],
                 &c = mesh.positions[mesh.indices[3 * f + 2]];
      const double world = glm::length(glm::cross(b - a, c - a));
      const double density = std::abs(uv_area2(t.data())) / world;
      largest_density = std::max(largest_density, density);
      smallest_density = std::min(smallest_density, density);
      triangles.push_back(t);
    }
  }
  // Every face here is flat in its chart's plane, so one density to float rounding.
  EXPECT_NEAR(smallest_density / largest_density, 1.0, 1e-4);
  // No face's corners or centroid lie inside another face (their texels would be shared), and
  // charts keep at least 2 × kLightmapPad texels apart: a corner of one chart is not within that
  // of another chart's corner.
  for (size_t i = 0; i < triangles.size(); ++i)
    for (size_t j = 0; j < triangles.size(); ++j) {
      if (i == j) continue;
      const Vec2* t = triangles[i].data();
      const Vec2 centroid = (triangles[j][0] + triangles[j][1] + triangles[j][2]) / 3.0f;
      EXPECT_FALSE(strictly_inside(t, centroid, 1e-6)) << i << " " << j;
      for (const Vec2& p : triangles[j]) EXPECT_FALSE(strictly_inside(t, p, 1e-6)) << i << " " << j;
    }
  fs::remove_all(dir);
}

TEST(Lightmap, TexelsHoldTheSunAndSkyAndThePanelsShadows) {
  // Irradiance on the open floor: E = E_sun + π L_sky = 2 + 0.3π (the panels are too small and
  // high to hide much sky: at the points tested below, 1 m or more from their shadows' edges, the
  // sky they hide is under 6 %). Under a panel the sun is gone. The panels' tops see sun and sky
  // alone. The solution's sky and interreflection is the element solution's, whose error on
  // this scene is well under 2 %; the sun is exact (a shadow ray per point).
  const fs::path dir = fresh_dir("values");
  const Solved s = solve(write_model(dir), 1600);
  const rad::bake::Lightmap lm = rad::bake::bake_lightmap(s.scene, s.solution, rad::bake::Quantity::irradiance, 256);
  const double sky = 0.3 * M_PI, open = 2.0 + sky;
  size_t floor = SIZE_MAX;
  for (size_t m = 0; m < s.scene.meshes.size(); ++m)
    if (s.scene.meshes[m].origin.mesh == 0) floor = m;
  ASSERT_NE(floor, SIZE_MAX);
  const rc::scene::TriangleMesh& mesh = s.scene.meshes[floor];
  // The lightmap at a floor point (x, z): find its face and barycentrics.
  const auto at = [&](float x, float z) {
    for (size_t f = 0; f < mesh.triangle_count(); ++f) {
      const Vec3 &a = mesh.positions[mesh.indices[3 * f]], &b = mesh.positions[mesh.indices[3 * f + 1]],
                 &c = mesh.positions[mesh.indices[3 * f + 2]];
      const Vec2 p(x, z), pa(a.x, a.z), pb(b.x, b.z), pc(c.x, c.z);
      const double d = cross2(pb - pa, pc - pa);
      const double u = cross2(p - pa, pc - pa) / d, v = cross2(pb - pa, p - pa) / d;
      if (u >= 0 && v >= 0 && u + v <= 1) return lm.at(floor, f, float(u), float(v));
    }
    ADD_FAILURE() << "no floor face at " << x << ", " << z;
    return rc::Rgb(0.0f);
  };
  for (const Vec2 p : {Vec2(0.0f, 1.6f), Vec2(0.0f, -1.6f), Vec2(1.8f, 1.8f), Vec2(-1.8f, -1.8f)}) {
    EXPECT_NEAR(at(p.x, p.y).g, open, 0.06 * open) << p.x << ", " << p.y;
  }
  // In the panels' shadows, well inside (0.25 from their edges, 4 texels at this size): no sun.
  for (const Vec2 p : {Vec2(-1.0f, 0.0f), Vec2(1.0f, 0.0f), Vec2(-1.2f, 0.2f), Vec2(0.8f, -0.2f)}) {
    const float e = at(p.x, p.y).g;
    EXPECT_LT(e, 0.5 * open) << p.x << ", " << p.y;
    EXPECT_GT(e, 0.3 * sky) << p.x << ", " << p.y;
  }
  // The panels' tops: the sun and the whole sky.
  for (size_t m = 0; m < s.scene.meshes.size(); ++m) {
    if (s.scene.meshes[m].origin.mesh != 1) continue;
    const rc::scene::TriangleMesh& panel = s.scene.meshes[m];
    for (size_t f = 0; f < panel.triangle_count(); ++f) {
      const Vec3 n = glm::cross(panel.positions[panel.indices[3 * f + 1]] - panel.positions[panel.indices[3 * f]],
                                panel.positions[panel.indices[3 * f + 2]] - panel.positions[panel.indices[3 * f]]);
      if (n.y <= 0.0f) continue;
      EXPECT_NEAR(lm.at(m, f, 1.0f / 3.0f, 1.0f / 3.0f).g, open, 0.02 * open);
    }
  }
  // The check agrees: its points on the open floor and panels match within the estimates' noise.
  rad::bake::CheckSettings check;
  check.points = 64;
  check.samples = 256;
  const rad::bake::SurfaceCheckResult r = rad::bake::check_lightmap(s.scene, lm, check);
  EXPECT_GT(r.points, 32u);
  EXPECT_LT(r.mean_relative_error, 0.1);
  fs::remove_all(dir);
}

TEST(Lightmap, FinalGatherIsUnbiasedOnOpenSurfacesAndRepeatable) {
  // --bake-gather traces each point's light. On the panels' tops nothing but the sun and the sky
  // reaches: E = 2 + 0.3π, the sun by its shadow ray and the uniform sky by the gather rays,
  // every one of which escapes and brings πL (rc::render::sky_left_to_bsdf_sampling): exact, up to
  // float rounding in the sum of 4,096 samples.
  const fs::path dir = fresh_dir("gather");
  const Solved s = solve(write_model(dir), 400);
  const double sky = 0.3 * M_PI, open = 2.0 + sky;
  const int rays = 4096;
  const double tolerance = 1e-4 * open;
  const rad::bake::SolutionAtInput gathered(s.scene, s.solution, rad::bake::Quantity::irradiance, rad::bake::BakeGather{rays, 3});
  const rc::scene::Material& grey = s.scene.materials[s.scene.meshes[0].material];
  int tops = 0;
  for (const rc::scene::TriangleMesh& panel : s.scene.meshes) {
    if (panel.origin.mesh != 1) continue;
    for (size_t f = 0; f < panel.triangle_count(); ++f) {
      const Vec3 a = panel.positions[panel.indices[3 * f]], b = panel.positions[panel.indices[3 * f + 1]],
                 c = panel.positions[panel.indices[3 * f + 2]];
      const Vec3 n = glm::normalize(glm::cross(b - a, c - a));
      if (n.y <= 0.0f) continue;
      const std::optional<rc::Rgb> e = gathered(grey, (a + b + c) / 3.0f, n);
      ASSERT_TRUE(e.has_value());
      EXPECT_NEAR(e->g, open, tolerance);
      // Each point draws from its own stream: the same point gives the same value.
      EXPECT_EQ(gathered(grey, (a + b + c) / 3.0f, n)->g, e->g);
      ++tops;
    }
  }
  EXPECT_EQ(tops, 4);
  EXPECT_EQ(gathered.gather_count().gathered, 8u);
  EXPECT_EQ(gathered.gather_count().late, 0u);
  // Past its deadline the bake reads the solution, point for point as without a gather, and
  // counts those points.
  rad::bake::BakeGather late{rays, 3};
  late.deadline = std::chrono::steady_clock::now();
  const rad::bake::SolutionAtInput reading(s.scene, s.solution, rad::bake::Quantity::irradiance);
  const rad::bake::SolutionAtInput past(s.scene, s.solution, rad::bake::Quantity::irradiance, late);
  const Vec3 floor_point(0.3f, 0.0f, 1.2f), up(0.0f, 1.0f, 0.0f);
  ASSERT_TRUE(reading(grey, floor_point, up).has_value());
  EXPECT_EQ(past(grey, floor_point, up)->g, reading(grey, floor_point, up)->g);
  EXPECT_EQ(past.gather_count().late, 1u);
  fs::remove_all(dir);
}

TEST(Lightmap, VertexGatherIsUnbiasedOnOpenSurfacesAndRepeatable) {
  // `--onto elements --bake-gather N` (gather_at_vertices): each vertex of the element mesh takes
  // its light from N points of the input under the disk it stands for. On the panels' tops only
  // the sun and the sky reach: E = 2 + 0.3π, exact at every sample as in the test above.
  const fs::path dir = fresh_dir("vertex-gather");
  const Solved s = solve(write_model(dir), 400);
  const double open = 2.0 + 0.3 * M_PI;
  const int rays = 4096;
  const double tolerance = 1e-4 * open;
  rad::bake::BakeGatherCount count;
  const rad::solver::Solution gathered = rad::bake::gather_at_vertices(s.scene, s.solution, rad::bake::BakeGather{rays, 3}, &count);
  const rad::mesh::RadiosityMesh& mesh = s.solution.mesh;
  ASSERT_EQ(gathered.vertex_irradiance.size(), mesh.vertex_count());
  size_t tops = 0;
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    const Vec3 p = mesh.positions[v];
    if (!(mesh.normals[v].y > 0.999f && std::abs(p.y - 1.0f) < 1e-4f)) continue;
    EXPECT_NEAR(gathered.vertex_irradiance[v].g, open, tolerance) << "vertex " << v << " at " << p.x << ", " << p.z;
    // Radiosity follows from it: B = ρE on the unlit panels.
    EXPECT_NEAR(gathered.vertex_radiosity[v].g, s.solution.vertex_albedo[v].g * gathered.vertex_irradiance[v].g,
                1e-5 * open);
    ++tops;
  }
  EXPECT_GT(tops, 8u);
  EXPECT_GE(count.gathered, tops);
  EXPECT_LE(count.gathered, mesh.vertex_count());
  EXPECT_EQ(count.late, 0u);
  // Each vertex draws its own stream: the same for any thread count.
  {
    const rc::util::ThreadLimit one(1);
    const rad::solver::Solution again = rad::bake::gather_at_vertices(s.scene, s.solution, rad::bake::BakeGather{rays, 3});
    for (size_t v = 0; v < mesh.vertex_count(); ++v) EXPECT_EQ(again.vertex_irradiance[v].g, gathered.vertex_irradiance[v].g);
  }
  // Past its deadline every vertex keeps the solve's value, and is counted.
  rad::bake::BakeGather late{rays, 3};
  late.deadline = std::chrono::steady_clock::now();
  const rad::solver::Solution kept = rad::bake::gather_at_vertices(s.scene, s.solution, late, &count);
  EXPECT_EQ(count.late, mesh.vertex_count());
  EXPECT_EQ(count.gathered, 0u);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) EXPECT_EQ(kept.vertex_irradiance[v].g, s.solution.vertex_irradiance[v].g);
  fs::remove_all(dir);
}

/// The input's triangles with area as positions, by bits, in order: what the output must reproduce.
std::vector<std::array<float, 9>> triangles_of(const tinygltf::Model& m, const tinygltf::Primitive& p) {
  const auto bytes = [&](int index, size_t element) {
    const tinygltf::Accessor& a = m.accessors.at(size_t(index));
    const tinygltf::BufferView& v = m.bufferViews.at(size_t(a.bufferView));
    const size_t stride = v.byteStride ? v.byteStride : element;
    const unsigned char* base = m.buffers.at(size_t(v.buffer)).data.data() + v.byteOffset + a.byteOffset;
    std::vector<std::string> out;
    for (size_t i = 0; i < a.count; ++i) out.emplace_back(reinterpret_cast<const char*>(base + i * stride), element);
    return out;
  };
  const auto positions = bytes(p.attributes.at("POSITION"), 12);
  std::vector<uint32_t> indices;
  if (p.indices < 0) {
    for (uint32_t i = 0; i < positions.size(); ++i) indices.push_back(i);
  } else {
    const tinygltf::Accessor& ia = m.accessors.at(size_t(p.indices));
    for (const std::string& raw : bytes(p.indices, size_t(tinygltf::GetComponentSizeInBytes(uint32_t(ia.componentType))))) {
      uint32_t index = 0;
      std::memcpy(&index, raw.data(), raw.size());
      indices.push_back(index);
    }
  }
  std::vector<std::array<float, 9>> out;
  if (p.mode >= 0 && p.mode != TINYGLTF_MODE_TRIANGLES) return out;  // strips and fans are not compared
  for (size_t i = 0; i + 2 < indices.size(); i += 3) {
    std::array<float, 9> t;
    for (size_t k = 0; k < 3; ++k) std::memcpy(&t[3 * k], positions.at(indices[i + k]).data(), 12);
    // Faces without area are dropped by the loader, and by the writer with it.
    const Vec3 a(t[0], t[1], t[2]), b(t[3], t[4], t[5]), c(t[6], t[7], t[8]);
    if (glm::length(glm::cross(b - a, c - a)) > 0.0f) out.push_back(t);
  }
  return out;
}

tinygltf::Model load(const fs::path& path) { return load_gltf_model(path); }

TEST(Lightmap, TheGltfKeepsItsNodesAndFacesAndGainsAUvSet) {
  const fs::path dir = fresh_dir("gltf");
  const fs::path scene = write_model(dir);
  const std::string before = slurp(dir / "model.gltf");
  for (const char* name : {"lit.gltf", "lit.glb"}) {
    const CliResult r = run_command(
        kGilt + " radiosity " + quoted(scene) + " --lightmap 64 --elements 400 -q -o " + quoted(dir / name), dir);
    ASSERT_EQ(r.code, 0) << r.err;
    const tinygltf::Model in = load(dir / "model.gltf"), out = load(dir / name);
    ASSERT_EQ(out.nodes.size(), in.nodes.size());
    EXPECT_EQ(out.meshes.size(), in.meshes.size() + 1) << "panel B gets its own copy of the panel";
    for (size_t n = 0; n < in.nodes.size(); ++n) {
      EXPECT_EQ(out.nodes[n].translation, in.nodes[n].translation);
      const tinygltf::Primitive &pi = in.meshes.at(size_t(in.nodes[n].mesh)).primitives.at(0),
                                &po = out.meshes.at(size_t(out.nodes[n].mesh)).primitives.at(0);
      // The same triangles, corner by corner, to the bit.
      EXPECT_EQ(triangles_of(out, po), triangles_of(in, pi)) << "node " << n;
      // The model has no UVs: the lightmap's set is TEXCOORD_0, named with the EXR in the extras.
      ASSERT_TRUE(po.attributes.count("TEXCOORD_0")) << "node " << n;
      EXPECT_EQ(out.accessors.at(size_t(po.attributes.at("TEXCOORD_0"))).count,
                out.accessors.at(size_t(po.attributes.at("POSITION"))).count);
      ASSERT_GE(po.material, 0);
      const tinygltf::Value& extras = out.materials.at(size_t(po.material)).extras.Get("gilt_lightmap");
      ASSERT_TRUE(extras.IsObject()) << "node " << n;
      const std::string stem = fs::path(name).stem().string();
      EXPECT_EQ(extras.Get("uri").Get<std::string>(), stem + "_lightmap.exr");
      EXPECT_EQ(extras.Get("texCoord").GetNumberAsInt(), 0);
    }
    const std::string stem = fs::path(name).stem().string();
    const rc::util::Image image = rc::util::read_image((dir / (stem + "_lightmap.exr")).string());
    EXPECT_EQ(image.width, 64);
    EXPECT_EQ(image.height, 64);
    size_t lit = 0;
    for (const rc::Rgb& p : image.pixels) {
      EXPECT_TRUE(std::isfinite(p.r) && p.r >= 0.0f);
      lit += p.g > 0.0f;
    }
    EXPECT_GT(lit, 64u * 64u / 4u);
  }
  EXPECT_EQ(slurp(dir / "model.gltf"), before);
  // The atlas is the same for any thread count.
  for (const std::string gather : {"0", "4"}) {  // and with a final gather, whose points draw their own streams
    std::string bytes[2];
    for (int t = 1; t <= 2; ++t) {
      std::string stem(1, 't');  // built piecewise: GCC 12 warns falsely about "t" + std::string
      stem += std::to_string(t) + "g" + gather;
      const fs::path out = dir / (stem + ".glb");
      const CliResult r = run_command(kGilt + " radiosity " + quoted(scene) + " --lightmap 64 --elements 400 -q --threads " +
                                          std::to_string(t) + " --bake-gather " + gather + " -o " + quoted(out),
                                      dir);
      ASSERT_EQ(r.code, 0) << r.err;
      if (gather != "0") {
        EXPECT_NE(r.out.find("gather:  4 shadow and gather rays"), std::string::npos) << r.out;
      }
      bytes[t - 1] = slurp(dir / (stem + "_lightmap.exr"));
    }
    EXPECT_FALSE(bytes[0].empty());
    EXPECT_TRUE(bytes[0] == bytes[1]) << "--threads 1 and 2 baked different atlases, --bake-gather " << gather;
  }
  // On the element mesh's export the gather takes each vertex's light from the input under it,
  // with the same bytes for any thread count.
  std::string elements[2];
  for (int t = 1; t <= 2; ++t) {
    const std::string out = "e" + std::to_string(t) + ".ply";
    const CliResult r = run_command(kGilt + " radiosity " + quoted(scene) + " --elements 400 --bake-gather 4 -q --threads " +
                                        std::to_string(t) + " -o " + quoted(dir / out),
                                    dir);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("vertices traced from the input surface under them, 4 rays each"), std::string::npos) << r.out;
    elements[t - 1] = slurp(dir / out);
  }
  EXPECT_FALSE(elements[0].empty());
  EXPECT_TRUE(elements[0] == elements[1]) << "--threads 1 and 2 exported different vertex colours with --bake-gather";
  fs::remove_all(dir);
}

TEST(Lightmap, SharedScenesKeepTheirNodesAndTriangles) {
  const fs::path scenes = fs::path(GILT_SOURCE_DIR) / ".." / "shared" / "scenes";
  if (!fs::is_directory(scenes)) GTEST_SKIP() << scenes << " is not beside the checkout";
  const fs::path dir = fresh_dir("shared");
  const struct {
    fs::path scene, model;
  } cases[] = {
      {scenes / "wrap" / "truck-lit.json", scenes / "milk-truck" / "CesiumMilkTruck.gltf"},
      {scenes / "animate-all" / "24_animation_pointer.gltf", scenes / "animate-all" / "24_animation_pointer.gltf"},
  };
  for (const auto& c : cases) {
    if (!fs::exists(c.model)) continue;
    const fs::path out = dir / (c.model.stem().string() + ".glb");
    const CliResult r = run_command(
        kGilt + " radiosity " + quoted(c.scene) + " --lightmap 256 --elements 2000 -q -o " + quoted(out), dir);
    ASSERT_EQ(r.code, 0) << c.scene << "\n" << r.err;
    const tinygltf::Model in = load(c.model), o = load(out);
    ASSERT_EQ(o.nodes.size(), in.nodes.size()) << c.model;
    EXPECT_EQ(o.animations.size(), in.animations.size()) << c.model;
    EXPECT_EQ(o.textures.size(), in.textures.size()) << c.model;
    EXPECT_GE(o.materials.size(), in.materials.size()) << c.model;
    size_t lightmapped = 0;
    for (size_t n = 0; n < in.nodes.size(); ++n) {
      EXPECT_EQ(o.nodes[n].children, in.nodes[n].children);
      if (in.nodes[n].mesh < 0) continue;
      const tinygltf::Mesh &mi = in.meshes.at(size_t(in.nodes[n].mesh)), &mo = o.meshes.at(size_t(o.nodes[n].mesh));
      ASSERT_EQ(mo.primitives.size(), mi.primitives.size());
      for (size_t p = 0; p < mi.primitives.size(); ++p) {
        EXPECT_EQ(triangles_of(o, mo.primitives[p]), triangles_of(in, mi.primitives[p])) << c.model << " node " << n;
        // Every attribute the input had is still there, over the output's vertices.
        for (const auto& [name, accessor] : mi.primitives[p].attributes) {
          ASSERT_TRUE(mo.primitives[p].attributes.count(name)) << name;
          EXPECT_EQ(o.accessors.at(size_t(mo.primitives[p].attributes.at(name))).count,
                    o.accessors.at(size_t(mo.primitives[p].attributes.at("POSITION"))).count)
              << name;
        }
        lightmapped += mo.primitives[p].attributes.size() > mi.primitives[p].attributes.size();
      }
    }
    EXPECT_GT(lightmapped, 0u) << c.model;
  }
  fs::remove_all(dir);
}

/// A floor and, 1 above it, a panel (each placed once), with UV sets: `uv1` true gives both
/// TEXCOORD_1 in separate parts of [0, 1]² (floor left half, panel top right corner); TEXCOORD_0
/// maps each to the whole square (overlapping) unless `uv0_apart`, which puts them apart too.
fs::path write_uv_model(const fs::path& dir, bool uv1, bool uv0_apart) {
  std::string bin;
  const auto put = [&bin](std::initializer_list<float> xs) {
    for (float x : xs) bin.append(reinterpret_cast<const char*>(&x), 4);
  };
  put({-2, 0, 2, 2, 0, 2, 2, 0, -2, -2, 0, -2});                       // 0: floor positions, 48 bytes
  put({-0.5f, 1, 0.5f, 0.5f, 1, 0.5f, 0.5f, 1, -0.5f, -0.5f, 1, -0.5f});  // 48: panel positions
  for (uint16_t i : {0, 1, 2, 0, 2, 3}) bin.append(reinterpret_cast<const char*>(&i), 2);  // 96: indices
  bin.append(4, '\0');                                                  // 108: pad to 112
  if (uv0_apart) {
    put({0, 1, 0.5f, 1, 0.5f, 0.5f, 0, 0.5f});                          // 112: floor TEXCOORD_0
    put({0.6f, 0.4f, 1, 0.4f, 1, 0, 0.6f, 0});                          // 144: panel TEXCOORD_0
  } else {
    put({0, 1, 1, 1, 1, 0, 0, 0});
    put({0, 1, 1, 1, 1, 0, 0, 0});
  }
  put({0, 1, 0.5f, 1, 0.5f, 0, 0, 0});                                  // 176: floor TEXCOORD_1
  put({0.6f, 0.4f, 1, 0.4f, 1, 0, 0.6f, 0});                            // 208: panel TEXCOORD_1
  write_file(dir / "uv.bin", bin);
  Json model = Json::parse(R"({
    "asset": {"version": "2.0"},
    "extensionsUsed": ["KHR_materials_specular"],
    "scene": 0,
    "scenes": [{"nodes": [0, 1]}],
    "nodes": [{"name": "floor", "mesh": 0}, {"name": "panel", "mesh": 1}],
    "meshes": [
      {"name": "floor", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 3}, "indices": 2, "material": 0}]},
      {"name": "panel", "primitives": [{"attributes": {"POSITION": 1, "TEXCOORD_0": 4}, "indices": 2, "material": 0}]}],
    "materials": [{"name": "grey", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0},
                   "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}],
    "accessors": [
      {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-2, 0, -2], "max": [2, 0, 2]},
      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-0.5, 1, -0.5], "max": [0.5, 1, 0.5]},
      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"},
      {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"},
      {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC2"},
      {"bufferView": 5, "componentType": 5126, "count": 4, "type": "VEC2"},
      {"bufferView": 6, "componentType": 5126, "count": 4, "type": "VEC2"}],
    "bufferViews": [
      {"buffer": 0, "byteOffset": 0, "byteLength": 48, "target": 34962},
      {"buffer": 0, "byteOffset": 48, "byteLength": 48, "target": 34962},
      {"buffer": 0, "byteOffset": 96, "byteLength": 12, "target": 34963},
      {"buffer": 0, "byteOffset": 112, "byteLength": 32, "target": 34962},
      {"buffer": 0, "byteOffset": 144, "byteLength": 32, "target": 34962},
      {"buffer": 0, "byteOffset": 176, "byteLength": 32, "target": 34962},
      {"buffer": 0, "byteOffset": 208, "byteLength": 32, "target": 34962}],
    "buffers": [{"uri": "uv.bin"}]})");
  model["buffers"][0]["byteLength"] = bin.size();
  if (uv1) {
    model["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_1"] = 5;
    model["meshes"][1]["primitives"][0]["attributes"]["TEXCOORD_1"] = 6;
  }
  write_file(dir / "uv.gltf", model.dump(2));
  write_file(dir / "uv-scene.json", R"({
    "meshes": [{"file": "uv.gltf"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 2},
               {"type": "environment", "radiance": 0.3}]})");
  return dir / "uv-scene.json";
}

TEST(Lightmap, TheInputsOwnUvSetIsUsedWhenItCanHoldTheLightmap) {
  const fs::path dir = fresh_dir("input-uvs");
  struct Case {
    bool uv1, uv0_apart;
    int expected_set;
  };
  // TEXCOORD_1 first; else TEXCOORD_0 when its charts lie apart; else gilt's own (overlapping
  // TEXCOORD_0, as a tiling or mirrored texture's).
  for (const Case c : {Case{true, false, 1}, Case{false, true, 0}, Case{false, false, -1}}) {
    const Solved s = solve(write_uv_model(dir, c.uv1, c.uv0_apart), 400);
    const rad::bake::Lightmap lm = rad::bake::bake_lightmap(s.scene, s.solution, rad::bake::Quantity::irradiance, 128);
    EXPECT_EQ(lm.stats.uv_set, c.expected_set) << lm.stats.uv_source;
    if (c.expected_set < 0) {
      EXPECT_NE(lm.stats.uv_source.find("overlap"), std::string::npos) << lm.stats.uv_source;
      continue;
    }
    // The floor's corners in the set used, by vertex.
    size_t floor = 0;
    while (s.scene.meshes[floor].origin.mesh != 0) ++floor;
    const rc::scene::TriangleMesh& mesh = s.scene.meshes[floor];
    const float low = c.expected_set == 1 ? 0.0f : 0.5f;
    const Vec2 corner[4] = {Vec2(0, 1), Vec2(0.5f, 1), Vec2(0.5f, low), Vec2(0, low)};
    for (size_t k = 0; k < mesh.indices.size(); ++k) EXPECT_EQ(lm.corner_uv[floor][k], corner[mesh.indices[k]]);
    // The open floor (beside the panel's shadow) holds E = 2 + 0.3π.
    const double open = 2.0 + 0.3 * M_PI;
    EXPECT_NEAR(lm.at(floor, 0, 0.1f, 0.05f).g, open, 0.06 * open);
  }
  // Written out: the input's JSON kept but for the extras, which name TEXCOORD_1; no new buffer.
  const fs::path scene = write_uv_model(dir, true, false);
  const CliResult r =
      run_command(kGilt + " radiosity " + quoted(scene) + " --lightmap 128 --elements 400 -q -o " + quoted(dir / "out.gltf"), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  Json in = Json::parse(slurp(dir / "uv.gltf")), out = Json::parse(slurp(dir / "out.gltf"));
  for (Json& p : {std::ref(out["meshes"][0]["primitives"][0]), std::ref(out["meshes"][1]["primitives"][0])}) {
    EXPECT_EQ(p["extras"]["gilt_lightmap"]["texCoord"], 1);
    p.erase("extras");
  }
  EXPECT_EQ(out["materials"][0]["extras"]["gilt_lightmap"]["uri"], "out_lightmap.exr");
  out["materials"][0].erase("extras");
  EXPECT_EQ(out, in);
  EXPECT_FALSE(fs::exists(dir / "out.bin"));
  fs::remove_all(dir);
}

TEST(Lightmap, CompressedQuantizedAndSparseModelsAreNamedNotMisread) {
  // gilt reads neither meshopt compression nor quantized positions, and no sparse accessors:
  // each must be refused with its name, and the input left as it was. (Draco is decoded:
  // test_gltf_draco.)
  const fs::path dir = fresh_dir("unsupported");
  const fs::path scene = write_uv_model(dir, true, false);
  const Json model = Json::parse(slurp(dir / "uv.gltf"));
  struct Case {
    std::string name, message;
    std::function<void(Json&)> edit;
  };
  const Case cases[] = {
      {"meshopt", "EXT_meshopt_compression",
       [](Json& j) { j["extensionsUsed"] = j["extensionsRequired"] = {"EXT_meshopt_compression"}; }},
      {"quantized", "KHR_mesh_quantization",
       [](Json& j) { j["extensionsUsed"] = j["extensionsRequired"] = {"KHR_mesh_quantization"}; }},
      {"sparse", "sparse",
       [](Json& j) {
         j["accessors"][0]["sparse"] = {{"count", 1},
                                        {"indices", {{"bufferView", 2}, {"componentType", 5123}}},
                                        {"values", {{"bufferView", 0}}}};
       }},
  };
  for (const Case& c : cases) {
    Json edited = model;
    c.edit(edited);
    write_file(dir / "uv.gltf", edited.dump(2));
    const std::string before = slurp(dir / "uv.gltf");
    for (const char* mode : {"--lightmap 64", "--onto input"}) {
      const CliResult r = run_command(kGilt + " radiosity " + quoted(scene) + " " + mode + " -q -o " +
                                          quoted(dir / (c.name + ".glb")),
                                      dir);
      EXPECT_NE(r.code, 0) << c.name << " " << mode;
      EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << " " << mode << ": " << r.err;
      EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(dir / (c.name + ".glb")));
    }
    EXPECT_EQ(slurp(dir / "uv.gltf"), before);
  }
  fs::remove_all(dir);
}

TEST(Lightmap, AnObjComesOutAsGltfWithItsUvsAndTheLightmaps) {
  const fs::path dir = fresh_dir("obj");
  write_file(dir / "room.mtl", "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.1 0.1\n");
  write_file(dir / "room.obj",
             "mtllib room.mtl\n"
             "v -2 0 2\nv 2 0 2\nv 2 0 -2\nv -2 0 -2\nv -2 2 -2\nv 2 2 -2\n"
             "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
             "usemtl white\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n"
             "usemtl red\nf 4/1 3/2 6/3\nf 4/1 6/3 5/4\n");
  write_file(dir / "scene.json", R"({"meshes": [{"file": "room.obj"}],
    "lights": [{"type": "directional", "direction": [0.2, -1, 0.4], "irradiance": 3},
               {"type": "environment", "radiance": 0.5}]})");
  const CliResult r = run_command(
      kGilt + " radiosity " + quoted(dir / "scene.json") + " --lightmap 64 --elements 300 -q -o " + quoted(dir / "room.glb"), dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const tinygltf::Model out = load(dir / "room.glb");
  ASSERT_EQ(out.meshes.size(), 1u);
  ASSERT_EQ(out.meshes[0].primitives.size(), 2u);
  ASSERT_EQ(out.materials.size(), 2u);
  for (const tinygltf::Primitive& p : out.meshes[0].primitives) {
    EXPECT_TRUE(p.attributes.count("TEXCOORD_0"));  // the OBJ's own, v flipped for glTF
    EXPECT_TRUE(p.attributes.count("TEXCOORD_1"));  // the lightmap's
    EXPECT_EQ(triangles_of(out, p).size(), 2u);
    EXPECT_EQ(out.materials.at(size_t(p.material)).extras.Get("gilt_lightmap").Get("texCoord").GetNumberAsInt(), 1);
  }
  EXPECT_TRUE(fs::exists(dir / "room_lightmap.exr"));
  // A lightmap cannot go into an OBJ (one UV set): refused before solving.
  const CliResult bad =
      run_command(kGilt + " radiosity " + quoted(dir / "scene.json") + " --lightmap 64 -q -o " + quoted(dir / "x.obj"), dir);
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("--lightmap writes glTF"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}

TEST(Lightmap, BadRequestsAreRefusedBeforeSolving) {
  const fs::path dir = fresh_dir("bad");
  const fs::path scene = write_model(dir);
  const std::string q = quoted(scene) + " --elements 100 -q ";
  const struct {
    std::string args, message;
  } cases[] = {
      {q + "--lightmap 64 -o " + quoted(dir / "model.gltf"), "is the input model"},
      {q + "--lightmap 64 --onto elements -o " + quoted(dir / "x.glb"), "cannot go with --onto elements"},
      {q + "--lightmap 64 --fit point -o " + quoted(dir / "x.glb"), "--fit applies to vertex colours"},
      {q + "--lightmap 8 -o " + quoted(dir / "x.glb"), "--lightmap"},
      {q + "--lightmap 64 -o " + quoted(dir / "x.ply"), "--lightmap writes glTF"},
      {q + "--lightmap 64 -o " + quoted(dir / "no-such-folder" / "x.glb"), "does not exist"},
      {"cornell --lightmap 64 -o " + quoted(dir / "x.glb"), "use --onto elements"},
  };
  const std::string before = slurp(dir / "model.gltf");
  for (const auto& c : cases) {
    const CliResult r = run_command(kGilt + " radiosity " + c.args, dir);
    EXPECT_NE(r.code, 0) << c.args;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << "\n" << r.err;
  }
  EXPECT_EQ(slurp(dir / "model.gltf"), before);
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  EXPECT_FALSE(fs::exists(dir / "x_lightmap.exr"));
  fs::remove_all(dir);
}

TEST(Lightmap, AnAtlasTooSmallForItsChartsIsRefusedNotLeftEmpty) {
  // Six separate triangles: six charts. In 16² each needs, at any texel density above 0, a cell
  // of 2 texels and 2 × kLightmapPad of border (6 × 6: four fit); as points, cells of 5 × 5 (nine
  // fit), which once gave a layout at density 0 where no face held a texel and an empty atlas
  // was written. Now 16 is refused, before the solve, and 32 bakes.
  const fs::path dir = fresh_dir("too-small");
  std::string obj;
  for (int i = 0; i < 6; ++i) {
    const float x = 3.0f * float(i);
    obj += "v " + std::to_string(x) + " 0 0\nv " + std::to_string(x + 1) + " 0 0\nv " + std::to_string(x) + " 0 -1\n";
    obj += "f " + std::to_string(3 * i + 1) + " " + std::to_string(3 * i + 2) + " " + std::to_string(3 * i + 3) + "\n";
  }
  write_file(dir / "tiles.obj", obj);
  write_file(dir / "scene.json", R"({"meshes": [{"file": "tiles.obj"}],
    "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": 1}]})");
  const rc::scene::Scene scene = rc::io::load_scene((dir / "scene.json").string());
  try {
    rad::bake::check_lightmap_layout(scene, 16);
    ADD_FAILURE() << "a 16-texel atlas cannot hold six charts";
  } catch (const rc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("32 holds them"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(rad::bake::check_lightmap_layout(scene, 32));
  const CliResult r = run_command(kGilt + " radiosity " + quoted(dir / "scene.json") + " --lightmap 16 -q -o " +
                                      quoted(dir / "x.glb"),
                                  dir);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("give a larger size (32 holds them)"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "x.glb"));
  rad::solver::SolverSettings settings;
  settings.mesh.elements = 50;
  const rad::bake::Lightmap lm = rad::bake::bake_lightmap(scene, rad::solver::solve(scene, settings), rad::bake::Quantity::irradiance, 32);
  EXPECT_EQ(lm.stats.charts, 6u);
  // Each face holds texels: at least its one texel of density, of the 32² atlas.
  EXPECT_GE(lm.stats.texels, 6u);
  EXPECT_GT(lm.stats.texels_per_metre, 0.0);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gilt::test
