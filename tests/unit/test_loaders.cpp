// Scene loaders: OBJ/MTL, glTF (.gltf and .glb), PLY, gilt's JSON, the built-in scenes, and bad
// input, which must raise InputError naming the file and the line or field. Fixtures are written
// to a fresh temporary directory at run time.

#include <gtest/gtest.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::raytrace_core::io {
namespace {

namespace fs = std::filesystem;

class Loaders : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("gilt_loaders_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(counter++) + "_" + info->name());
    fs::create_directories(dir_);
    // Linear copies of sRGB textures go with the test's files rather than into $HOME's cache.
    ::setenv("GILT_TEXTURE_CACHE", (dir_ / "texture-cache").c_str(), 1);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// Writes `content` to `name` inside the test's directory and returns the full path.
  std::string write(const std::string& name, const std::string& content) {
    const fs::path path = dir_ / name;
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << content;
    return path.string();
  }
  fs::path dir_;
};

/// The InputError message `f` throws; a test failure when it throws nothing or something else.
std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got: " << e.what();
    return {};
  }
  ADD_FAILURE() << "expected InputError, nothing was thrown";
  return {};
}

#define EXPECT_CONTAINS(text, part) EXPECT_NE((text).find(part), std::string::npos) << "in: " << (text)

bool has_warning(const scene::Scene& scene, const std::string& part) {
  for (const std::string& w : scene.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

Vec3 triangle_normal(const scene::TriangleMesh& mesh, size_t t) {
  const Vec3 a = mesh.positions[mesh.indices[3 * t]], b = mesh.positions[mesh.indices[3 * t + 1]],
             c = mesh.positions[mesh.indices[3 * t + 2]];
  return glm::cross(b - a, c - a);
}

const scene::TriangleMesh& mesh_named(const scene::Scene& scene, const std::string& name) {
  for (const scene::TriangleMesh& m : scene.meshes)
    if (m.name == name) return m;
  throw std::runtime_error("no mesh " + name);
}

// ---------------------------------------------------------------- OBJ + MTL

const char* kMtl = R"(newmtl lamp
Kd 0 0 0
Ke 17 12 4
newmtl glass
illum 7
Ni 1.33
Tf 0.9 0.9 1
Pr 0.4
newmtl chrome
illum 3
Kd 0 0 0
Ks 0.9 0.9 0.9
newmtl plastic
Kd 0.5 0.5 0.5
Ks 0.3 0.3 0.3
Ns 50
newmtl hot
Kd 0.8 0.8 0.8
Ks 0.5 0.5 0.5
Ns 10
)";

TEST_F(Loaders, ObjMaterialsSplitPerMaterial) {
  write("box.mtl", kMtl);
  const std::string obj = write("box.obj", R"(mtllib box.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vn 0 0 1
vt 0 0
usemtl lamp
f 1/1/1 2/1/1 3/1/1 4/1/1
usemtl glass
f 1 2 3
usemtl lamp
f 1/1/1 3/1/1 4/1/1
usemtl chrome
f 1 2 3
usemtl plastic
f 1 2 3
usemtl hot
f -4 -3 -2
)");
  scene::Scene scene = load_scene_file(obj);
  ASSERT_EQ(scene.materials.size(), 5u);
  ASSERT_EQ(scene.meshes.size(), 5u);  // one mesh per material, the two lamp groups merged
  for (const scene::TriangleMesh& mesh : scene.meshes) {
    const scene::Material& m = scene.materials[mesh.material];
    if (m.name == "lamp") {
      EXPECT_EQ(mesh.triangle_count(), 3u);  // the quad triangulated, plus the later lamp face
      EXPECT_EQ(mesh.normals.size(), mesh.positions.size());
      EXPECT_EQ(mesh.uvs.size(), mesh.positions.size());
      EXPECT_EQ(m.emission, Rgb(17, 12, 4));
    } else {
      EXPECT_EQ(mesh.triangle_count(), 1u);
      EXPECT_TRUE(mesh.normals.empty());
    }
  }
  const auto material = [&](const std::string& name) -> const scene::Material& {
    for (const scene::Material& m : scene.materials)
      if (m.name == name) return m;
    throw std::runtime_error("no material " + name);
  };
  EXPECT_EQ(material("glass").kind, scene::MaterialKind::dielectric);
  EXPECT_FLOAT_EQ(material("glass").ior, 1.33f);
  EXPECT_NEAR(material("glass").absorption.r, -std::log(0.9f), 1e-5f);
  EXPECT_EQ(material("glass").absorption.b, 0.0f);
  EXPECT_FLOAT_EQ(material("glass").roughness, 0.4f);  // Pr on glass: frosted, still glass
  EXPECT_TRUE(material("glass").is_rough_dielectric());
  EXPECT_EQ(material("chrome").kind, scene::MaterialKind::mirror);
  EXPECT_FLOAT_EQ(material("chrome").specular.g, 0.9f);
  EXPECT_EQ(material("plastic").kind, scene::MaterialKind::glossy);
  EXPECT_FLOAT_EQ(material("plastic").exponent, 50.0f);
  const scene::Material& hot = material("hot");  // Kd + Ks = 1.3 > 1: scaled to sum 1
  EXPECT_NEAR(hot.albedo.r + hot.specular.r, 1.0f, 1e-6f);
  EXPECT_TRUE(has_warning(scene, "Kd + Ks exceeds 1"));

  const scene::Scene committed = load_scene(obj);
  EXPECT_EQ(committed.lights().size(), 3u);  // the three lamp triangles
}

TEST_F(Loaders, ObjWithoutMtlGetsDefaultMaterial) {
  const std::string obj = write("plain.obj", "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  const scene::Scene scene = load_scene_file(obj);
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.materials[scene.meshes[0].material].kind, scene::MaterialKind::diffuse);
  EXPECT_TRUE(has_warning(scene, "missing.mtl"));
}

// Comments may follow the numbers on an MTL or OBJ line, as in McGuire's Cornell boxes; the
// numbers before them are read as usual.
TEST_F(Loaders, ObjAndMtlCommentsAfterNumbers) {
  write("commented.mtl", "newmtl red\nKa 0.63 0.065 0.05 # Red\nKd 0.63 0.065 0.05 # Red\nNs 10 # shiny\n");
  const std::string obj = write("commented.obj",
                                "mtllib commented.mtl # materials\nv 0 0 0 # origin\nv 1 0 0\n"
                                "v 0 1 0\nusemtl red\nf 1 2 3\n");
  const scene::Scene scene = load_scene_file(obj);
  ASSERT_EQ(scene.meshes.size(), 1u);
  const scene::Material& m = scene.materials[scene.meshes[0].material];
  EXPECT_NEAR(m.albedo.r, 0.63f, 1e-6f);
  EXPECT_NEAR(m.albedo.g, 0.065f, 1e-6f);
  write("bad.mtl", "newmtl red\nKd 0.5 0.5 # two numbers and a comment 3\n");
  const std::string bad_obj =
      write("bad.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(bad_obj); }), "bad.mtl:2:");
}

// A comment may also follow a name (newmtl, usemtl, map_Kd) or a face, which tinyobjloader would
// otherwise read as part of the name or as one more corner; McGuire's files also end lines in CRLF.
TEST_F(Loaders, ObjCommentsAfterNamesAndFaces) {
  write("named.mtl",
        "newmtl blue # Blue\r\n    Ka 0.161 0.133 0.427 # Blue\r\n    Kd 0.161 0.133 0.427 # Blue\r\n"
        "    map_Kd wall.png # the wall\r\n");
  write("wall.png", "not read before commit");
  const std::string obj = write("named.obj",
                                "mtllib named.mtl # lib\r\nv 0 0 0\r\nv 1 0 0\r\nv 0 1 0\r\nvt 0 0\r\n"
                                "usemtl blue # wall\r\nf 1/1 2/1 3/1 # one triangle\r\n");
  const scene::Scene scene = load_scene_file(obj);
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.meshes[0].triangle_count(), 1u);
  const scene::Material& m = scene.materials[scene.meshes[0].material];
  EXPECT_EQ(m.name, "blue");
  EXPECT_NEAR(m.albedo.b, 0.427f, 1e-6f);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(fs::path(scene.textures[0].file).filename(), "wall.png");
  EXPECT_FALSE(has_warning(scene, "not found"));
}

/// The albedo_texture map of a material, for comparing with an expected one.
void expect_map(const scene::TextureRef& ref, const std::array<float, 6>& expected) {
  for (size_t k = 0; k < 6; ++k) EXPECT_NEAR(ref.map[k], expected[k], 1e-6f) << "map[" << k << "]";
}

const char* kTexturedQuad = R"(mtllib textured.mtl
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vt 0.5 0.5
usemtl wood
f 1/1 2/2 3/3 4/4
usemtl other
f 1/1 2/2 3/3
f 1/5 3/3 4/4
)";

// map_Kd becomes the albedo texture: the file found next to the MTL, sRGB, repeating, and OBJ's
// upward v flipped into OpenImageIO's downward t.
TEST_F(Loaders, ObjMapKdBecomesAlbedoTexture) {
  write("textures/wood.png", "not read before commit");
  write("textured.mtl", "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd textures/wood.png\nnewmtl other\nKd 1 1 1\n");
  const std::string obj = write("textured.obj", kTexturedQuad);
  const scene::Scene scene = load_scene_file(obj);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].file, (dir_ / "textures" / "wood.png").lexically_normal().string());
  EXPECT_TRUE(scene.textures[0].srgb);
  EXPECT_EQ(scene.textures[0].wrap_s, scene::TextureWrap::repeat);
  EXPECT_EQ(scene.textures[0].wrap_t, scene::TextureWrap::repeat);
  const scene::TriangleMesh& wood = mesh_named(scene, "textured:wood");
  const scene::Material& m = scene.materials[wood.material];
  EXPECT_EQ(m.albedo, Rgb(0.5f));
  EXPECT_EQ(m.albedo_texture.image, 0);
  expect_map(m.albedo_texture, {1, 0, 0, 0, -1, 1});
  EXPECT_EQ(wood.uvs.size(), wood.positions.size());
  // Position 1 appears with two texture coordinates in `other`: the seam splits the vertex.
  const scene::TriangleMesh& other = mesh_named(scene, "textured:other");
  EXPECT_FALSE(scene.materials[other.material].is_textured());
  EXPECT_EQ(other.positions.size(), 5u);
  EXPECT_FALSE(has_warning(scene, "texture maps are ignored"));
  EXPECT_FALSE(has_warning(scene, "map_Kd"));
}

// -s and -o act on (u, v) before the flip: u' = 2u + 0.5, v' = 2v + 0, so s = 2u + 0.5 and
// t = 1 − v' = −2v + 1. -clamp on clamps both axes.
TEST_F(Loaders, ObjMapKdScaleOffsetAndClamp) {
  write("wood.png", "not read before commit");
  write("textured.mtl", "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd -s 2 2 -o 0.5 0 -clamp on wood.png\n");
  const std::string obj = write("textured.obj", kTexturedQuad);
  const scene::Scene scene = load_scene_file(obj);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(scene.textures[0].wrap_s, scene::TextureWrap::clamp);
  EXPECT_EQ(scene.textures[0].wrap_t, scene::TextureWrap::clamp);
  const scene::TextureRef& ref = scene.materials[mesh_named(scene, "textured:wood").material].albedo_texture;
  expect_map(ref, {2, 0, 0.5f, 0, -2, 1});
  const Vec2 st = ref.st(Vec2(0.25f, 0.25f));  // s = 2·0.25 + 0.5 = 1, t = 1 − 2·0.25 = 0.5
  EXPECT_NEAR(st.x, 1.0f, 1e-6f);
  EXPECT_NEAR(st.y, 0.5f, 1e-6f);

  // An option without its number is an error on the MTL's line, not a file named "-s".
  write("bad.mtl", "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd -s wood.png\n");
  const std::string bad =
      write("bad.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl wood\nf 1 2 3\n");
  EXPECT_CONTAINS(error_of([&] { load_scene_file(bad); }), "bad.mtl:3: map_Kd -s needs a number");
}

TEST_F(Loaders, ObjMissingTextureWarnsAndLeavesMaterialUntextured) {
  write("textured.mtl", "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd nothere.png\n");
  const std::string obj = write("textured.obj", kTexturedQuad);
  const scene::Scene scene = load_scene_file(obj);
  EXPECT_TRUE(scene.textures.empty());
  EXPECT_FALSE(scene.materials[mesh_named(scene, "textured:wood").material].is_textured());
  EXPECT_TRUE(has_warning(scene, "nothere.png"));
  const scene::Scene committed = load_scene(obj);  // and the scene still commits
  EXPECT_EQ(committed.triangle_count(), 4u);
}

// Materials naming the same file (once as a Windows-style path) share one image; the maps the
// loader cannot use are named once per file, in one warning. A textured material without Kd
// gets Kd 0.6, also after a material that had one.
TEST_F(Loaders, ObjMaterialsSharingATextureShareOneImage) {
  write("tex/stone.png", "not read before commit");
  write("tex/stone-bump.png", "not read before commit");
  write("shared.mtl",
        "newmtl wall\nKd 0.8 0.8 0.8\nmap_Kd tex/stone.png\nbump tex/stone-bump.png\n"
        "newmtl pillar\nmap_Kd tex\\stone.png\nmap_bump tex/stone-bump.png\nmap_Ks tex/stone.png\n");
  const std::string obj = write("shared.obj",
                                "mtllib shared.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                "usemtl wall\nf 1/1 2/2 3/3\nusemtl pillar\nf 1/1 3/3 2/2\n");
  const scene::Scene scene = load_scene_file(obj);
  // Two images: the stone (colour) and its bump map (data), each shared by both materials.
  ASSERT_EQ(scene.textures.size(), 2u);
  const scene::Material& wall = scene.materials[mesh_named(scene, "shared:wall").material];
  const scene::Material& pillar = scene.materials[mesh_named(scene, "shared:pillar").material];
  EXPECT_EQ(wall.albedo_texture.image, 0);
  EXPECT_EQ(pillar.albedo_texture.image, 0);
  EXPECT_EQ(wall.normal_texture.image, 1);
  EXPECT_EQ(pillar.normal_texture.image, 1);
  EXPECT_TRUE(pillar.normal_is_height);
  EXPECT_EQ(pillar.albedo, Rgb(0.6f));
  int ignored = 0;
  for (const std::string& w : scene.warnings)
    if (w.find("are ignored") != std::string::npos) {
      ++ignored;
      EXPECT_EQ(w.find("bump"), std::string::npos) << w;
      EXPECT_CONTAINS(w, "specular maps (map_Ks)");
      EXPECT_EQ(w.find("map_Kd"), std::string::npos) << w;
    }
  EXPECT_EQ(ignored, 1);
}

// A textured material keeps the uvs its faces have; corners without one read (0, 0).
TEST_F(Loaders, ObjTexturedMeshWithSomeCornersLackingUvs) {
  write("wood.png", "not read before commit");
  write("textured.mtl", "newmtl wood\nKd 0.5 0.5 0.5\nmap_Kd wood.png\n");
  const std::string obj = write("textured.obj",
                                "mtllib textured.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0.5 0.5\n"
                                "usemtl wood\nf 1/1 2/1 3/1\nf 2 4 3\n");
  const scene::Scene scene = load_scene_file(obj);
  const scene::TriangleMesh& mesh = mesh_named(scene, "textured:wood");
  ASSERT_EQ(mesh.uvs.size(), mesh.positions.size());
  EXPECT_EQ(mesh.positions.size(), 6u);  // (v, vt) and (v, none) are different vertices
  EXPECT_EQ(mesh.uvs[0], Vec2(0.5f, 0.5f));
  EXPECT_EQ(mesh.uvs[5], Vec2(0.0f, 0.0f));
  EXPECT_TRUE(has_warning(scene, "3 face corner(s) without texture coordinates"));
}

/// The surface point of mesh `geom_id` whose texture coordinates are `uv`.
scene::SurfaceInteraction point_at_uv(const scene::Scene& scene, uint32_t geom_id, Vec2 uv) {
  const scene::TriangleMesh& mesh = scene.meshes[geom_id];
  for (uint32_t t = 0; t < mesh.triangle_count(); ++t) {
    const Vec2 a = mesh.uvs[mesh.indices[3 * t]], b = mesh.uvs[mesh.indices[3 * t + 1]],
               c = mesh.uvs[mesh.indices[3 * t + 2]];
    // Solve uv = a + b1 (b − a) + b2 (c − a) by Cramer's rule.
    const Vec2 e1 = b - a, e2 = c - a, d = uv - a;
    const float det = e1.x * e2.y - e1.y * e2.x;
    if (det == 0.0f) continue;
    const float b1 = (d.x * e2.y - d.y * e2.x) / det, b2 = (e1.x * d.y - e1.y * d.x) / det;
    if (b1 >= 0.0f && b2 >= 0.0f && b1 + b2 <= 1.0f) return scene.triangle_point(geom_id, t, Vec2(b1, b2));
  }
  throw std::runtime_error("no triangle covers that uv");
}

// Kd × map_Kd at two points of a quad textured with a 2×1 image, red texel left, blue right.
// Saturated primaries survive the sRGB → linear conversion exactly (code 255 → 1, 0 → 0); the
// remaining error is the linear copy's half floats and the bilinear weights at a texel's centre,
// well inside 1e-3.
TEST_F(Loaders, ObjTextureAlbedoAtPoints) {
  util::Image image;
  image.width = 2;
  image.height = 1;
  image.pixels = {Rgb(1, 0, 0), Rgb(0, 0, 1)};
  util::write_image((dir_ / "redblue.png").string(), image);  // 8-bit sRGB
  write("quad.mtl", "newmtl painted\nKd 0.5 0.8 0.6\nmap_Kd redblue.png\n");
  const std::string obj = write("quad.obj",
                                "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl painted\nf 1/1 2/2 3/3 4/4\n");
  const scene::Scene scene = load_scene(obj);
  ASSERT_EQ(scene.meshes.size(), 1u);
  ASSERT_NE(scene.texture_set(), nullptr);
  const auto albedo_at = [&](Vec2 uv) {
    const scene::SurfaceInteraction si = point_at_uv(scene, 0, uv);
    EXPECT_NEAR(si.uv.x, uv.x, 1e-6f);
    EXPECT_NEAR(si.uv.y, uv.y, 1e-6f);
    scene::Material scratch;
    return scene.shading_material(si, scratch).albedo;
  };
  // u = 0.25 and 0.75 are the texel centres; v = 0.5 the middle of the one row.
  const Rgb left = albedo_at(Vec2(0.25f, 0.5f)), right = albedo_at(Vec2(0.75f, 0.5f));
  EXPECT_NEAR(left.r, 0.5f, 1e-3f);
  EXPECT_NEAR(left.g, 0.0f, 1e-3f);
  EXPECT_NEAR(left.b, 0.0f, 1e-3f);
  EXPECT_NEAR(right.r, 0.0f, 1e-3f);
  EXPECT_NEAR(right.g, 0.0f, 1e-3f);
  EXPECT_NEAR(right.b, 0.6f, 1e-3f);
}

TEST_F(Loaders, ObjFaceIndexOutOfRange) {
  const std::string obj = write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  const std::string message = error_of([&] { load_scene(obj); });
  EXPECT_CONTAINS(message, "bad_index.obj:4:");
  EXPECT_CONTAINS(message, "vertex 9 of 3");
  const std::string zero = write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(zero); }), "zero.obj:4:");
}

TEST_F(Loaders, ObjNonFiniteCoordinate) {
  const std::string nan = write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(nan); }), "nan.obj:2:");
  const std::string inf = write("inf.obj", "v 0 0 0\nv 1 0 0\nv 0 1e999 0\nf 1 2 3\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(inf); }), "inf.obj:3:");
}

TEST_F(Loaders, DegenerateTrianglesDroppedWithWarning) {
  const std::string obj = write("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
  const scene::Scene scene = load_scene(obj);
  EXPECT_EQ(scene.triangle_count(), 1u);
  EXPECT_TRUE(has_warning(scene, "1 degenerate"));
}

// ---------------------------------------------------------------- glTF

std::string base64(const std::vector<unsigned char>& bytes) {
  const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t n = (uint32_t(bytes[i]) << 16) | (i + 1 < bytes.size() ? uint32_t(bytes[i + 1]) << 8 : 0) |
                       (i + 2 < bytes.size() ? uint32_t(bytes[i + 2]) : 0);
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(n >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[n & 63] : '=';
  }
  return out;
}

/// A unit quad in the z = 0 plane (4 float positions, then 6 u16 indices): 60 bytes.
std::vector<unsigned char> quad_buffer(float first_x = 0.0f, uint16_t last_index = 3) {
  const float positions[12] = {first_x, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  const uint16_t indices[6] = {0, 1, 2, 0, 2, last_index};
  std::vector<unsigned char> bytes(sizeof positions + sizeof indices);
  std::memcpy(bytes.data(), positions, sizeof positions);
  std::memcpy(bytes.data() + sizeof positions, indices, sizeof indices);
  return bytes;
}

/// A glTF document around a 60-byte buffer given by `buffer` (the JSON of buffers[0]).
std::string gltf_json(const std::string& buffer, int position_type = 5126) {
  return R"({"asset": {"version": "2.0"}, "scene": 0,
  "extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission",
                     "KHR_materials_ior"],
  "scenes": [{"nodes": [0, 3, 4, 5, 6, 7]}],
  "nodes": [{"name": "root", "translation": [10, 0, 0], "children": [1, 2]},
            {"mesh": 0, "translation": [0, 1, 0]},
            {"mesh": 1, "scale": [2, 2, 2]},
            {"camera": 0, "translation": [0, 0, 5]},
            {"translation": [0, 3, 0], "extensions": {"KHR_lights_punctual": {"light": 0}}},
            {"extensions": {"KHR_lights_punctual": {"light": 1}}},
            {"rotation": [-0.70710678, 0, 0, 0.70710678], "extensions": {"KHR_lights_punctual": {"light": 2}}},
            {"name": "above", "camera": 1, "translation": [0, 4, 0], "rotation": [-0.70710678, 0, 0, 0.70710678]}],
  "meshes": [{"name": "lamp", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]},
             {"name": "pane", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 1}]}],
  "materials": [{"name": "lamp", "emissiveFactor": [1, 1, 1], "doubleSided": true,
                 "pbrMetallicRoughness": {"baseColorFactor": [0, 0, 0, 1]},
                 "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 5}}},
                {"name": "glass", "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                                                 "KHR_materials_ior": {"ior": 1.4}}},
                {"name": "chrome", "pbrMetallicRoughness": {"metallicFactor": 1, "roughnessFactor": 0}},
                {"name": "satin", "pbrMetallicRoughness": {"metallicFactor": 0, "roughnessFactor": 0.5}}],
  "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}},
              {"name": "plan", "type": "orthographic", "orthographic": {"xmag": 4, "ymag": 2, "znear": 0, "zfar": 9}}],
  "extensions": {"KHR_lights_punctual": {"lights": [
      {"type": "point", "color": [1, 0.5, 0.25], "intensity": 10},
      {"type": "spot", "intensity": 20, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
      {"type": "directional", "intensity": 3}]}},
  "buffers": [)" +
         buffer + R"(],
  "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 12}],
  "accessors": [{"bufferView": 0, "componentType": )" +
         std::to_string(position_type) + R"(, "count": 4, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}]})";
}

std::string embedded_buffer(const std::vector<unsigned char>& bytes) {
  return R"({"byteLength": )" + std::to_string(bytes.size()) +
         R"(, "uri": "data:application/octet-stream;base64,)" + base64(bytes) + "\"}";
}

void expect_gltf_contents(const scene::Scene& scene) {
  ASSERT_EQ(scene.meshes.size(), 2u);
  EXPECT_EQ(scene.meshes[0].positions[0], Vec3(10, 1, 0));  // root then child translation
  EXPECT_EQ(scene.meshes[1].positions[2], Vec3(12, 2, 0));  // scaled by 2, then moved by the root
  ASSERT_EQ(scene.materials.size(), 4u);
  const scene::Material& lamp = scene.materials[scene.meshes[0].material];
  EXPECT_EQ(lamp.emission, Rgb(5.0f));
  EXPECT_TRUE(lamp.two_sided_emission);
  const scene::Material& glass = scene.materials[scene.meshes[1].material];
  EXPECT_EQ(glass.kind, scene::MaterialKind::dielectric);
  EXPECT_FLOAT_EQ(glass.ior, 1.4f);
  EXPECT_EQ(scene.materials[2].kind, scene::MaterialKind::mirror);
  EXPECT_TRUE(glass.thin_walled);  // no KHR_materials_volume: a sheet
  // No pbrMetallicRoughness: glTF's default roughnessFactor of 1, which its transmission shares.
  EXPECT_FLOAT_EQ(glass.roughness, 1.0f);
  EXPECT_TRUE(glass.is_rough_dielectric());
  EXPECT_EQ(scene.materials[3].kind, scene::MaterialKind::metallic_roughness);
  EXPECT_EQ(scene.materials[3].metallic, 0.0f);
  EXPECT_EQ(scene.materials[3].roughness, 0.5f);

  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_EQ(scene.camera->look_from, Vec3(0, 0, 5));
  EXPECT_EQ(scene.camera->look_at, Vec3(0, 0, 4));
  EXPECT_NEAR(scene.camera->vfov_degrees, 0.8f * 180.0f / kPi, 1e-4f);
  EXPECT_EQ(scene.render.width, 768);

  ASSERT_EQ(scene.punctual_lights.size(), 3u);
  const scene::Light& point = scene.punctual_lights[0];
  EXPECT_EQ(point.kind, scene::LightKind::point);
  EXPECT_EQ(point.position, Vec3(0, 3, 0));
  EXPECT_EQ(point.intensity, Rgb(10.0f, 5.0f, 2.5f));
  const scene::Light& spot = scene.punctual_lights[1];
  EXPECT_EQ(spot.kind, scene::LightKind::spot);
  EXPECT_FLOAT_EQ(spot.cos_inner, std::cos(0.2f));
  EXPECT_FLOAT_EQ(spot.cos_outer, std::cos(0.5f));
  EXPECT_EQ(spot.direction, Vec3(0, 0, -1));
  const scene::Light& sun = scene.punctual_lights[2];
  EXPECT_EQ(sun.kind, scene::LightKind::directional);
  EXPECT_EQ(sun.irradiance, Rgb(3.0f));
  EXPECT_NEAR(sun.direction.y, -1.0f, 1e-6f);  // node −z turned by −90° about x
}

TEST_F(Loaders, GltfEmbeddedBuffer) {
  const std::string path = write("scene.gltf", gltf_json(embedded_buffer(quad_buffer())));
  expect_gltf_contents(load_scene_file(path));
  EXPECT_EQ(load_scene(path).lights().size(), 2u + 3u);  // two lamp triangles, three punctual lights
}

TEST_F(Loaders, JsonSceneKeepsItsGltfsCameraUnlessItHasOne) {
  // The glTF's camera (at (0, 0, 5), looking down −z, aspect 1.5) moved by the file's transform;
  // a second file's camera is ignored with a warning; a JSON camera wins over both.
  write("scene.gltf", gltf_json(embedded_buffer(quad_buffer())));
  const std::string wrapped =
      write("wrapped.json", R"({"meshes": [{"file": "scene.gltf", "transform": {"translate": [1, 2, 3]}},
                                          {"file": "scene.gltf"}]})");
  const scene::Scene scene = load_scene_file(wrapped);
  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_EQ(scene.camera->look_from, Vec3(1, 2, 8));
  EXPECT_EQ(scene.camera->look_at, Vec3(1, 2, 7));
  EXPECT_EQ(scene.camera->up, Vec3(0, 1, 0));
  EXPECT_NEAR(scene.camera->vfov_degrees, 0.8f * 180.0f / kPi, 1e-4f);
  EXPECT_EQ(scene.render.width, 768);
  EXPECT_TRUE(has_warning(scene, "an earlier file's is used"));
  const std::string own = write("own.json", R"({"meshes": [{"file": "scene.gltf"}],
      "camera": {"look_from": [0, 0, -3], "look_at": [0, 0, 0]}})");
  const scene::Scene with_own = load_scene_file(own);
  ASSERT_TRUE(with_own.camera.has_value());
  EXPECT_EQ(with_own.camera->look_from, Vec3(0, 0, -3));
  EXPECT_TRUE(has_warning(with_own, "the scene's own is used"));
}

TEST_F(Loaders, GltfCamerasAreAllKeptAndChosenByNumberOrName) {
  // Two cameras: the first (unnamed, on an unnamed node) frames the scene; the second is
  // orthographic, 2·ymag = 4 high with aspect xmag / ymag = 2, on a node 4 above the origin
  // turned to look straight down.
  const std::string path = write("scene.gltf", gltf_json(embedded_buffer(quad_buffer())));
  scene::Scene scene = load_scene_file(path);
  ASSERT_EQ(scene.cameras.size(), 2u);
  EXPECT_EQ(scene.cameras[0].name, "camera 0");
  EXPECT_EQ(scene.cameras[1].name, "plan");  // the camera's own name before its node's
  EXPECT_FALSE(scene.camera->orthographic);
  const scene::Camera& plan = scene.cameras[1].camera;
  EXPECT_TRUE(plan.orthographic);
  EXPECT_FLOAT_EQ(plan.ortho_height, 4.0f);
  EXPECT_FLOAT_EQ(scene.cameras[1].aspect, 2.0f);
  EXPECT_EQ(plan.look_from, Vec3(0, 4, 0));
  EXPECT_NEAR(plan.look_at.y, 3.0f, 1e-6f);
  // An orthographic camera's rays are parallel, from a film 4 × 8 centred on look_from.
  const scene::Ray left = plan.generate_ray(Vec2(0.0f, 0.5f), Vec2(0.5f), 2.0f);
  const scene::Ray right = plan.generate_ray(Vec2(1.0f, 0.5f), Vec2(0.5f), 2.0f);
  EXPECT_NEAR(glm::distance(left.direction, right.direction), 0.0f, 1e-6f);
  EXPECT_NEAR(glm::distance(left.origin, right.origin), 8.0f, 1e-5f);
  EXPECT_NEAR(left.direction.y, -1.0f, 1e-6f);
  EXPECT_EQ(plan.pixel_spread(100), 0.0f);

  select_camera(scene, "1");
  EXPECT_TRUE(scene.camera->orthographic);
  EXPECT_EQ(scene.render.width, 1024);  // the height's 512 times the aspect 2
  select_camera(scene, "camera 0");
  EXPECT_FALSE(scene.camera->orthographic);
  EXPECT_EQ(scene.render.width, 768);
  select_camera(scene, "plan");
  EXPECT_TRUE(scene.camera->orthographic);
  for (const std::string bad : {"2", "planned", "", "99999999999999999999"}) {
    try {
      select_camera(scene, bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("0 'camera 0', 1 'plan'"), std::string::npos) << e.what();
    }
  }
  // A JSON scene keeps every included file's cameras, moved with the file, after its own.
  const std::string own = write("own.json", R"({"meshes": [{"file": "scene.gltf", "transform": {"translate": [1, 2, 3]}}],
      "camera": {"name": "mine", "look_from": [0, 0, -3], "look_at": [0, 0, 0], "orthographic_height": 6}})");
  scene::Scene wrapped = load_scene_file(own);
  ASSERT_EQ(wrapped.cameras.size(), 3u);
  EXPECT_EQ(wrapped.cameras[0].name, "mine");
  EXPECT_TRUE(wrapped.camera->orthographic);
  EXPECT_FLOAT_EQ(wrapped.camera->ortho_height, 6.0f);
  EXPECT_EQ(wrapped.cameras[2].camera.look_from, Vec3(1, 6, 3));
  select_camera(wrapped, "plan");
  EXPECT_EQ(wrapped.camera->look_from, Vec3(1, 6, 3));
  const std::string bad_height = write("bad.json", R"({"meshes": [{"file": "scene.gltf"}],
      "camera": {"look_from": [0, 0, -3], "look_at": [0, 0, 0], "orthographic_height": 0}})");
  EXPECT_THROW(load_scene_file(bad_height), InputError);
}

TEST_F(Loaders, GlbBinaryContainer) {
  std::string json = gltf_json(R"({"byteLength": 60})");
  while (json.size() % 4 != 0) json += ' ';
  const std::vector<unsigned char> bin = quad_buffer();  // 60 bytes: already a multiple of 4
  const auto u32 = [](std::string& out, uint32_t v) {
    for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xff);
  };
  std::string glb;
  u32(glb, 0x46546C67);  // "glTF"
  u32(glb, 2);
  u32(glb, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
  u32(glb, uint32_t(json.size()));
  u32(glb, 0x4E4F534A);  // "JSON"
  glb += json;
  u32(glb, uint32_t(bin.size()));
  u32(glb, 0x004E4942);  // "BIN"
  glb.append(bin.begin(), bin.end());
  expect_gltf_contents(load_scene_file(write("scene.glb", glb)));
}

TEST_F(Loaders, GltfBadInput) {
  const std::string index = write("bad_index.gltf", gltf_json(embedded_buffer(quad_buffer(0.0f, 7))));
  std::string message = error_of([&] { load_scene(index); });
  EXPECT_CONTAINS(message, "bad_index.gltf");
  EXPECT_CONTAINS(message, "index 7");

  const std::string type = write("bad_type.gltf", gltf_json(embedded_buffer(quad_buffer()), 5123));
  message = error_of([&] { load_scene(type); });
  EXPECT_CONTAINS(message, "bad_type.gltf");
  EXPECT_CONTAINS(message, "expected float VEC3");

  const std::string nan = write("nan.gltf", gltf_json(embedded_buffer(quad_buffer(std::nanf("")))));
  EXPECT_CONTAINS(error_of([&] { load_scene(nan); }), "nan.gltf");

  const std::string junk = write("junk.gltf", "{ not json");
  EXPECT_CONTAINS(error_of([&] { load_scene(junk); }), "junk.gltf");
}

// ---------------------------------------------------------------- PLY

const char* kPlyHeader =
    "ply\nformat ascii 1.0\ncomment test\nelement vertex 5\nproperty float x\nproperty float y\n"
    "property float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
    "element face 2\nproperty list uchar int vertex_indices\nend_header\n";

TEST_F(Loaders, PlyAscii) {
  const std::string ply =
      write("mesh.ply", std::string(kPlyHeader) +
                            "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n0.5 2 0 0 0 1\n"
                            "4 0 1 2 3\n3 3 2 4\n");
  const scene::Scene scene = load_scene(ply);
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.triangle_count(), 3u);  // the quad fanned into two
  EXPECT_EQ(scene.meshes[0].normals.size(), 5u);
  EXPECT_EQ(scene.meshes[0].normals[4], Vec3(0, 0, 1));
  EXPECT_FLOAT_EQ(scene.materials[0].albedo.g, 0.8f);
  EXPECT_TRUE(has_warning(scene, "no lights"));
}

// A JSON scene that gives a PLY mesh its own material replaces the PLY's default one, so the
// PLY's note about that default ("diffuse albedo 0.8, no lights") would mislead there; without a
// material of its own the note stays.
TEST_F(Loaders, JsonMaterialReplacesThePlyNote) {
  write("mesh.ply", std::string(kPlyHeader) +
                        "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n0.5 2 0 0 0 1\n"
                        "4 0 1 2 3\n3 3 2 4\n");
  const std::string own = write("own.json", R"({"materials": {"marble": {"kind": "diffuse", "albedo": 0.6}},
    "meshes": [{"file": "mesh.ply", "material": "marble"}],
    "lights": [{"type": "environment", "radiance": 1}]})");
  const scene::Scene with_material = load_scene(own);
  EXPECT_FALSE(has_warning(with_material, "geometry only"));
  EXPECT_FLOAT_EQ(with_material.materials[with_material.meshes[0].material].albedo.g, 0.6f);
  const std::string plain = write("plain.json", R"({"meshes": [{"file": "mesh.ply"}],
    "lights": [{"type": "environment", "radiance": 1}]})");
  EXPECT_TRUE(has_warning(load_scene(plain), "geometry only"));
}

TEST_F(Loaders, PlyBadInput) {
  const std::string body = "0 0 0 0 0 1\n1 0 0 0 0 1\n1 1 0 0 0 1\n0 1 0 0 0 1\n";
  const std::string index = write("bad_index.ply", kPlyHeader + body + "0.5 2 0 0 0 1\n4 0 1 2 3\n3 3 2 9\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(index); }), "bad_index.ply:20:");
  const std::string nan = write("nan.ply", kPlyHeader + body + "nan 2 0 0 0 1\n4 0 1 2 3\n3 3 2 4\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(nan); }), "nan.ply:18:");
  const std::string truncated = write("short.ply", kPlyHeader + body);
  EXPECT_CONTAINS(error_of([&] { load_scene(truncated); }), "short.ply");
  const std::string junk = write("junk.ply", "hello\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(junk); }), "junk.ply:1:");

  // Binary: a face naming vertex 7 of 3.
  std::string binary =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int32_t face[3] = {0, 1, 7};
  binary.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  binary += char(3);
  binary.append(reinterpret_cast<const char*>(face), sizeof face);
  const std::string binary_path = write("bad_binary.ply", binary);
  EXPECT_CONTAINS(error_of([&] { load_scene(binary_path); }), "bad_binary.ply");
}

// Inputs found by fuzzing, each of which once made the reader run out of memory or time (OpenMesh's
// token-by-token header parse looped on a failed stream), or read values off by one.
TEST_F(Loaders, PlyHeadersThatOnceExhaustedTheReader) {
  const std::string vertices =
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  const std::string ascii_body = "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  // An obj_info line is skipped whole, whatever it holds: one triangle.
  const std::string info =
      write("info.ply", "ply\nformat ascii 1.0\nobj_info element vertex 99999999999\n" + vertices + ascii_body);
  EXPECT_EQ(load_scene(info).triangle_count(), 1u);
  // An element without properties holds nothing, however many items it declares.
  std::string binary = "ply\nformat binary_little_endian 1.0\n" + vertices;
  binary.insert(binary.find("end_header"), "element junk 1000000000000000000\n");
  const float xyz[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const int32_t face[3] = {0, 1, 2};
  binary.append(reinterpret_cast<const char*>(xyz), sizeof xyz);
  binary += char(3);
  binary.append(reinterpret_cast<const char*>(face), sizeof face);
  EXPECT_EQ(load_scene(write("empty_elements.ply", binary)).triangle_count(), 1u);
  // An element declared twice is refused: which count would hold?
  const std::string twice = write("twice.ply", "ply\nformat ascii 1.0\nelement vertex 1000000000\n" + vertices +
                                                   ascii_body);
  EXPECT_CONTAINS(error_of([&] { load_scene(twice); }), "twice.ply:4: element 'vertex' declared twice");
  // A count past 2^64 is malformed, not read as 0.
  std::string text = "ply\nformat ascii 1.0\n" + vertices + ascii_body;
  text.replace(text.find("face 1"), 6, "face 055555555555555555555555555555");
  const std::string huge = write("huge.ply", text);
  EXPECT_CONTAINS(error_of([&] { load_scene(huge); }), "huge.ply:7: malformed 'element' line");
  // A value too many on an ascii line would shift every later value: refused at its line.
  const std::string extra =
      write("extra.ply", "ply\nformat ascii 1.0\n" + vertices + "0 0 0 7\n1 0 0\n0 1 0\n3 0 1 2\n");
  EXPECT_CONTAINS(error_of([&] { load_scene(extra); }), "extra.ply:10: vertex 0: 4 values on the line, 3 declared");
}

// A face that names a vertex twice loses only its fan triangles without area.
TEST_F(Loaders, PlyFaceWithARepeatedVertexKeepsItsRealTriangles) {
  const std::string ply = write("repeat.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                                              "property float y\nproperty float z\nelement face 2\n"
                                              "property list uchar int vertex_indices\nend_header\n"
                                              "0 0 0\n1 0 0\n1 1 0\n0 1 0\n5 0 1 1 2 3\n3 0 0 1\n");
  const scene::Scene scene = load_scene(ply);
  EXPECT_EQ(scene.meshes[0].indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
  EXPECT_TRUE(has_warning(scene, "2 face(s) name a vertex twice"));
  EXPECT_TRUE(scene.meshes[0].normals.empty());  // the file has none
}

// ---------------------------------------------------------------- JSON

TEST_F(Loaders, JsonSceneWithRelativeMeshes) {
  write("meshes/tri.mtl", "newmtl red\nKd 0.7 0.1 0.1\n");
  write("meshes/tri.obj", "mtllib tri.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n");
  const std::string path = write("scene.json", R"({
    // comments are allowed
    "materials": {"white": {"albedo": 0.7}, "lamp": {"albedo": 0, "emission": [4, 4, 4]},
                  "glass": {"kind": "dielectric", "ior": 1.5, "roughness": 0.2}, "gloss": {"kind": "glossy", "specular": 0.2}},
    "meshes": [{"file": "meshes/tri.obj", "material": "white",
                "transform": {"scale": 2, "rotate_deg_axis": [90, 0, 0, 1], "translate": [1, 0, 0]}},
               {"file": "meshes/tri.obj", "transform": {"scale": [-1, 1, 1]}}],
    "shapes": [{"type": "sphere", "center": [0, 1, 0], "radius": 0.5, "material": "glass"},
               {"type": "quad", "vertices": [[0, 2, 0], [1, 2, 0], [1, 2, 1], [0, 2, 1]], "material": "lamp"}],
    "lights": [{"type": "point", "position": [0, 1, 2], "intensity": [1, 2, 3]},
               {"type": "spot", "position": [0, 3, 0], "direction": [0, -2, 0], "intensity": 5,
                "inner_angle_deg": 20, "outer_angle_deg": 30},
               {"type": "directional", "direction": [0, -1, 0], "irradiance": 2},
               {"type": "environment", "radiance": 0.1}],
    "camera": {"look_from": [0, 1, 5], "look_at": [0, 1, 0], "vfov": 45, "aperture_radius": 0.1},
    "render": {"width": 320, "height": 240, "spp": 16}
  })");
  const scene::Scene scene = load_scene_file(path);
  ASSERT_EQ(scene.materials.size(), 5u);  // four of its own, plus the OBJ's red for the second mesh
  ASSERT_EQ(scene.meshes.size(), 3u);
  const scene::TriangleMesh& turned = scene.meshes[0];
  EXPECT_EQ(scene.materials[turned.material].name, "white");
  EXPECT_NEAR(turned.positions[1].x, 1.0f, 1e-6f);  // (1,0,0) scaled, turned 90° about z, moved
  EXPECT_NEAR(turned.positions[1].y, 2.0f, 1e-6f);
  EXPECT_GT(triangle_normal(turned, 0).z, 0.0f);
  const scene::TriangleMesh& mirrored = scene.meshes[1];
  EXPECT_EQ(scene.materials[mirrored.material].name, "red");
  EXPECT_EQ(mirrored.positions[1], Vec3(-1, 0, 0));
  EXPECT_GT(triangle_normal(mirrored, 0).z, 0.0f);  // the winding follows the mirror: front stays +z
  EXPECT_LT(triangle_normal(mesh_named(scene, "shapes:lamp"), 0).y, 0.0f);  // faces down
  ASSERT_EQ(scene.spheres.size(), 1u);
  EXPECT_EQ(scene.materials[scene.spheres[0].material].kind, scene::MaterialKind::dielectric);
  EXPECT_FLOAT_EQ(scene.materials[scene.spheres[0].material].roughness, 0.2f);
  ASSERT_EQ(scene.punctual_lights.size(), 4u);
  EXPECT_EQ(scene.punctual_lights[1].direction, Vec3(0, -1, 0));
  EXPECT_FLOAT_EQ(scene.punctual_lights[1].cos_outer, std::cos(glm::radians(30.0f)));
  EXPECT_EQ(scene.punctual_lights[3].kind, scene::LightKind::environment);
  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_FLOAT_EQ(scene.camera->aperture_radius, 0.1f);
  EXPECT_EQ(scene.render.width, 320);
  EXPECT_EQ(scene.render.spp, 16);
  EXPECT_EQ(load_scene(path).lights().size(), 2u + 4u);
}

// An environment light from an image: its path relative to the JSON file, `scale` multiplying its
// texels, `rotate_deg` turning it, `radiance` a tint (default 1). Misused fields are errors.
TEST_F(Loaders, JsonEnvironmentImage) {
  util::Image sky;
  sky.width = 8, sky.height = 4;
  sky.pixels.assign(32, Rgb(0.25f, 0.5f, 1.0f));
  util::write_image(write("skies/sky.exr", ""), sky);
  const std::string path = write("env.json", R"({
    "lights": [{"type": "environment", "file": "skies/sky.exr", "scale": 2, "rotate_deg": 30}]})");
  const scene::Scene scene = load_scene_file(path);
  ASSERT_EQ(scene.punctual_lights.size(), 1u);
  const scene::Light& env = scene.punctual_lights[0];
  ASSERT_TRUE(env.map);
  EXPECT_EQ(env.radiance, Rgb(1.0f));
  EXPECT_EQ(env.map->rotate_degrees(), 30.0f);
  EXPECT_EQ(scene::environment_radiance(env, Vec3(0.0f, 1.0f, 0.0f)), Rgb(0.5f, 1.0f, 2.0f));
  EXPECT_CONTAINS(error_of([&] {
                    load_scene(write("a.json", R"({"lights": [{"type": "environment", "radiance": 1, "scale": 2}]})"));
                  }),
                  "a.json: /lights/0/scale: needs \"file\"");
  EXPECT_CONTAINS(error_of([&] {
                    load_scene(write("b.json", R"({"lights": [{"type": "environment", "file": "none.exr"}]})"));
                  }),
                  "b.json: /lights/0/file: no such file");
  EXPECT_CONTAINS(error_of([&] {
                    load_scene(write("c.json", R"({"lights": [{"type": "environment", "file": "skies/sky.exr", "scale": -1}]})"));
                  }),
                  "c.json: /lights/0/scale: must not be negative");
}

TEST_F(Loaders, JsonBadInputNamesTheField) {
  const std::string malformed =
      write("malformed.json", "{\n  \"materials\": {\n    \"a\": {\"albedo\": 0.5,,}\n  }\n}\n");
  std::string message = error_of([&] { load_scene(malformed); });
  EXPECT_CONTAINS(message, "malformed.json:3:");

  const std::string unknown = write("unknown.json", R"({"materials": {"white": {}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "nope"}]})");
  message = error_of([&] { load_scene(unknown); });
  EXPECT_CONTAINS(message, "unknown.json: /shapes/0/material: unknown material 'nope'");

  const std::string type =
      write("type.json", R"({"materials": {"glass": {"kind": "dielectric", "ior": "x"}}})");
  EXPECT_CONTAINS(error_of([&] { load_scene(type); }), "type.json: /materials/glass/ior: expected a number");
  const std::string rough =
      write("rough.json", R"({"materials": {"glass": {"kind": "dielectric", "roughness": 1.5}}})");
  EXPECT_CONTAINS(error_of([&] { load_scene(rough); }), "rough.json: /materials/glass/roughness: must lie in [0, 1]");

  const std::string missing = write("missing.json", R"({"meshes": [{"file": "nowhere.obj"}]})");
  EXPECT_CONTAINS(error_of([&] { load_scene(missing); }), "missing.json: /meshes/0/file: no such file");

  write("broken.obj", "v 0 0 0\nf 1 2 3\n");
  const std::string nested = write("nested.json", R"({"meshes": [{"file": "broken.obj"}]})");
  message = error_of([&] { load_scene(nested); });
  EXPECT_CONTAINS(message, "nested.json: /meshes/0/file:");
  EXPECT_CONTAINS(message, "broken.obj:2:");

  const std::string bright = write("bright.json", R"({"materials": {"w": {"albedo": [0.5, 1.5, 0.5]}}})");
  EXPECT_CONTAINS(error_of([&] { load_scene(bright); }), "bright.json: /materials/w/albedo:");
}

// ---------------------------------------------------------------- dispatch

TEST_F(Loaders, MissingFileAndUnknownExtension) {
  const std::string nowhere = (dir_ / "nowhere.obj").string();
  EXPECT_CONTAINS(error_of([&] { load_scene(nowhere); }), "nowhere.obj: no such file");
  const std::string odd = write("scene.xyz", "whatever");
  std::string message = error_of([&] { load_scene(odd); });
  EXPECT_CONTAINS(message, "scene.xyz");
  EXPECT_CONTAINS(message, "'.xyz'");
  EXPECT_CONTAINS(error_of([&] { builtin_scene("cornel"); }), "cornel");
}

// ---------------------------------------------------------------- built-in scenes

TEST(BuiltinScenes, AllLoadAndCommit) {
  ASSERT_EQ(builtin_scene_names().size(), 4u);
  for (const std::string& name : builtin_scene_names()) {
    EXPECT_TRUE(is_builtin_scene(name));
    const scene::Scene scene = load_scene(name);
    EXPECT_TRUE(scene.committed()) << name;
    EXPECT_TRUE(scene.camera.has_value()) << name;
  }
  EXPECT_FALSE(is_builtin_scene("cornell.obj"));
}

TEST(BuiltinScenes, CornellBox) {
  const scene::Scene scene = load_scene("cornell");
  EXPECT_EQ(scene.meshes.size(), 8u);
  EXPECT_EQ(scene.triangle_count(), 38u);
  EXPECT_EQ(scene.materials.size(), 4u);
  EXPECT_EQ(scene.lights().size(), 2u);  // the light quad's two triangles
  EXPECT_EQ(scene.render.width, 512);
  EXPECT_FLOAT_EQ(scene.camera->vfov_degrees, 39.3f);
  EXPECT_EQ(scene.camera->look_from, Vec3(278, 273, -800));

  const Vec3 inside(278.0f, 274.4f, 279.6f);
  for (const char* wall : {"floor", "ceiling", "back_wall", "left_wall", "right_wall"}) {
    const scene::TriangleMesh& mesh = mesh_named(scene, wall);
    for (size_t t = 0; t < mesh.triangle_count(); ++t)
      EXPECT_GT(glm::dot(triangle_normal(mesh, t), inside - mesh.positions[mesh.indices[3 * t]]), 0.0f)
          << wall;
  }
  for (const char* block : {"short_block", "tall_block"}) {
    const scene::TriangleMesh& mesh = mesh_named(scene, block);
    EXPECT_EQ(mesh.triangle_count(), 10u);
    Vec3 center(0.0f);
    for (const Vec3& p : mesh.positions) center += p / float(mesh.positions.size());
    for (size_t t = 0; t < mesh.triangle_count(); ++t)
      EXPECT_GT(glm::dot(triangle_normal(mesh, t), mesh.positions[mesh.indices[3 * t]] - center), 0.0f)
          << block;
  }
  // The light fills a hole in the ceiling: both at y = 548.8, areas adding up to the full ceiling.
  const scene::TriangleMesh& light = mesh_named(scene, "light");
  const scene::TriangleMesh& ceiling = mesh_named(scene, "ceiling");
  float light_area = 0.0f, ceiling_area = 0.0f;
  for (size_t t = 0; t < light.triangle_count(); ++t) {
    EXPECT_LT(triangle_normal(light, t).y, 0.0f);  // emits downwards
    light_area += 0.5f * glm::length(triangle_normal(light, t));
  }
  for (size_t t = 0; t < ceiling.triangle_count(); ++t)
    ceiling_area += 0.5f * glm::length(triangle_normal(ceiling, t));
  for (const Vec3& p : light.positions) EXPECT_EQ(p.y, 548.8f);
  EXPECT_NEAR(light_area, 130.0f * 105.0f, 0.5f);
  EXPECT_NEAR(ceiling_area + light_area, 556.0f * 559.2f, 2.0f);
  EXPECT_EQ(scene.materials[light.material].emission, Rgb(17, 12, 4));
}

TEST(BuiltinScenes, CausticsFurnaceSmallpt) {
  const scene::Scene caustics = load_scene("cornell-caustics");
  EXPECT_EQ(caustics.meshes.size(), 6u);
  EXPECT_EQ(caustics.triangle_count(), 18u);
  ASSERT_EQ(caustics.spheres.size(), 2u);
  for (const scene::Sphere& s : caustics.spheres)
    EXPECT_FLOAT_EQ(s.center.y, s.radius);  // resting on the floor
  EXPECT_EQ(caustics.materials[caustics.spheres[1].material].kind, scene::MaterialKind::dielectric);
  EXPECT_EQ(caustics.materials[caustics.spheres[0].material].kind, scene::MaterialKind::mirror);

  const scene::Scene furnace = load_scene("furnace");
  EXPECT_EQ(furnace.triangle_count(), 12u);
  EXPECT_EQ(furnace.lights().size(), 12u);
  const scene::Material& wall = furnace.materials[0];
  EXPECT_EQ(wall.emission, Rgb(0.5f));
  EXPECT_EQ(wall.albedo, Rgb(0.8f));  // every pixel: 0.5 / (1 − 0.8) = 2.5
  const scene::TriangleMesh& box = furnace.meshes[0];
  for (size_t t = 0; t < box.triangle_count(); ++t)
    EXPECT_LT(glm::dot(triangle_normal(box, t), box.positions[box.indices[3 * t]]), 0.0f);  // faces inwards
  EXPECT_EQ(furnace_scene(1.0f, 0.5f).materials[0].emission, Rgb(1.0f));
  EXPECT_CONTAINS(error_of([] { furnace_scene(1.0f, 1.0f); }), "furnace");

  const scene::Scene smallpt = load_scene("smallpt");
  EXPECT_EQ(smallpt.spheres.size(), 8u);  // smallpt's nine less the black front wall
  EXPECT_EQ(smallpt.meshes.size(), 0u);
  EXPECT_EQ(smallpt.lights().size(), 1u);
  EXPECT_EQ(smallpt.render.width, 1024);
  EXPECT_EQ(smallpt.render.height, 768);
  EXPECT_NEAR(smallpt.camera->vfov_degrees, 28.80f, 0.01f);  // 2·atan(0.5135 / 2)
}

TEST(BuiltinScenes, TransformScene) {
  scene::Scene cornell = builtin_scene("cornell");
  const Vec3 offset(1000.0f, -20.0f, 3.0f);
  const Vec3 p = cornell.meshes[0].positions[0];
  transform_scene(cornell, 2.0f, offset);
  EXPECT_EQ(cornell.meshes[0].positions[0], 2.0f * p + offset);
  EXPECT_EQ(cornell.camera->look_from, 2.0f * Vec3(278, 273, -800) + offset);

  scene::Scene caustics = builtin_scene("cornell-caustics");
  scene::Material& glass = caustics.materials[caustics.spheres[1].material];
  glass.absorption = Rgb(0.5f);
  caustics.punctual_lights.push_back(
      scene::Light{.kind = scene::LightKind::point, .position = Vec3(1.0f), .intensity = Rgb(1.0f)});
  transform_scene(caustics, 4.0f, offset);
  EXPECT_EQ(caustics.spheres[0].radius, 400.0f);
  EXPECT_EQ(caustics.spheres[0].center, 4.0f * Vec3(400, 100, 370) + offset);
  EXPECT_EQ(glass.absorption, Rgb(0.125f));
  EXPECT_EQ(caustics.punctual_lights[0].position, Vec3(4.0f) + offset);
  EXPECT_EQ(caustics.punctual_lights[0].intensity, Rgb(16.0f));  // same irradiance at 4× the distance
  caustics.commit();
  EXPECT_CONTAINS(error_of([&] {
                    scene::Scene s = builtin_scene("furnace");
                    transform_scene(s, 0.0f, offset);
                  }),
                  "scale");
}

}  // namespace
}  // namespace gilt::raytrace_core::io
