// glTF base-colour textures: image files beside the model and images embedded in it (data: URIs,
// buffer views of .gltf and .glb files), the TEXCOORD set a texture reads, KHR_texture_transform
// and the sampler's wrap modes. Every fixture is written to a fresh temporary directory, which is
// also the texture cache (GILT_TEXTURE_CACHE) of the test.

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
#include <iterator>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/image_io.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::raytrace_core::io {
namespace {

namespace fs = std::filesystem;

#define EXPECT_CONTAINS(text, part) EXPECT_NE((text).find(part), std::string::npos) << "in: " << (text)

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

std::vector<unsigned char> read_bytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

template <typename T>
void append(std::vector<unsigned char>& out, const std::vector<T>& values) {
  if (values.empty()) return;  // memcpy from an empty vector's null data() is undefined
  const size_t at = out.size();
  out.resize(at + values.size() * sizeof(T));
  std::memcpy(out.data() + at, values.data(), values.size() * sizeof(T));
}

/// The unit quad x, y ∈ [0, 1] at z = 0 as two triangles (0 1 2) and (0 2 3), with three UV sets:
///   TEXCOORD_0 float           (u, v) = (x, y)
///   TEXCOORD_1 normalized u16  (u, v) = (1 − x, y), mirrored
///   TEXCOORD_2 normalized u8   (u, v) = (1 − x, y), mirrored, in 4-byte strides
/// and, when given, an image's bytes in buffer view 5.
struct QuadModel {
  std::string materials =
      R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.8, 1, 1], "metallicFactor": 0,
                                "baseColorTexture": {"index": 0}}}])";
  std::string textures = R"([{"source": 0}])";
  std::string images;    ///< JSON array; "[]" for none
  std::string samplers;  ///< JSON array, or empty for none
  std::string extensions_used;
  std::vector<unsigned char> image_bytes;
  std::vector<float> tangents;  ///< TANGENT (4 floats per corner) after the image, when set

  size_t tangent_offset() const { return (124 + image_bytes.size() + 3) / 4 * 4; }

  std::vector<unsigned char> buffer() const {
    std::vector<unsigned char> bin;
    append(bin, std::vector<float>{0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0});         // 0: 48 bytes
    append(bin, std::vector<uint16_t>{0, 1, 2, 0, 2, 3});                        // 48: 12 bytes
    append(bin, std::vector<float>{0, 0, 1, 0, 1, 1, 0, 1});                     // 60: 32 bytes
    append(bin, std::vector<uint16_t>{65535, 0, 0, 0, 0, 65535, 65535, 65535});  // 92: 16 bytes
    append(bin, std::vector<uint8_t>{255, 0, 0, 0, 0, 0, 0, 0, 0, 255, 0, 0, 255, 255, 0, 0});  // 108: 16
    append(bin, image_bytes);                                                                   // 124
    while (bin.size() % 4 != 0) bin.push_back(0);
    append(bin, tangents);
    return bin;
  }

  /// The glTF JSON around `buffer_json` (the one buffer).
  std::string json(const std::string& buffer_json) const {
    std::string views = R"([{"buffer": 0, "byteOffset": 0, "byteLength": 48},
        {"buffer": 0, "byteOffset": 48, "byteLength": 12},
        {"buffer": 0, "byteOffset": 60, "byteLength": 32},
        {"buffer": 0, "byteOffset": 92, "byteLength": 16},
        {"buffer": 0, "byteOffset": 108, "byteLength": 16, "byteStride": 4})";
    if (!image_bytes.empty())
      views +=
          R"(, {"buffer": 0, "byteOffset": 124, "byteLength": )" + std::to_string(image_bytes.size()) + "}";
    if (!tangents.empty())
      views += R"(, {"buffer": 0, "byteOffset": )" + std::to_string(tangent_offset()) + R"(, "byteLength": )" +
               std::to_string(4 * tangents.size()) + "}";
    views += "]";
    const std::string tangent_view = std::to_string(image_bytes.empty() ? 5 : 6);
    return R"({"asset": {"version": "2.0"}, "scene": 0, )" +
           (extensions_used.empty() ? std::string() : R"("extensionsUsed": )" + extensions_used + ", ") +
           R"("scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"name": "quad", "primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 2, "TEXCOORD_1": 3,
                                                             "TEXCOORD_2": 4)" +
           (tangents.empty() ? std::string() : R"(, "TANGENT": 5)") + R"(}, "indices": 1, "material": 0}]}],
  "materials": )" +
           materials + R"(, "textures": )" + textures + R"(, "images": )" + (images.empty() ? "[]" : images) +
           (samplers.empty() ? std::string() : R"(, "samplers": )" + samplers) + R"(,
  "buffers": [)" +
           buffer_json + R"(], "bufferViews": )" + views + R"(,
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"},
                {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"},
                {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                {"bufferView": 3, "componentType": 5123, "normalized": true, "count": 4, "type": "VEC2"},
                {"bufferView": 4, "componentType": 5121, "normalized": true, "count": 4, "type": "VEC2"})" +
           (tangents.empty() ? std::string()
                             : R"(, {"bufferView": )" + tangent_view + R"(, "componentType": 5126, "count": 4, "type": "VEC4"})") +
           "]}";
  }

  /// A .gltf with its buffer in a data: URI.
  std::string gltf() const {
    const std::vector<unsigned char> bin = buffer();
    return json(R"({"byteLength": )" + std::to_string(bin.size()) +
                R"(, "uri": "data:application/octet-stream;base64,)" + base64(bin) + "\"}");
  }

  /// A .glb: JSON chunk, then the buffer as the BIN chunk.
  std::string glb() const {
    const std::vector<unsigned char> bin = buffer();
    std::string text = json(R"({"byteLength": )" + std::to_string(bin.size()) + "}");
    while (text.size() % 4 != 0) text += ' ';
    const auto u32 = [](std::string& out, uint32_t v) {
      for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xff);
    };
    std::string out;
    u32(out, 0x46546C67);  // "glTF"
    u32(out, 2);
    u32(out, uint32_t(12 + 8 + text.size() + 8 + bin.size()));
    u32(out, uint32_t(text.size()));
    u32(out, 0x4E4F534A);  // "JSON"
    out += text;
    u32(out, uint32_t(bin.size()));
    u32(out, 0x004E4942);  // "BIN"
    out.append(bin.begin(), bin.end());
    return out;
  }
};

class GltfTextures : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("gilt_gltf_textures_" + std::to_string(::getpid()) + "_" +
                                        std::to_string(counter++) + "_" + info->name());
    fs::create_directories(dir_);
    if (const char* old = std::getenv("GILT_TEXTURE_CACHE")) old_cache_ = old;
    ::setenv("GILT_TEXTURE_CACHE", cache().c_str(), 1);
  }
  void TearDown() override {
    if (old_cache_)
      ::setenv("GILT_TEXTURE_CACHE", old_cache_->c_str(), 1);
    else
      ::unsetenv("GILT_TEXTURE_CACHE");
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string cache() const { return (dir_ / "cache").string(); }

  std::string write(const std::string& name, const std::string& content) {
    const fs::path path = dir_ / name;
    fs::create_directories(path.parent_path());
    std::ofstream(path, std::ios::binary) << content;
    return path.string();
  }

  /// A 2 × 1 PNG: left texel red, right texel blue (sRGB codes 255 and 0, so linear 1 and 0).
  std::string write_red_blue_png(const std::string& name) {
    const fs::path path = dir_ / name;
    fs::create_directories(path.parent_path());
    util::write_image(path.string(), util::Image{2, 1, {Rgb(1.0f, 0.0f, 0.0f), Rgb(0.0f, 0.0f, 1.0f)}});
    return path.string();
  }
  std::vector<unsigned char> red_blue_png_bytes() {
    return read_bytes(write_red_blue_png("source/red-blue.png"));
  }

  fs::path dir_;
  std::optional<std::string> old_cache_;
};

bool has_warning(const scene::Scene& scene, const std::string& part) {
  for (const std::string& w : scene.warnings)
    if (w.find(part) != std::string::npos) return true;
  return false;
}

int count_warnings(const scene::Scene& scene, const std::string& part) {
  int n = 0;
  for (const std::string& w : scene.warnings) n += w.find(part) != std::string::npos;
  return n;
}

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

// Points on the quad at (x, y) = (0.25, 0.75) and (0.75, 0.25): the centres of the red and the
// blue texel when UVs are (x, y).
scene::SurfaceInteraction left_point(const scene::Scene& scene) {
  return scene.triangle_point(0, 1, {0.25f, 0.5f});
}
scene::SurfaceInteraction right_point(const scene::Scene& scene) {
  return scene.triangle_point(0, 0, {0.5f, 0.25f});
}

Rgb albedo_at(const scene::Scene& scene, const scene::SurfaceInteraction& si) {
  scene::Material scratch;
  return scene.shading_material(si, scratch).albedo;
}

// The texture is stored as 8-bit sRGB, converted to a linear half-float copy at commit: codes 255
// and 0 become exactly 1 and 0, but allow for half-float rounding (≈ 5e-4 near 1) all the same.
constexpr float kTexelTolerance = 1e-3f;

void expect_rgb_near(Rgb actual, Rgb expected) {
  EXPECT_NEAR(actual.r, expected.r, kTexelTolerance);
  EXPECT_NEAR(actual.g, expected.g, kTexelTolerance);
  EXPECT_NEAR(actual.b, expected.b, kTexelTolerance);
}

/// The albedo on the left and right half of the quad: baseColorFactor (0.5, 0.8, 1) times red,
/// then times blue.
void expect_red_left_blue_right(const scene::Scene& scene) {
  ASSERT_EQ(scene.meshes.size(), 1u);
  const scene::SurfaceInteraction left = left_point(scene), right = right_point(scene);
  EXPECT_NEAR(left.uv.x, 0.25f, 1e-6f);
  EXPECT_NEAR(right.uv.x, 0.75f, 1e-6f);
  expect_rgb_near(albedo_at(scene, left), Rgb(0.5f, 0.0f, 0.0f));
  expect_rgb_near(albedo_at(scene, right), Rgb(0.0f, 0.0f, 1.0f));
}

void expect_no_part_files(const std::string& folder) {
  for (const auto& entry : fs::directory_iterator(folder))
    EXPECT_EQ(entry.path().filename().string().find(".part"), std::string::npos) << entry.path();
}

// ---------------------------------------------------------------- images

TEST_F(GltfTextures, ImageFileBesideTheModel) {
  write_red_blue_png("maps/red blue.png");
  QuadModel quad;
  quad.images = R"([{"uri": "maps/red%20blue.png"}])";  // percent-encoded, relative to the .gltf
  const std::string path = write("quad.gltf", quad.gltf());

  const scene::Scene loaded = load_scene_file(path);
  ASSERT_EQ(loaded.textures.size(), 1u);
  EXPECT_TRUE(fs::equivalent(loaded.textures[0].file, dir_ / "maps" / "red blue.png"));
  EXPECT_TRUE(loaded.textures[0].srgb);
  const scene::Material& m = loaded.materials[loaded.meshes[0].material];
  EXPECT_EQ(m.albedo_texture.image, 0);
  EXPECT_EQ(m.albedo_texture.map, (std::array<float, 6>{1, 0, 0, 0, 1, 0}));  // glTF UVs are (s, t) already
  EXPECT_EQ(m.albedo, Rgb(0.5f, 0.8f, 1.0f));
  EXPECT_FALSE(has_warning(loaded, "ignored"));

  expect_red_left_blue_right(load_scene(path));
}

TEST_F(GltfTextures, ImageInDataUri) {
  const std::vector<unsigned char> png = red_blue_png_bytes();
  QuadModel quad;
  quad.images = R"([{"uri": "data:image/png;base64,)" + base64(png) + "\"}]";
  const std::string path = write("quad.gltf", quad.gltf());

  const scene::Scene loaded = load_scene_file(path);
  ASSERT_EQ(loaded.textures.size(), 1u);
  const fs::path file = loaded.textures[0].file;
  EXPECT_TRUE(fs::equivalent(file.parent_path(), cache()));
  EXPECT_EQ(file.extension(), ".png");
  EXPECT_EQ(read_bytes(file), png);
  expect_no_part_files(cache());

  // Named by content: loading again finds the same file rather than writing another.
  EXPECT_EQ(load_scene_file(path).textures[0].file, file.string());
  expect_red_left_blue_right(load_scene(path));
}

TEST_F(GltfTextures, ImageInDataUriWithoutImageType) {
  // An application/octet-stream data URI declares no image type: the bytes tell it is a PNG.
  const std::vector<unsigned char> png = red_blue_png_bytes();
  QuadModel quad;
  quad.images = R"([{"uri": "data:application/octet-stream;base64,)" + base64(png) + "\"}]";
  const scene::Scene scene = load_scene(write("quad.gltf", quad.gltf()));
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(fs::path(scene.textures[0].file).extension(), ".png");
  expect_red_left_blue_right(scene);
}

TEST_F(GltfTextures, ImageInBufferViewOfGltfAndGlb) {
  QuadModel quad;
  quad.image_bytes = red_blue_png_bytes();
  quad.images = R"([{"bufferView": 5, "mimeType": "image/png"}])";

  const scene::Scene from_gltf = load_scene(write("quad.gltf", quad.gltf()));
  ASSERT_EQ(from_gltf.textures.size(), 1u);
  EXPECT_EQ(read_bytes(from_gltf.textures[0].file), quad.image_bytes);
  expect_red_left_blue_right(from_gltf);

  const scene::Scene from_glb = load_scene(write("quad.glb", quad.glb()));
  ASSERT_EQ(from_glb.textures.size(), 1u);
  EXPECT_EQ(from_glb.textures[0].file, from_gltf.textures[0].file);  // same bytes, same cache file
  expect_red_left_blue_right(from_glb);
  expect_no_part_files(cache());
}

TEST_F(GltfTextures, JpegMimeTypeGivesJpgFile) {
  QuadModel quad;
  quad.image_bytes = {0xff, 0xd8, 0xff, 0xe0, 0, 0, 0, 0};  // never opened: the scene is not committed
  quad.images = R"([{"bufferView": 5, "mimeType": "image/jpeg"}])";
  const scene::Scene scene = load_scene_file(write("quad.gltf", quad.gltf()));
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_EQ(fs::path(scene.textures[0].file).extension(), ".jpg");
}

TEST_F(GltfTextures, MissingImageFileLeavesMaterialUntextured) {
  QuadModel quad;
  quad.images = R"([{"uri": "nowhere.png"}])";
  const scene::Scene scene = load_scene(write("quad.gltf", quad.gltf()));  // not fatal: commits
  EXPECT_TRUE(scene.textures.empty());
  EXPECT_FALSE(scene.materials[scene.meshes[0].material].is_textured());
  EXPECT_EQ(count_warnings(scene, "nowhere.png"), 1) << "one warning naming the file";
  EXPECT_TRUE(has_warning(scene, "untextured"));
  expect_rgb_near(albedo_at(scene, left_point(scene)), Rgb(0.5f, 0.8f, 1.0f));
}

TEST_F(GltfTextures, BadTextureReferencesNameTheField) {
  QuadModel quad;
  quad.images = R"([{"uri": "nowhere.png"}])";
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 4}}}])";
  const std::string bad_texture = write("bad_texture.gltf", quad.gltf());
  std::string message = error_of([&] { load_scene_file(bad_texture); });
  EXPECT_CONTAINS(message, "bad_texture.gltf");
  EXPECT_CONTAINS(message, "materials[0].pbrMetallicRoughness.baseColorTexture.index");

  quad = QuadModel{};
  quad.textures = R"([{"source": 3}])";
  const std::string bad_source = write("bad_source.gltf", quad.gltf());
  message = error_of([&] { load_scene_file(bad_source); });
  EXPECT_CONTAINS(message, "bad_source.gltf");
  EXPECT_CONTAINS(message, "textures[0].source");
}

// ---------------------------------------------------------------- texture coordinates

TEST_F(GltfTextures, TexCoordSelectsTheUvSet) {
  write_red_blue_png("red-blue.png");
  QuadModel quad;
  quad.images = R"([{"uri": "red-blue.png"}])";

  // TEXCOORD_1: normalized unsigned short, mirrored; 65535 reads as 1.
  quad.materials =
      R"([{"pbrMetallicRoughness": {"metallicFactor": 0, "baseColorTexture": {"index": 0, "texCoord": 1}}}])";
  const scene::Scene set1 = load_scene(write("set1.gltf", quad.gltf()));
  ASSERT_EQ(set1.meshes[0].uvs.size(), 4u);
  EXPECT_EQ(set1.meshes[0].uvs[0], Vec2(1.0f, 0.0f));
  EXPECT_EQ(set1.meshes[0].uvs[3], Vec2(1.0f, 1.0f));
  expect_rgb_near(albedo_at(set1, left_point(set1)), Rgb(0.0f, 0.0f, 1.0f));  // mirrored: blue on the left
  expect_rgb_near(albedo_at(set1, right_point(set1)), Rgb(1.0f, 0.0f, 0.0f));

  // TEXCOORD_2: normalized unsigned byte; 255 reads as 1.
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 2}}}])";
  const scene::Scene set2 = load_scene_file(write("set2.gltf", quad.gltf()));
  ASSERT_EQ(set2.meshes[0].uvs.size(), 4u);
  EXPECT_EQ(set2.meshes[0].uvs[0], Vec2(1.0f, 0.0f));
  EXPECT_EQ(set2.meshes[0].uvs[2], Vec2(0.0f, 1.0f));

  // A set the primitive lacks: a warning naming it, no UVs.
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 5}}}])";
  const scene::Scene set5 = load_scene_file(write("set5.gltf", quad.gltf()));
  EXPECT_TRUE(set5.meshes[0].uvs.empty());
  EXPECT_TRUE(has_warning(set5, "TEXCOORD_5"));

  // An untextured material keeps TEXCOORD_0.
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1]}}])";
  const scene::Scene plain = load_scene_file(write("plain.gltf", quad.gltf()));
  ASSERT_EQ(plain.meshes[0].uvs.size(), 4u);
  EXPECT_EQ(plain.meshes[0].uvs[1], Vec2(1.0f, 0.0f));
}

// ---------------------------------------------------------------- KHR_texture_transform

TEST_F(GltfTextures, TextureTransformMap) {
  write_red_blue_png("red-blue.png");
  QuadModel quad;
  quad.images = R"([{"uri": "red-blue.png"}])";
  quad.extensions_used = R"(["KHR_texture_transform"])";
  quad.materials = R"([
    {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
        {"offset": [0.25, 0.5], "rotation": 0.3, "scale": [2, 3]}}}}},
    {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions": {"KHR_texture_transform":
        {"offset": [0, 1], "rotation": 1.57079632679, "scale": [0.5, 0.5]}}}}}])";
  const scene::Scene scene = load_scene_file(write("transform.gltf", quad.gltf()));
  ASSERT_EQ(scene.materials.size(), 2u);

  // Worked by hand: T(o)·R(r)·S(s) with R's rows (cos r, sin r) and (−sin r, cos r), so
  //   s = cos r·sx·u + sin r·sy·v + ox,   t = −sin r·sx·u + cos r·sy·v + oy.
  const float c = std::cos(0.3f), s = std::sin(0.3f);
  const std::array<float, 6> expected{2 * c, 3 * s, 0.25f, -2 * s, 3 * c, 0.5f};
  const scene::TextureRef& general = scene.materials[0].albedo_texture;
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(general.map[size_t(i)], expected[size_t(i)], 1e-6f) << "map[" << i << "]";

  // The extension's own example reads the image's lower-left quadrant (t grows downwards), turned
  // a quarter clockwise: the UV square's corners land on s ∈ [0, ½], t ∈ [½, 1], with u running up
  // the image and v running right.
  const scene::TextureRef& example = scene.materials[1].albedo_texture;
  const auto near = [](Vec2 a, Vec2 b) { return std::abs(a.x - b.x) < 1e-6f && std::abs(a.y - b.y) < 1e-6f; };
  EXPECT_TRUE(near(example.st({0, 0}), {0.0f, 1.0f}));
  EXPECT_TRUE(near(example.st({1, 0}), {0.0f, 0.5f}));
  EXPECT_TRUE(near(example.st({0, 1}), {0.5f, 1.0f}));
  EXPECT_TRUE(near(example.st({1, 1}), {0.5f, 0.5f}));
}

TEST_F(GltfTextures, TextureTransformOffsetAndTexCoordOverride) {
  write_red_blue_png("red-blue.png");
  QuadModel quad;
  quad.images = R"([{"uri": "red-blue.png"}])";
  quad.extensions_used = R"(["KHR_texture_transform"])";
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions":
      {"KHR_texture_transform": {"offset": [0.5, 0]}}}}}])";
  const scene::Scene shifted = load_scene(write("shifted.gltf", quad.gltf()));
  // Half the image's width along s (repeating): blue on the left, red on the right.
  expect_rgb_near(albedo_at(shifted, left_point(shifted)), Rgb(0.0f, 0.0f, 1.0f));
  expect_rgb_near(albedo_at(shifted, right_point(shifted)), Rgb(1.0f, 0.0f, 0.0f));

  // The extension's texCoord overrides the textureInfo's.
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 0, "extensions":
      {"KHR_texture_transform": {"texCoord": 1}}}}}])";
  const scene::Scene overridden = load_scene_file(write("overridden.gltf", quad.gltf()));
  ASSERT_EQ(overridden.meshes[0].uvs.size(), 4u);
  EXPECT_EQ(overridden.meshes[0].uvs[0], Vec2(1.0f, 0.0f));  // TEXCOORD_1

  // Required, the extension is now read rather than refused.
  quad.extensions_used = R"(["KHR_texture_transform"], "extensionsRequired": ["KHR_texture_transform"])";
  EXPECT_NO_THROW(load_scene_file(write("required.gltf", quad.gltf())));

  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "extensions":
      {"KHR_texture_transform": {"scale": [1]}}}}}])";
  const std::string message = error_of([&] { load_scene_file(write("bad_scale.gltf", quad.gltf())); });
  EXPECT_CONTAINS(message, "bad_scale.gltf");
  EXPECT_CONTAINS(message, "KHR_texture_transform.scale");
}

// ---------------------------------------------------------------- samplers

TEST_F(GltfTextures, SamplerWrapModes) {
  write_red_blue_png("red-blue.png");
  QuadModel quad;
  quad.images = R"([{"uri": "red-blue.png"}])";
  quad.samplers =
      R"([{"wrapS": 33071, "wrapT": 33648}, {"wrapS": 33648, "wrapT": 10497}, {"magFilter": 9729}])";
  quad.textures = R"([{"source": 0, "sampler": 0}, {"source": 0, "sampler": 1}, {"source": 0, "sampler": 2},
                      {"source": 0}, {"source": 0, "sampler": 0}])";
  quad.materials = "[";
  for (int i = 0; i < 5; ++i)
    quad.materials += std::string(i ? ", " : "") +
                      R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": )" + std::to_string(i) +
                      "}}}";
  quad.materials += "]";
  const scene::Scene scene = load_scene_file(write("samplers.gltf", quad.gltf()));
  ASSERT_EQ(scene.materials.size(), 5u);
  // One image per file and pair of wrap modes: textures 0 and 4 share one, as do 2 (a sampler
  // without wrap modes) and 3 (no sampler), both repeating.
  ASSERT_EQ(scene.textures.size(), 3u);
  const auto wraps = [&](int material) {
    const scene::TextureImage& t =
        scene.textures[size_t(scene.materials[size_t(material)].albedo_texture.image)];
    return std::make_pair(t.wrap_s, t.wrap_t);
  };
  EXPECT_EQ(wraps(0), std::make_pair(scene::TextureWrap::clamp, scene::TextureWrap::mirror));
  EXPECT_EQ(wraps(1), std::make_pair(scene::TextureWrap::mirror, scene::TextureWrap::repeat));
  EXPECT_EQ(wraps(2), std::make_pair(scene::TextureWrap::repeat, scene::TextureWrap::repeat));
  EXPECT_EQ(wraps(3), std::make_pair(scene::TextureWrap::repeat, scene::TextureWrap::repeat));
  EXPECT_EQ(scene.materials[2].albedo_texture.image, scene.materials[3].albedo_texture.image);
  EXPECT_EQ(scene.materials[0].albedo_texture.image, scene.materials[4].albedo_texture.image);

  quad.samplers = R"([{"wrapS": 1234}])";
  quad.textures = R"([{"source": 0, "sampler": 0}])";
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
  const std::string message = error_of([&] { load_scene_file(write("bad_wrap.gltf", quad.gltf())); });
  EXPECT_CONTAINS(message, "bad_wrap.gltf");
  EXPECT_CONTAINS(message, "samplers[0].wrapS");
}

// ---------------------------------------------------------------- what is still ignored

TEST_F(GltfTextures, UnmodelledMaterialExtensionsAreNamed) {
  QuadModel quad;
  quad.materials = R"([
    {"extensions": {"KHR_materials_unlit": {}}},
    {"extensions": {"KHR_materials_clearcoat": {"clearcoatFactor": 1}, "KHR_materials_ior": {"ior": 1.4}}},
    {"pbrMetallicRoughness": {"metallicFactor": 0}, "extensions": {"KHR_materials_specular": {"specularFactor": 0}}}])";
  const scene::Scene scene = load_scene_file(write("extensions.gltf", quad.gltf()));
  ASSERT_EQ(count_warnings(scene, "material extensions are ignored"), 1) << "one line per file";
  EXPECT_TRUE(has_warning(scene, "KHR_materials_unlit (its surfaces are lit)"));
  EXPECT_TRUE(has_warning(scene, "KHR_materials_clearcoat"));
  EXPECT_FALSE(has_warning(scene, "KHR_materials_ior"));       // read: the dielectric part's F0
  EXPECT_FALSE(has_warning(scene, "KHR_materials_specular"));  // read: factor 0 is Lambertian
  EXPECT_EQ(scene.materials[2].kind, scene::MaterialKind::diffuse);
  EXPECT_EQ(scene.materials[1].kind, scene::MaterialKind::metallic_roughness);
  EXPECT_FLOAT_EQ(scene.materials[1].ior, 1.4f);
}

TEST_F(GltfTextures, OtherTexturesWarnedInOneLine) {
  write_red_blue_png("red-blue.png");
  QuadModel quad;
  quad.images = R"([{"uri": "red-blue.png"}])";
  quad.materials = R"([
    {"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}, "normalTexture": {"index": 0},
     "emissiveTexture": {"index": 0}, "emissiveFactor": [1, 1, 1], "occlusionTexture": {"index": 0}},
    {"pbrMetallicRoughness": {"metallicRoughnessTexture": {"index": 0}}, "normalTexture": {"index": 0, "scale": 0.5}},
    {"name": "chrome", "pbrMetallicRoughness": {"metallicFactor": 1, "roughnessFactor": 0,
                                                "baseColorTexture": {"index": 0}}}])";
  const scene::Scene scene = load_scene_file(write("others.gltf", quad.gltf()));
  EXPECT_TRUE(scene.materials[0].albedo_texture.valid());
  EXPECT_TRUE(scene.materials[0].emission_texture.valid());
  EXPECT_TRUE(scene.materials[1].metallic_roughness_texture.valid());
  EXPECT_FALSE(scene.materials[1].albedo_texture.valid());
  // A mirror's base colour tints its reflection, which an albedo texture cannot: left out.
  EXPECT_EQ(scene.materials[2].kind, scene::MaterialKind::mirror);
  EXPECT_FALSE(scene.materials[2].is_textured());
  // Normal textures are read (as data), with their scale.
  for (size_t i : {0, 1}) {
    ASSERT_TRUE(scene.materials[i].normal_texture.valid());
    EXPECT_FALSE(scene.materials[i].normal_is_height);
    EXPECT_FALSE(scene.textures[size_t(scene.materials[i].normal_texture.image)].srgb);
  }
  EXPECT_EQ(scene.materials[0].normal_scale, 1.0f);
  EXPECT_EQ(scene.materials[1].normal_scale, 0.5f);
  // One image, read as colour (base, emission) and as data (metallic-roughness, normal).
  EXPECT_EQ(scene.textures.size(), 2u);
  ASSERT_EQ(count_warnings(scene, "ignored"), 1) << "one line per file";
  for (const char* kind : {"occlusion", "mirror"}) EXPECT_TRUE(has_warning(scene, kind)) << kind;
  for (const char* kind : {"normal", "emissive", "metallic-roughness"}) EXPECT_FALSE(has_warning(scene, kind)) << kind;

  // Nothing is said when the base colour is all there is.
  quad.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
  EXPECT_FALSE(has_warning(load_scene_file(write("base_only.gltf", quad.gltf())), "ignored"));
}

TEST_F(GltfTextures, NormalTextureTiltsTheShadingNormalUpTheImage) {
  // One texel holding the tangent-space normal (0, sin 30°, cos 30°): tilted up the image. The
  // quad's UVs are (x, y) and glTF's t runs down the image, so up the image is −y in the world:
  // the shading normal is the texel's normal (decoded from its own 8-bit codes, read as data,
  // exactly code/255) with its y negated. A scale of 0.5 halves x and y before normalising.
  {
    std::ofstream out(dir_ / "tilt.ppm", std::ios::binary);
    out << "P6\n1 1\n255\n";
    out.put(char(128)).put(char(191)).put(char(238));
  }
  QuadModel quad;
  quad.images = R"([{"uri": "tilt.ppm"}])";
  for (const float scale : {1.0f, 0.5f}) {
    quad.materials = R"([{"pbrMetallicRoughness": {"metallicFactor": 0}, "normalTexture": {"index": 0, "scale": )" +
                     std::to_string(scale) + "}}]";
    const scene::Scene scene = load_scene(write("tilt.gltf", quad.gltf()));
    const scene::SurfaceInteraction si = left_point(scene);
    const Vec3 expected = glm::normalize(Vec3(scale * (2 * 128 / 255.0f - 1), -scale * (2 * 191 / 255.0f - 1),
                                              2 * 238 / 255.0f - 1));
    EXPECT_NEAR(si.ns.x, expected.x, 1e-5f) << scale;
    EXPECT_NEAR(si.ns.y, expected.y, 1e-5f) << scale;
    EXPECT_NEAR(si.ns.z, expected.z, 1e-5f) << scale;
  }
  // The file's own TANGENT wins over the generated frame: tangent +y with w = +1 puts the
  // bitangent n × t along −x, so "up the image" now tilts the normal towards −x.
  quad.tangents = {0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1, 0, 1};
  quad.materials = R"([{"pbrMetallicRoughness": {"metallicFactor": 0}, "normalTexture": {"index": 0}}])";
  const scene::Scene scene = load_scene(write("tangents.gltf", quad.gltf()));
  ASSERT_EQ(scene.meshes[0].tangents.size(), 4u);
  const scene::SurfaceInteraction si = left_point(scene);
  const Vec3 expected = glm::normalize(Vec3(-(2 * 191 / 255.0f - 1), 2 * 128 / 255.0f - 1, 2 * 238 / 255.0f - 1));
  EXPECT_NEAR(si.ns.x, expected.x, 1e-5f);
  EXPECT_NEAR(si.ns.y, expected.y, 1e-5f);
  EXPECT_NEAR(si.ns.z, expected.z, 1e-5f);
}

TEST_F(GltfTextures, AlphaModeMaskAndBlendComeFromTheBaseColour) {
  // MASK with baseColorFactor alpha 0.3 under the default cutoff 0.5: the quad is cut away
  // entirely. With cutoff 0.2 it is whole. BLEND keeps the factor as the stopping probability.
  QuadModel quad;
  quad.textures = "[]";
  const auto load_with = [&](const std::string& material) {
    quad.materials = "[" + material + "]";
    return load_scene(write("alpha.gltf", quad.gltf()));
  };
  const auto stops_at_centre = [](const scene::Scene& scene) {
    const Bounds3& b = scene.bounds();
    const Vec3 c = 0.5f * (b.lo + b.hi), size = b.hi - b.lo;
    const int axis = size.x <= size.y && size.x <= size.z ? 0 : size.y <= size.z ? 1 : 2;  // the quad's normal
    Vec3 from = c, dir(0.0f);
    from[axis] += 1.0f;
    dir[axis] = -1.0f;
    return scene.occluded(scene::Ray{from, dir, 2.0f});
  };
  const std::string factor = R"("pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.3]})";
  const scene::Scene masked = load_with("{" + factor + R"(, "alphaMode": "MASK"})");
  EXPECT_EQ(masked.materials[0].alpha_mode, scene::AlphaMode::mask);
  EXPECT_FLOAT_EQ(masked.materials[0].alpha, 0.3f);
  EXPECT_FALSE(stops_at_centre(masked));
  EXPECT_TRUE(stops_at_centre(load_with("{" + factor + R"(, "alphaMode": "MASK", "alphaCutoff": 0.2})")));
  EXPECT_EQ(load_with("{" + factor + R"(, "alphaMode": "BLEND"})").materials[0].alpha_mode,
            scene::AlphaMode::blend);
  // OPAQUE (the default) ignores alpha.
  EXPECT_TRUE(stops_at_centre(load_with("{" + factor + "}")));
  EXPECT_NE(error_of([&] { load_with("{" + factor + R"(, "alphaMode": "CUTOUT"})"); }).find("alphaMode"), std::string::npos);
}

}  // namespace
}  // namespace gilt::raytrace_core::io
