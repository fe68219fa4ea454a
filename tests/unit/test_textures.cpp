// Image textures: sRGB decoding before filtering, lookups through Scene::shading_material, and
// the radiosity elements' mean reflectance. Images are written as binary PPM files (which
// OpenImageIO reads) into a fresh temporary folder, which is also the texture cache.
//
// Tolerances: the linear copies are half floats (11-bit significand, relative error ≤ 2⁻¹¹ ≈
// 5e-4), so a texel of 1.0 or 0.0 reads back within 1e-3 once filtering weights are summed.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "radiosity/mesh/element_albedo.h"
#include "radiosity/mesh/mesh.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"
#include "raytrace_core/scene/light.h"
#include "raytrace_core/scene/normal_map.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/scene/scene.h"
#include "raytrace_core/scene/texture.h"

namespace gilt {
namespace {

namespace fs = std::filesystem;
namespace rc = raytrace_core;

class Textures : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("gilt_textures_" + std::to_string(::getpid()) + "_" + info->name());
    fs::create_directories(dir_);
    ::setenv("GILT_TEXTURE_CACHE", (dir_ / "cache").c_str(), 1);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// Writes an 8-bit RGB image, rows top to bottom, as a binary PPM; returns its path.
  std::string ppm(const std::string& name, int width, int height, const std::vector<unsigned char>& rgb) {
    const fs::path path = dir_ / name;
    std::ofstream out(path, std::ios::binary);
    out << "P6\n" << width << ' ' << height << "\n255\n";
    out.write(reinterpret_cast<const char*>(rgb.data()), std::streamsize(rgb.size()));
    return path.string();
  }
  fs::path dir_;
};

constexpr float kHalfTolerance = 1e-3f;

/// A unit quad in the z = 0 plane facing +z, UVs (x, y), with `material`.
rc::scene::TriangleMesh quad(uint32_t material) {
  rc::scene::TriangleMesh m;
  m.name = "quad";
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  m.material = material;
  return m;
}

/// The unit quad of quad() with one diffuse material of albedo `albedo` × `image`, committed.
rc::scene::Scene textured_quad(const rc::scene::TextureImage& image, rc::Rgb albedo) {
  rc::scene::Scene scene;
  rc::scene::Material m = rc::scene::Material::make_diffuse("textured", albedo);
  scene.textures.push_back(image);
  m.albedo_texture.image = 0;
  scene.materials.push_back(m);
  scene.meshes.push_back(quad(0));
  scene.commit();
  return scene;
}

TEST_F(Textures, DecodesSrgbBeforeReading) {
  // Texels red, blue and the sRGB code 188, read at their centres (bilinear is exact there).
  const std::string file = ppm("rb.ppm", 3, 1, {255, 0, 0, 0, 0, 255, 188, 188, 188});
  rc::scene::TextureSet set(
      {rc::scene::TextureImage{file, true, rc::scene::TextureWrap::clamp, rc::scene::TextureWrap::clamp}});
  const rc::scene::Texel red = set.lookup(0, {1.0f / 6.0f, 0.5f});
  const rc::scene::Texel blue = set.lookup(0, {0.5f, 0.5f});
  const rc::scene::Texel grey = set.lookup(0, {5.0f / 6.0f, 0.5f});
  EXPECT_NEAR(red.rgb.r, 1.0f, kHalfTolerance);
  EXPECT_NEAR(red.rgb.b, 0.0f, kHalfTolerance);
  EXPECT_NEAR(blue.rgb.b, 1.0f, kHalfTolerance);
  EXPECT_NEAR(blue.rgb.r, 0.0f, kHalfTolerance);
  // sRGB's curve at 188/255: ((0.73725 + 0.055) / 1.055)^2.4 = 0.50289.
  EXPECT_NEAR(grey.rgb.g, 0.50289f, kHalfTolerance);
  // The same file read as data is not decoded: 188/255 = 0.7373.
  rc::scene::TextureSet data(
      {rc::scene::TextureImage{file, false, rc::scene::TextureWrap::clamp, rc::scene::TextureWrap::clamp}});
  EXPECT_NEAR(data.lookup(0, {5.0f / 6.0f, 0.5f}).rgb.g, 188.0f / 255.0f, kHalfTolerance);
}

TEST_F(Textures, FiltersLinearValuesNotCodes) {
  // A 4 × 4 checker of black and white: its mean is 0.5 in linear light. Averaging the codes
  // (127.5) and decoding after would give 0.212.
  std::vector<unsigned char> texels;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 3; ++c) texels.push_back((x + y) % 2 ? 255 : 0);
  rc::scene::TextureSet set({rc::scene::TextureImage{ppm("checker.ppm", 4, 4, texels)}});
  // A footprint as large as the image reads its coarsest level, the mean.
  const rc::scene::Texel whole = set.lookup(0, {0.5f, 0.5f}, {1.0f, 0.0f}, {0.0f, 1.0f});
  EXPECT_NEAR(whole.rgb.g, 0.5f, kHalfTolerance);
  // The stratified mean over a triangle covering half the image: each half of a 4 × 4 checker
  // split along the diagonal is black and white in equal parts but for the diagonal's own
  // texels; 64 strata filtered over their shares give the mean within a few per cent.
  const rc::scene::Texel half = set.triangle_mean(0, {0, 0}, {1, 0}, {1, 1});
  EXPECT_NEAR(half.rgb.g, 0.5f, 0.05f);
}

TEST_F(Textures, ShadingMaterialMultipliesTheAlbedoByTheTexel) {
  rc::scene::Scene scene;
  rc::scene::Material m = rc::scene::Material::make_diffuse("textured", rc::Rgb(0.8f, 0.6f, 0.4f));
  scene.textures.push_back(rc::scene::TextureImage{ppm("rb.ppm", 2, 1, {255, 0, 0, 0, 0, 255})});
  m.albedo_texture.image = 0;
  scene.materials.push_back(m);
  scene.meshes.push_back(quad(0));
  scene.commit();
  ASSERT_NE(scene.texture_set(), nullptr);
  rc::scene::Material scratch;
  // (u, v) = (0.25, 0.5) is in the red texel, (0.75, 0.5) in the blue one.
  rc::scene::SurfaceInteraction at_left = scene.triangle_point(0, 0, {0.25f, 0.25f});
  at_left.uv = {0.25f, 0.5f};
  const rc::scene::Material& red = scene.shading_material(at_left, scratch);
  EXPECT_NEAR(red.albedo.r, 0.8f, 0.8f * kHalfTolerance);
  EXPECT_NEAR(red.albedo.g, 0.0f, kHalfTolerance);
  EXPECT_NEAR(red.albedo.b, 0.0f, kHalfTolerance);
  rc::scene::SurfaceInteraction at_right = at_left;
  at_right.uv = {0.75f, 0.5f};
  const rc::scene::Material& blue = scene.shading_material(at_right, scratch);
  EXPECT_NEAR(blue.albedo.b, 0.4f, 0.4f * kHalfTolerance);
  EXPECT_NEAR(blue.albedo.r, 0.0f, kHalfTolerance);
  // The surface point's own UVs come from the mesh: barycentrics (0.5, 0.25) of triangle 0
  // (corners (0,0), (1,0), (1,1)) are uv (0.75, 0.25), in the blue half.
  const rc::scene::SurfaceInteraction hit = scene.triangle_point(0, 0, {0.5f, 0.25f});
  EXPECT_NEAR(hit.uv.x, 0.75f, 1e-6f);
  EXPECT_NEAR(scene.shading_material(hit, scratch).albedo.b, 0.4f, 0.4f * kHalfTolerance);
  // An untextured material is returned as it is, not copied.
  rc::scene::Scene plain;
  plain.materials.push_back(rc::scene::Material::make_diffuse("plain", rc::Rgb(0.5f)));
  plain.meshes.push_back(quad(0));
  plain.commit();
  EXPECT_EQ(&plain.shading_material(plain.triangle_point(0, 0, {0.2f, 0.2f}), scratch), &plain.materials[0]);
}

TEST_F(Textures, MetallicRoughnessTextureScalesTheFactors) {
  // glTF's channels: roughness in green, metalness in blue (read as data, not decoded).
  rc::scene::Scene scene;
  rc::scene::Material m = rc::scene::Material::make_metallic_roughness("mr", rc::Rgb(0.5f), 0.8f, 0.6f);
  scene.textures.push_back(rc::scene::TextureImage{ppm("mr.ppm", 1, 1, {0, 128, 255}), false});
  m.metallic_roughness_texture.image = 0;
  scene.materials.push_back(m);
  scene.meshes.push_back(quad(0));
  scene.commit();
  rc::scene::Material scratch;
  const rc::scene::Material& at = scene.shading_material(scene.triangle_point(0, 0, {0.3f, 0.3f}), scratch);
  EXPECT_EQ(at.kind, rc::scene::MaterialKind::metallic_roughness);
  EXPECT_NEAR(at.roughness, 0.6f * 128.0f / 255.0f, kHalfTolerance);
  EXPECT_NEAR(at.metallic, 0.8f, kHalfTolerance);
  EXPECT_EQ(at.albedo, rc::Rgb(0.5f));
}

TEST_F(Textures, EmissionTextureSetsRadianceAndLightPower) {
  // A lamp quad whose emission texture is two texels, white and black, clamped at the edges:
  // bilinear filtering makes it 1 for s ≤ 1/4, a ramp down to 0 at s = 3/4, then 0, whose mean
  // over the quad is 1/2. What a camera sees, what light sampling returns and the light's power
  // all follow the texture.
  rc::scene::Scene scene;
  rc::scene::Material lamp = rc::scene::Material::make_emitter("lamp", rc::Rgb(2.0f));
  scene.textures.push_back(
      rc::scene::TextureImage{ppm("half.ppm", 2, 1, {255, 255, 255, 0, 0, 0}), true, rc::scene::TextureWrap::clamp, rc::scene::TextureWrap::clamp});
  lamp.emission_texture.image = 0;
  scene.materials.push_back(lamp);
  scene.meshes.push_back(quad(0));
  scene.commit();
  rc::scene::Material scratch;
  rc::scene::SurfaceInteraction left = scene.triangle_point(0, 0, {0.1f, 0.05f});
  left.uv = {0.2f, 0.5f};
  rc::scene::SurfaceInteraction right = left;
  right.uv = {0.8f, 0.5f};
  EXPECT_NEAR(scene.shading_material(left, scratch).emission.g, 2.0f, 2.0f * kHalfTolerance);
  EXPECT_NEAR(scene.shading_material(right, scratch).emission.g, 0.0f, kHalfTolerance);
  // Light power: Le π A over the two triangles at their texture means, 2 π · 1 · 1/2 in all
  // (the triangles split it 0.27 : 0.73; each mean is a 64-stratum estimate of a piecewise
  // linear function, within 1 %).
  double total = 0.0;
  for (const rc::scene::Light& light : scene.lights()) total += rc::scene::light_power(scene, light).g;
  EXPECT_NEAR(total, 2.0 * rc::kPi * 0.5, 0.01 * 2.0 * rc::kPi * 0.5);
  // Light samples carry the radiance where they land: uniform points on the quad (both
  // triangles alike, equal areas) average Le · 1/2 = 1. Values lie in [0, 2], so the standard
  // error of 4000 samples is at most 1/√4000 = 0.016; 4 of them is 0.064.
  rc::scene::SurfacePoint ref;
  ref.p = rc::Vec3(0.5f, 0.5f, 1.0f);
  ref.ng = rc::Vec3(0.0f, 0.0f, -1.0f);
  rc::util::Rng rng(3);
  double sum = 0.0;
  constexpr int kSamples = 4000;
  for (int k = 0; k < kSamples; ++k) {
    const rc::scene::Light& light = scene.lights()[size_t(k) % scene.lights().size()];
    sum += rc::scene::sample_light(scene, light, ref, rng.uniform2()).radiance.g;
  }
  EXPECT_NEAR(sum / kSamples, 1.0, 0.064);
}

TEST_F(Textures, MaskCutsOutWhereAlphaIsBelowTheCutoff) {
  // A grey (one-channel) coverage image: the left texel 0, the right one 255. Read as data, its
  // first channel is the coverage. Rays down onto the quad's left half pass through; on the
  // right they stop, for closest hits and shadow rays alike.
  const fs::path file = dir_ / "mask.pgm";
  {
    std::ofstream out(file, std::ios::binary);
    out << "P5\n2 1\n255\n";
    out.put(char(0)).put(char(255));
  }
  rc::scene::Scene scene;
  rc::scene::Material m = rc::scene::Material::make_diffuse("leaf", rc::Rgb(0.5f));
  scene.textures.push_back(rc::scene::TextureImage{file.string(), false, rc::scene::TextureWrap::clamp, rc::scene::TextureWrap::clamp});
  m.alpha_mode = rc::scene::AlphaMode::mask;
  m.alpha_texture.image = 0;
  m.alpha_in_colour = true;
  scene.materials.push_back(m);
  scene.meshes.push_back(quad(0));
  scene.commit();
  for (float x : {0.05f, 0.2f, 0.4f}) {
    const rc::scene::Ray ray{{x, 0.5f, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f};
    EXPECT_FALSE(scene.intersect(ray).has_value()) << x;
    EXPECT_FALSE(scene.occluded(ray)) << x;
  }
  for (float x : {0.6f, 0.8f, 0.95f}) {
    const rc::scene::Ray ray{{x, 0.5f, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f};
    EXPECT_TRUE(scene.intersect(ray).has_value()) << x;
    EXPECT_TRUE(scene.occluded(ray)) << x;
  }
}

TEST_F(Textures, ObjMapDIsACutout) {
  // The same mask as above through an OBJ's map_d: OBJ's v runs up, and the mask's two texels
  // lie side by side, so the left half of the quad is cut away.
  {
    std::ofstream out(dir_ / "mask.pgm", std::ios::binary);
    out << "P5\n2 1\n255\n";
    out.put(char(0)).put(char(255));
  }
  std::ofstream(dir_ / "leaf.mtl") << "newmtl leaf\nKd 0.5 0.5 0.5\nmap_d mask.pgm\n";
  std::ofstream(dir_ / "leaf.obj") << "mtllib leaf.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                      "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl leaf\nf 1/1 2/2 3/3 4/4\n";
  rc::scene::Scene scene = rc::io::load_scene((dir_ / "leaf.obj").string());
  ASSERT_EQ(scene.materials.size(), 1u);
  EXPECT_EQ(scene.materials[0].alpha_mode, rc::scene::AlphaMode::mask);
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_FALSE(scene.textures[0].srgb);
  EXPECT_FALSE(scene.occluded(rc::scene::Ray{{0.25f, 0.5f, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f}));
  EXPECT_TRUE(scene.occluded(rc::scene::Ray{{0.75f, 0.5f, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f}));
}

TEST_F(Textures, ObjPbrFieldsAndMapKe) {
  // MTL's PBR extension: Pr and Pm make the metallic-roughness model with base colour Kd;
  // map_Ke scales Ke as a colour (sRGB) image; a material without them stays as it was.
  {
    std::ofstream out(dir_ / "glow.pgm", std::ios::binary);
    out << "P5\n1 1\n255\n";
    out.put(char(255));
  }
  std::ofstream(dir_ / "pbr.mtl") << "newmtl brass\nKd 0.8 0.6 0.2\nPr 0.4\nPm 1\n"
                                     "newmtl panel\nKd 0.1 0.1 0.1\nKe 3 2 1\nmap_Ke glow.pgm\n"
                                     "newmtl plain\nKd 0.5 0.5 0.5\nmap_Ke glow.pgm\n";
  std::ofstream(dir_ / "pbr.obj") << "mtllib pbr.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                                     "usemtl brass\nf 1/1 2/2 3/3\nusemtl panel\nf 1/1 2/2 3/3\n"
                                     "usemtl plain\nf 1/1 2/2 3/3\n";
  rc::scene::Scene scene = rc::io::load_scene((dir_ / "pbr.obj").string());
  ASSERT_EQ(scene.materials.size(), 3u);
  const rc::scene::Material& brass = scene.materials[0];
  EXPECT_EQ(brass.kind, rc::scene::MaterialKind::metallic_roughness);
  EXPECT_FLOAT_EQ(brass.roughness, 0.4f);
  EXPECT_FLOAT_EQ(brass.metallic, 1.0f);
  EXPECT_EQ(brass.albedo, rc::Rgb(0.8f, 0.6f, 0.2f));
  const rc::scene::Material& panel = scene.materials[1];
  EXPECT_EQ(panel.kind, rc::scene::MaterialKind::diffuse);
  ASSERT_TRUE(panel.emission_texture.valid());
  EXPECT_TRUE(scene.textures[size_t(panel.emission_texture.image)].srgb);
  // A black Ke leaves map_Ke unused, and says so.
  EXPECT_FALSE(scene.materials[2].emission_texture.valid());
  EXPECT_TRUE(std::any_of(scene.warnings.begin(), scene.warnings.end(),
                          [](const std::string& w) { return w.find("Ke is black") != std::string::npos; }));
}

TEST_F(Textures, JsonSceneKeepsEachFilesImages) {
  // Two OBJ files in one JSON scene, the second's material reading its own emission, normal and
  // albedo images: every one of its references moves past the first file's images.
  for (const char* name : {"red.pgm", "glow.pgm", "bumps.pgm"}) {
    std::ofstream out(dir_ / name, std::ios::binary);
    out << "P5\n1 1\n255\n";
    out.put(char(200));
  }
  const char* quad_obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n";
  std::ofstream(dir_ / "a.mtl") << "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd red.pgm\n";
  std::ofstream(dir_ / "a.obj") << "mtllib a.mtl\n" << quad_obj << "usemtl a\nf 1/1 2/2 3/3\n";
  std::ofstream(dir_ / "b.mtl") << "newmtl b\nKd 0.5 0.5 0.5\nKe 1 1 1\nmap_Ke glow.pgm\nbump bumps.pgm\nmap_Kd red.pgm\n";
  std::ofstream(dir_ / "b.obj") << "mtllib b.mtl\n" << quad_obj << "usemtl b\nf 1/1 2/2 3/3\n";
  std::ofstream(dir_ / "ab.json") << R"({"meshes": [{"file": "a.obj"}, {"file": "b.obj"}]})";
  const rc::scene::Scene scene = rc::io::load_scene((dir_ / "ab.json").string());
  ASSERT_EQ(scene.materials.size(), 2u);
  const auto file_of = [&](const rc::scene::TextureRef& t) {
    return t.valid() ? fs::path(scene.textures[size_t(t.image)].file).filename().string() : std::string("none");
  };
  EXPECT_EQ(file_of(scene.materials[0].albedo_texture), "red.pgm");
  EXPECT_EQ(file_of(scene.materials[1].albedo_texture), "red.pgm");
  EXPECT_EQ(file_of(scene.materials[1].emission_texture), "glow.pgm");
  EXPECT_EQ(file_of(scene.materials[1].normal_texture), "bumps.pgm");
}

TEST_F(Textures, CameraRaysFilterOverTheirPixelsFootprint) {
  // A 64 × 64 black-and-white checker (data, one texel per square) on the unit quad, seen
  // head-on from distance 2 by a ray whose pixel spans 1/8 of the quad there (16 texels): the
  // lookup reads MIP levels where every texel averages whole periods of the checker, which is
  // 0.5, stored (an 8-bit image's levels are 8-bit too) as the code 128, within 1/255 of it. A
  // ray without a cone (spread 0) reads the finest level: at a texel's centre, exactly 0 or 1.
  // Tilted to 60°, the footprint stretches along the tilt, and the reading is the same.
  std::vector<unsigned char> texels;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) texels.insert(texels.end(), 3, (x + y) % 2 ? (unsigned char)255 : (unsigned char)0);
  const rc::scene::Scene scene = textured_quad(
      rc::scene::TextureImage{ppm("checker.ppm", 64, 64, texels), false, rc::scene::TextureWrap::repeat, rc::scene::TextureWrap::repeat},
      rc::Rgb(1.0f));
  const auto albedo = [&](const rc::scene::Ray& ray) {
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    EXPECT_TRUE(hit.has_value());
    rc::scene::Material scratch;
    return hit ? scene.shading_material(scene.surface(ray, *hit), scratch).albedo.r : -1.0f;
  };
  constexpr float kMipCode = 1.0f / 255.0f;
  const rc::Vec3 texel_centre((20 + 0.5f) / 64.0f, (31 + 0.5f) / 64.0f, 0.0f);
  rc::scene::Ray ray{texel_centre + rc::Vec3(0, 0, 2), {0.0f, 0.0f, -1.0f}, 4.0f};
  const float sharp = albedo(ray);
  EXPECT_TRUE(std::fabs(sharp) < 1e-4f || std::fabs(sharp - 1.0f) < 1e-4f) << sharp;
  ray.spread = 0.125f / 2.0f;
  EXPECT_NEAR(albedo(ray), 0.5f, kMipCode);
  const rc::Vec3 tilted = glm::normalize(rc::Vec3(0.0f, std::sin(1.047f), -std::cos(1.047f)));
  ray = rc::scene::Ray{texel_centre - 2.0f * tilted, tilted, 4.0f};
  ray.spread = 0.125f / 2.0f;
  EXPECT_NEAR(albedo(ray), 0.5f, kMipCode);
}

TEST_F(Textures, ContinuedRaysCarryThePixelsConeAlongThePath) {
  // The checker of the test above. A camera ray of spread 1/64 hits the quad head-on at distance
  // 1 (width 1/64: one texel), and the path goes on: a ray continued from that hit is 1/64 wide
  // at its origin and widens by 1/64 per unit. Hitting the quad again after 7 units (a mirror
  // elsewhere, say), its cone is 1/64 + 7/64 = 1/8 wide: 8 texels, so the lookup reads levels
  // whose texels average whole periods, 0.5 within one code. A ray spawned plainly (a shadow
  // ray, a photon) carries no cone and reads the finest level.
  std::vector<unsigned char> texels;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x)
      texels.insert(texels.end(), 3, (x + y) % 2 ? (unsigned char)255 : (unsigned char)0);
  const rc::scene::Scene scene =
      textured_quad(rc::scene::TextureImage{ppm("checker2.ppm", 64, 64, texels), false,
                                            rc::scene::TextureWrap::repeat, rc::scene::TextureWrap::repeat},
                    rc::Rgb(1.0f));
  const rc::Vec3 texel_centre((20 + 0.5f) / 64.0f, (31 + 0.5f) / 64.0f, 0.0f);
  rc::scene::Ray camera_ray{texel_centre + rc::Vec3(0, 0, 1), {0.0f, 0.0f, -1.0f}, 4.0f};
  camera_ray.spread = 1.0f / 64.0f;
  const std::optional<rc::scene::Hit> first = scene.intersect(camera_ray);
  ASSERT_TRUE(first.has_value());
  const rc::scene::SurfaceInteraction si = scene.surface(camera_ray, *first);
  EXPECT_NEAR(si.cone_width, 1.0f / 64.0f, 1e-6f);
  EXPECT_EQ(si.cone_spread, 1.0f / 64.0f);
  const rc::scene::Ray continued = rc::scene::continue_ray(si, {0.0f, 0.0f, 1.0f});
  EXPECT_EQ(continued.width, si.cone_width);
  EXPECT_EQ(continued.spread, si.cone_spread);

  // The continued cone, moved to arrive head-on 7 units later at the texel's centre.
  rc::scene::Ray later = continued;
  later.origin = texel_centre + rc::Vec3(0, 0, 7);
  later.direction = {0.0f, 0.0f, -1.0f};
  later.tmax = 8.0f;
  const std::optional<rc::scene::Hit> second = scene.intersect(later);
  ASSERT_TRUE(second.has_value());
  const rc::scene::SurfaceInteraction sj = scene.surface(later, *second);
  EXPECT_NEAR(sj.cone_width, 8.0f / 64.0f, 1e-5f);
  rc::scene::Material scratch;
  EXPECT_NEAR(scene.shading_material(sj, scratch).albedo.r, 0.5f, 1.0f / 255.0f);

  const rc::scene::Ray plain = rc::scene::spawn_ray(si, {0.0f, 0.0f, 1.0f});
  EXPECT_EQ(plain.width, 0.0f);
  EXPECT_EQ(plain.spread, 0.0f);
  later.width = later.spread = 0.0f;
  const float sharp = scene.shading_material(scene.surface(later, *scene.intersect(later)), scratch).albedo.r;
  EXPECT_TRUE(std::fabs(sharp) < 1e-4f || std::fabs(sharp - 1.0f) < 1e-4f) << sharp;
}

TEST_F(Textures, BlendStopsRaysInProportionToAlpha) {
  // Constant alpha 0.3, BLEND: each ray stops with probability 0.3, fixed by the ray itself. Over
  // n = 20,000 rays the fraction's standard deviation is √(0.3 · 0.7 / n) = 0.0032; 4 of them.
  rc::scene::Scene scene;
  rc::scene::Material m = rc::scene::Material::make_diffuse("veil", rc::Rgb(0.5f));
  m.alpha_mode = rc::scene::AlphaMode::blend;
  m.alpha = 0.3f;
  scene.materials.push_back(m);
  scene.meshes.push_back(quad(0));
  scene.commit();
  const int n = 20000;
  int hits = 0, blocked = 0;
  for (int i = 0; i < n; ++i) {
    const float x = (float(i % 200) + 0.5f) / 200.0f, y = (float(i / 200) + 0.5f) / 100.0f;
    const rc::scene::Ray ray{{x, y, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f};
    hits += scene.intersect(ray).has_value();
    blocked += scene.occluded(ray);
  }
  EXPECT_NEAR(double(hits) / n, 0.3, 4 * 0.0032);
  // The same ray meets the same choice in both queries.
  EXPECT_EQ(hits, blocked);
}

TEST_F(Textures, TransformMapsUvToImage) {
  // OBJ's convention (t = 1 − v) composed with a scale of 2 in s.
  rc::scene::TextureRef flip;
  flip.map = {1, 0, 0, 0, -1, 1};
  const rc::scene::TextureRef scaled = flip.then({2, 0, 0, 0, 1, 0});
  const rc::Vec2 st = scaled.st({0.25f, 0.25f});
  EXPECT_FLOAT_EQ(st.x, 0.5f);
  EXPECT_FLOAT_EQ(st.y, 0.75f);
  const rc::Vec2 d = scaled.st_delta({0.1f, 0.1f});
  EXPECT_FLOAT_EQ(d.x, 0.2f);
  EXPECT_FLOAT_EQ(d.y, -0.1f);
}

TEST_F(Textures, UnreadableImageIsAnInputError) {
  rc::scene::Scene scene;
  rc::scene::Material m = rc::scene::Material::make_diffuse("textured", rc::Rgb(0.5f));
  m.albedo_texture.image = 0;
  scene.materials.push_back(m);
  scene.textures.push_back(rc::scene::TextureImage{(dir_ / "missing.png").string()});
  scene.meshes.push_back(quad(0));
  try {
    scene.commit();
    ADD_FAILURE() << "a missing texture file was accepted";
  } catch (const rc::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
  // A reference past the scene's textures is refused too.
  rc::scene::Scene bad;
  bad.materials.push_back(m);
  bad.meshes.push_back(quad(0));
  EXPECT_THROW(bad.commit(), rc::InputError);
}

TEST_F(Textures, ElementsReflectTheTexturesMeanOverThem) {
  // A quad whose texture is red on its left half and blue on its right (64 texels across, so
  // the filters blur the step over a few hundredths of the quad): the elements' area-weighted
  // mean reflectance is the texture's mean times the albedo, and elements wholly on one side,
  // at least 0.05 from the step, take that side's colour. The strata (16 per element, each
  // filtered over its share) err only on elements straddling the step, with errors of both
  // signs; the total is checked to 2 %.
  std::vector<unsigned char> texels;
  for (int x = 0; x < 64; ++x) texels.insert(texels.end(), {x < 32 ? (unsigned char)255 : (unsigned char)0, 0, x < 32 ? (unsigned char)0 : (unsigned char)255});
  // Clamped: repeating would blend the blue right edge into the red left one.
  const rc::scene::Scene scene =
      textured_quad(rc::scene::TextureImage{ppm("rb.ppm", 64, 1, texels), true, rc::scene::TextureWrap::clamp,
                                            rc::scene::TextureWrap::clamp},
                    rc::Rgb(0.9f));
  const radiosity::mesh::RadiosityMesh mesh = radiosity::mesh::build_mesh(scene, radiosity::mesh::MeshSettings{.max_edge = 0.1f});
  const std::vector<rc::Rgb> rho = radiosity::mesh::element_reflectance(scene, mesh);
  ASSERT_EQ(rho.size(), mesh.element_count());
  rc::Rgb sum(0.0f);
  double area = 0.0;
  int pure_left = 0, pure_right = 0;
  for (size_t e = 0; e < rho.size(); ++e) {
    sum += rho[e] * mesh.element_area[e];
    area += mesh.element_area[e];
    float lo = 1.0f, hi = 0.0f;
    for (uint32_t v : mesh.elements[e]) {
      lo = std::min(lo, mesh.positions[v].x);
      hi = std::max(hi, mesh.positions[v].x);
    }
    if (hi < 0.45f) {
      ++pure_left;
      EXPECT_NEAR(rho[e].r, 0.9f, 0.9f * kHalfTolerance);
      EXPECT_NEAR(rho[e].b, 0.0f, kHalfTolerance);
    } else if (lo > 0.55f) {
      ++pure_right;
      EXPECT_NEAR(rho[e].b, 0.9f, 0.9f * kHalfTolerance);
      EXPECT_NEAR(rho[e].r, 0.0f, kHalfTolerance);
    }
  }
  EXPECT_GT(pure_left, 10);
  EXPECT_GT(pure_right, 10);
  const rc::Rgb mean = sum * float(1.0 / area);
  EXPECT_NEAR(mean.r, 0.45f, 0.02f * 0.45f);
  EXPECT_NEAR(mean.b, 0.45f, 0.02f * 0.45f);
  EXPECT_NEAR(mean.g, 0.0f, kHalfTolerance);
}

TEST(NormalMaps, TangentsFollowTheImageAxes) {
  // A quad facing +z whose image has its top at y = 1: the tangent runs along +s and the
  // bitangent w·(n × t) up the image, +y. Mirrored (s = 1 − x), the tangent turns to −x and w to
  // −1, so the bitangent still runs up the image. Exact up to rounding.
  rc::scene::TriangleMesh m = quad(0);
  m.uvs = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
  const rc::scene::TextureRef identity;
  for (const bool mirrored : {false, true}) {
    if (mirrored)
      for (rc::Vec2& uv : m.uvs) uv.x = 1.0f - uv.x;
    const std::vector<glm::vec4> t = rc::scene::generate_tangents(m, identity);
    ASSERT_EQ(t.size(), 4u);
    for (const glm::vec4& v : t) {
      EXPECT_NEAR(v.x, mirrored ? -1.0f : 1.0f, 1e-6f);
      EXPECT_NEAR(v.y, 0.0f, 1e-6f);
      EXPECT_NEAR(v.z, 0.0f, 1e-6f);
      EXPECT_EQ(v.w, mirrored ? -1.0f : 1.0f);
      const rc::Vec3 up = rc::scene::tangent_to_world(rc::Vec3(0, 0, 1), v, rc::Vec3(0, 1, 0));
      EXPECT_NEAR(up.y, 1.0f, 1e-6f) << "mirrored " << mirrored;
    }
  }
  // A face without a usable (s, t) frame still gets a unit tangent orthogonal to the normal.
  rc::scene::TriangleMesh flat = quad(0);
  flat.uvs.assign(4, rc::Vec2(0.5f));
  for (const glm::vec4& v : rc::scene::generate_tangents(flat, identity)) {
    EXPECT_NEAR(glm::length(rc::Vec3(v)), 1.0f, 1e-6f);
    EXPECT_NEAR(v.z, 0.0f, 1e-6f);
  }
}

TEST_F(Textures, ObjNormalMapTiltsTheShadingNormal) {
  // One texel holding the tangent-space normal (sin 30°, 0, cos 30°) as 8-bit codes, read as data
  // (exactly code/255): the shading normal on an OBJ quad (v up the image, so +s is +x and the
  // image's up is +y) is that normal, decoded from the same codes, in world axes.
  {
    std::ofstream out(dir_ / "tilt.ppm", std::ios::binary);
    out << "P6\n1 1\n255\n";
    out.put(char(191)).put(char(128)).put(char(238));
  }
  std::ofstream(dir_ / "n.mtl") << "newmtl stone\nKd 0.5 0.5 0.5\nnorm tilt.ppm\n";
  std::ofstream(dir_ / "n.obj") << "mtllib n.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl stone\nf 1/1 2/2 3/3 4/4\n";
  rc::scene::Scene scene = rc::io::load_scene((dir_ / "n.obj").string());
  ASSERT_TRUE(scene.materials[0].normal_texture.valid());
  EXPECT_FALSE(scene.materials[0].normal_is_height);
  EXPECT_FALSE(scene.textures[0].srgb);
  const rc::Vec3 expected = glm::normalize(rc::Vec3(2 * 191 / 255.0f - 1, 2 * 128 / 255.0f - 1, 2 * 238 / 255.0f - 1));
  const rc::scene::Ray ray{{0.3f, 0.6f, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f};
  const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
  ASSERT_TRUE(hit.has_value());
  const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
  EXPECT_NEAR(si.ns.x, expected.x, 1e-5f);
  EXPECT_NEAR(si.ns.y, expected.y, 1e-5f);
  EXPECT_NEAR(si.ns.z, expected.z, 1e-5f);
  EXPECT_EQ(si.ng, rc::Vec3(0, 0, 1));
}

TEST_F(Textures, ObjBumpMapSlopesByItsHeights) {
  // An 8 × 1 height ramp rising 16 codes per texel along +s, with -bm 4: between texel centres
  // away from the wrap, bilinear reads are exact and the central difference is 16/255 per texel,
  // so the tangent-space normal is (−4 · 16/255, 0, 1), normalised.
  {
    std::ofstream out(dir_ / "ramp.pgm", std::ios::binary);
    out << "P5\n8 1\n255\n";
    for (int i = 0; i < 8; ++i) out.put(char(16 * i));
  }
  std::ofstream(dir_ / "b.mtl") << "newmtl stone\nKd 0.5 0.5 0.5\nbump -bm 4 ramp.pgm\n";
  std::ofstream(dir_ / "b.obj") << "mtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl stone\nf 1/1 2/2 3/3 4/4\n";
  rc::scene::Scene scene = rc::io::load_scene((dir_ / "b.obj").string());
  ASSERT_TRUE(scene.materials[0].normal_texture.valid());
  EXPECT_TRUE(scene.materials[0].normal_is_height);
  EXPECT_FLOAT_EQ(scene.materials[0].normal_scale, 4.0f);
  const rc::Vec3 expected = glm::normalize(rc::Vec3(-4.0f * 16.0f / 255.0f, 0.0f, 1.0f));
  for (const float x : {3.5f / 8.0f, 4.0f / 8.0f}) {
    const rc::scene::Ray ray{{x, 0.5f, 1.0f}, {0.0f, 0.0f, -1.0f}, 2.0f};
    const std::optional<rc::scene::Hit> hit = scene.intersect(ray);
    ASSERT_TRUE(hit.has_value());
    const rc::scene::SurfaceInteraction si = scene.surface(ray, *hit);
    EXPECT_NEAR(si.ns.x, expected.x, 1e-5f) << x;
    EXPECT_NEAR(si.ns.y, expected.y, 1e-5f) << x;
    EXPECT_NEAR(si.ns.z, expected.z, 1e-5f) << x;
  }
}

}  // namespace
}  // namespace gilt
