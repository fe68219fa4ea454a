// gilt's exports opened in Blender (Debian's `blender`, headless) as a user would open them,
// through scripts/blender_check.py: Blender must hold the colours gilt wrote, and show the
// lightmaps gilt names. Each case renders a picture into <build>/clients/ for a reviewer.
// Skipped when blender is not installed (scripts/setup.sh test installs it).
//
// Blender reports colours as linear floats in its own domain (per vertex or per face corner)
// and, for 8-bit attributes, after sRGB quantisation; gilt's files hold one colour per vertex.
// The means are compared within 10 %: corner weighting moves a mean by a few per cent on
// these meshes and 8-bit quantisation by far less, while a wrong convention (sRGB read as
// linear, unclamped HDR, a lost attribute) moves it by a factor.

#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "tests/support/cli_run.h"
#include "tests/support/model_files.h"

namespace gilt::test {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

const std::string kGilt = GILT_BINARY_PATH;

bool have_blender() { return std::system("command -v blender >/dev/null 2>&1") == 0; }

/// What Blender reported: its "gilt-check <kind> <json>" lines.
struct BlenderReport {
  std::vector<Json> colours, lightmaps;
  Json render;
  double colour_mean() const {  // over all colour attributes' elements
    double sum = 0.0, count = 0.0;
    for (const Json& c : colours) {
      sum += c["mean"].get<double>() * c["count"].get<double>();
      count += c["count"].get<double>();
    }
    return count > 0.0 ? sum / count : 0.0;
  }
};

BlenderReport open_in_blender(const fs::path& model, const fs::path& picture, double scale, const fs::path& dir) {
  std::string command = "blender -b --factory-startup --python ";
  command += quoted(fs::path(GILT_SOURCE_DIR) / "scripts" / "blender_check.py");
  command += " -- ";
  command += quoted(model);
  command += ' ';
  command += quoted(picture);
  command += ' ';
  command += std::to_string(scale);
  const CliResult r = run_command(command, dir);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  BlenderReport report;
  std::istringstream lines(r.out);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("gilt-check ", 0) != 0) continue;
    const size_t space = line.find(' ', 11);
    const std::string kind = line.substr(11, space - 11);
    const Json j = Json::parse(line.substr(space + 1));
    if (kind == "colour") report.colours.push_back(j);
    if (kind == "lightmap") report.lightmaps.push_back(j);
    if (kind == "render") report.render = j;
  }
  EXPECT_TRUE(report.render.is_object()) << "Blender did not render " << model << "\n" << r.out << r.err;
  return report;
}

/// Mean of a glTF's COLOR_0 over every primitive's vertices.
double gltf_colour_mean(const fs::path& path) {
  const tinygltf::Model m = load_gltf_model(path);
  double sum = 0.0;
  size_t count = 0;
  for (const tinygltf::Mesh& mesh : m.meshes)
    for (const tinygltf::Primitive& p : mesh.primitives) {
      const auto it = p.attributes.find("COLOR_0");
      if (it == p.attributes.end()) continue;
      const tinygltf::Accessor& a = m.accessors.at(size_t(it->second));
      const tinygltf::BufferView& v = m.bufferViews.at(size_t(a.bufferView));
      const float* x = reinterpret_cast<const float*>(m.buffers.at(size_t(v.buffer)).data.data() + v.byteOffset +
                                                      a.byteOffset);
      for (size_t i = 0; i < 3 * a.count; ++i) sum += x[i];
      count += 3 * a.count;
    }
  return count ? sum / double(count) : 0.0;
}

/// Mean of an OBJ's `v x y z r g b` colours, which gilt writes sRGB-encoded, taken back to linear.
double obj_colour_mean(const fs::path& path) {
  std::istringstream in(slurp(path));
  double sum = 0.0;
  size_t count = 0;
  for (std::string line; std::getline(in, line);) {
    std::istringstream words(line);
    std::string tag;
    double x, y, z, r, g, b;
    const auto linear = [](double e) { return e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4); };
    if (words >> tag && tag == "v" && words >> x >> y >> z >> r >> g >> b)
      sum += linear(r) + linear(g) + linear(b), count += 3;
  }
  return count ? sum / double(count) : 0.0;
}

fs::path pictures() {
  const fs::path dir = fs::path(GILT_BUILD_DIR) / "clients";
  fs::create_directories(dir);
  return dir;
}

/// Two walls and a floor of two materials, lit by a sun and a sky, as OBJ behind a JSON wrapper.
fs::path write_room(const fs::path& dir) {
  write_file(dir / "room.mtl", "newmtl white\nKd 0.7 0.7 0.7\nnewmtl red\nKd 0.6 0.1 0.1\n");
  write_file(dir / "room.obj",
             "mtllib room.mtl\n"
             "v -2 0 2\nv 2 0 2\nv 2 0 -2\nv -2 0 -2\nv -2 2 -2\nv 2 2 -2\nv -2 2 2\n"
             "usemtl white\nf 1 2 3\nf 1 3 4\n"
             "usemtl red\nf 4 3 6\nf 4 6 5\nf 1 4 5\nf 1 5 7\n");
  write_file(dir / "scene.json", R"({"meshes": [{"file": "room.obj"}],
    "lights": [{"type": "directional", "direction": [0.4, -1, 0.3], "irradiance": 2},
               {"type": "environment", "radiance": 0.4}]})");
  return dir / "scene.json";
}

TEST(Blender, ShowsTheColoursOfElementExports) {
  if (!have_blender()) GTEST_SKIP() << "blender is not installed (scripts/setup.sh test installs it)";
  const fs::path dir = fresh_dir("gilt-clients", "elements");
  const fs::path glb = dir / "cornell.glb", ply = dir / "cornell.ply", obj = dir / "cornell.obj";
  for (const fs::path& out : {glb, ply, obj}) {
    const CliResult r = run_command(kGilt + " radiosity cornell --elements 800 -q -o " + quoted(out), dir);
    ASSERT_EQ(r.code, 0) << r.err;
  }
  // The same solve (deterministic) in all three, with gilt's default display colours: COLOR_0 is
  // the radiance clamped to [0, 1]; the PLY's 8-bit sRGB bytes and the OBJ's sRGB-encoded floats
  // are the same values encoded, which Blender decodes back to linear.
  const double expected = gltf_colour_mean(glb);
  ASSERT_GT(expected, 0.0);
  EXPECT_NEAR(obj_colour_mean(obj), expected, 1e-4 * expected + 1e-6);
  std::vector<BlenderReport> seen;
  for (const fs::path& out : {glb, ply, obj}) {
    const BlenderReport b = open_in_blender(out, pictures() / ("cornell-elements" + out.extension().string() + ".png"),
                                            1.0, dir);
    ASSERT_FALSE(b.colours.empty()) << out;
    EXPECT_NEAR(b.colour_mean(), expected, 0.1 * expected) << out;
    EXPECT_GT(b.render.value("covered", 0.0), 0.05) << out;
    EXPECT_GT(b.render.value("mean", 0.0), 0.0) << out;
    seen.push_back(b);
  }
  // The three pictures are one picture: the same model seen from the same place (the PLY turned
  // y up, see blender_check.py) covers the same pixels, and shows the same colours up to the
  // PLY's 8-bit codes and Cycles' 4 samples of the pixel filter at the edges (2 %).
  for (size_t i = 1; i < seen.size(); ++i) {
    EXPECT_NEAR(seen[i].render.value("covered", 0.0), seen[0].render.value("covered", 0.0), 0.01) << i;
    EXPECT_NEAR(seen[i].render.value("mean", 0.0), seen[0].render.value("mean", 0.0),
                0.02 * seen[0].render.value("mean", 0.0)) << i;
  }
  fs::remove_all(dir);
}

TEST(Blender, ShowsColoursBakedOntoAnObjAndItsLightmap) {
  if (!have_blender()) GTEST_SKIP() << "blender is not installed (scripts/setup.sh test installs it)";
  const fs::path dir = fresh_dir("gilt-clients", "room");
  const fs::path scene = write_room(dir);
  const fs::path obj = dir / "baked.obj", glb = dir / "lit.glb";
  CliResult r = run_command(kGilt + " radiosity " + quoted(scene) +
                                " --onto input --quantity irradiance --exposure -2 --elements 400 -q -o " + quoted(obj),
                            dir);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run_command(kGilt + " radiosity " + quoted(scene) + " --lightmap 128 --quantity irradiance --elements 400 -q -o " +
                      quoted(glb),
                  dir);
  ASSERT_EQ(r.code, 0) << r.err;

  // OBJ: `v x y z r g b`, clamped display (sRGB) values, which Blender decodes to a linear float
  // colour per vertex.
  const double expected = obj_colour_mean(obj);
  ASSERT_GT(expected, 0.0);
  const BlenderReport colours = open_in_blender(obj, pictures() / "room-onto-input.obj.png", 1.0, dir);
  ASSERT_FALSE(colours.colours.empty());
  EXPECT_NEAR(colours.colour_mean(), expected, 0.1 * expected);

  // The lightmap: named in each material's extras, on the second UV map (the OBJ's own UVs are
  // absent, so the lightmap's set is TEXCOORD_0 here and Blender's first map).
  const BlenderReport lit = open_in_blender(glb, pictures() / "room-lightmap.glb.png", 0.25, dir);
  ASSERT_EQ(lit.lightmaps.size(), 1u);
  EXPECT_EQ(lit.lightmaps[0]["image"], "lit_lightmap.exr");
  EXPECT_EQ(lit.lightmaps[0]["width"], 128);
  EXPECT_GT(lit.render.value("covered", 0.0), 0.05);
  EXPECT_GT(lit.render.value("mean", 0.0), 0.02);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace gilt::test
