// glTF 2.0 (.gltf and .glb) through tinygltf: the node hierarchy of the default scene with its
// transforms, triangle primitives, materials with their textures, its cameras (perspective and
// orthographic; the first frames the scene) and KHR_lights_punctual lights. Occlusion textures, extensions' textures, skins, morph targets
// and animations are ignored (with a warning naming them). Normal textures are read, with the
// primitive's TANGENT when it has one (else tangents are generated: normal_map.h).
//
// Material mapping (documented in docs/scene-format.md); base = baseColorFactor.rgb,
// m = metallicFactor, r = roughnessFactor:
//   KHR_materials_transmission factor > 0.5 → dielectric, ior from KHR_materials_ior (1.5),
//       transmission tinted by base, GGX roughness r (0: a perfect interface; rough_dielectric.h);
//       with KHR_materials_volume of thickness > 0 a solid with
//       σa = −ln(attenuationColor) / attenuationDistance, else a thin sheet (light passes unbent)
//   m = 1, r² ≤ kMinGgxAlpha, untextured     → mirror, reflectance base
//   m = 0, KHR_materials_specular's specularFactor = 0 → diffuse (F0 = 0: exactly Lambertian)
//   otherwise                               → metallic_roughness (the specification's appendix B,
//       raytrace_core/scene/bsdf.cpp), ior from KHR_materials_ior for the dielectric's F0
//   emission = emissiveFactor × KHR_materials_emissive_strength; doubleSided → two-sided emission
// Photometric light units are read as radiometric: point/spot intensity (cd) as W·sr⁻¹,
// directional illuminance (lx) as W·m⁻², i.e. no 683 lm/W factor.
//
// Textures: baseColorTexture (sRGB) scales the base colour, metallicRoughnessTexture (linear;
// roughness in green, metalness in blue) the two factors, emissiveTexture (sRGB) the emission.
// Each reads the sampler's wrap modes. A mirror's or glass's base colour texture is ignored with
// a warning. A material reads one UV set (textureInfo.texCoord, or the KHR_texture_transform's
// own): its first texture's; a texture on another set is ignored with a warning. glTF's UVs
// already have OpenImageIO's origin (top-left), so the map is the identity unless
// KHR_texture_transform gives one. Image files are handed to OpenImageIO as they are; images
// embedded in the glTF (data: URIs, buffer views) are first written to the texture cache folder
// under a name made from their content.

#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "raytrace_core/io/gltf_file.h"
#include <glm/gtc/quaternion.hpp>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/scene/microfacet.h"

namespace gilt::raytrace_core::io {

namespace fs = std::filesystem;

namespace {

/// Number `key` of a JSON-like extension object, or `fallback`.
double number_or(const tinygltf::Value& object, const char* key, double fallback) {
  if (!object.IsObject() || !object.Has(key) || !object.Get(key).IsNumber()) return fallback;
  return object.Get(key).GetNumberAsDouble();
}

/// The extension object named `name`, or a null Value.
const tinygltf::Value& extension(const tinygltf::ExtensionMap& extensions, const char* name) {
  static const tinygltf::Value null_value;
  const auto it = extensions.find(name);
  return it == extensions.end() ? null_value : it->second;
}

Rgb rgb_or(const std::vector<double>& v, Rgb fallback) {
  return v.size() >= 3 ? Rgb(float(v[0]), float(v[1]), float(v[2])) : fallback;
}

/// A URI's %XX escapes replaced by the bytes they stand for (a malformed escape is kept as written).
std::string percent_decode(const std::string& uri) {
  const auto hex = [](char c) -> int {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
  };
  std::string out;
  out.reserve(uri.size());
  for (size_t i = 0; i < uri.size(); ++i) {
    if (uri[i] == '%' && i + 2 < uri.size() && hex(uri[i + 1]) >= 0 && hex(uri[i + 2]) >= 0) {
      out += char(hex(uri[i + 1]) * 16 + hex(uri[i + 2]));
      i += 2;
    } else {
      out += uri[i];
    }
  }
  return out;
}

/// File extension for an embedded image: from its declared MIME type, else from its first bytes
/// (a data:application/octet-stream URI declares none). Empty when neither tells.
std::string image_extension(const std::string& mime_type, const unsigned char* bytes, size_t size) {
  if (mime_type == "image/png") return ".png";
  if (mime_type == "image/jpeg") return ".jpg";
  if (mime_type == "image/webp") return ".webp";
  if (mime_type == "image/bmp") return ".bmp";
  if (mime_type == "image/gif") return ".gif";
  const auto starts = [&](std::initializer_list<unsigned char> magic, size_t at = 0) {
    return size >= at + magic.size() && std::equal(magic.begin(), magic.end(), bytes + at);
  };
  if (starts({0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'})) return ".png";
  if (starts({0xff, 0xd8, 0xff})) return ".jpg";
  if (starts({'R', 'I', 'F', 'F'}) && starts({'W', 'E', 'B', 'P'}, 8)) return ".webp";
  if (starts({'G', 'I', 'F', '8'})) return ".gif";
  if (starts({'B', 'M'})) return ".bmp";
  return {};
}

/// FNV-1a over bytes: a name for cached content that is the same in every run and build.
uint64_t content_hash(const unsigned char* bytes, size_t size) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (size_t i = 0; i < size; ++i) h = (h ^ bytes[i]) * 0x100000001b3ull;
  return h;
}

/// True when `path` holds exactly these bytes.
bool file_holds(const fs::path& path, const unsigned char* bytes, size_t size) {
  std::error_code ec;
  if (fs::file_size(path, ec) != size || ec) return false;
  std::ifstream in(path, std::ios::binary);
  const std::vector<unsigned char> held((std::istreambuf_iterator<char>(in)),
                                        std::istreambuf_iterator<char>());
  return held.size() == size && std::equal(held.begin(), held.end(), bytes);
}

/// The texture wrap mode of a glTF sampler's wrapS or wrapT value.
bool wrap_mode(int gl_wrap, scene::TextureWrap& out) {
  switch (gl_wrap) {
    case TINYGLTF_TEXTURE_WRAP_REPEAT:
      out = scene::TextureWrap::repeat;
      return true;
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
      out = scene::TextureWrap::clamp;
      return true;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
      out = scene::TextureWrap::mirror;
      return true;
    default:
      return false;
  }
}

scene::Material convert_material(const tinygltf::Material& gm, const std::string& name) {
  const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
  const Rgb base = clamp(rgb_or(pbr.baseColorFactor, Rgb(1.0f)), 0.0f, 1.0f);
  const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
  const float roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
  const double transmission =
      number_or(extension(gm.extensions, "KHR_materials_transmission"), "transmissionFactor", 0.0);
  float ior = float(number_or(extension(gm.extensions, "KHR_materials_ior"), "ior", 1.5));
  if (!(ior >= 1.0f) || !std::isfinite(ior)) ior = 1.5f;  // the extension allows ior = 0 ("infinite"): not glass

  scene::Material m;
  if (transmission > 0.5) {
    Rgb absorption(0.0f);
    const tinygltf::Value& volume = extension(gm.extensions, "KHR_materials_volume");
    const double distance = number_or(volume, "attenuationDistance", 0.0);
    if (distance > 0.0 && volume.Has("attenuationColor") && volume.Get("attenuationColor").ArrayLen() == 3) {
      const tinygltf::Value& color = volume.Get("attenuationColor");
      for (int c = 0; c < 3; ++c)
        absorption[c] = float(-std::log(std::clamp(color.Get(c).GetNumberAsDouble(), 1e-4, 1.0)) / distance);
    }
    m = scene::Material::make_dielectric(name, ior, absorption);
    // The base colour tints what the surface transmits. Without KHR_materials_volume (or with a
    // thickness of zero) the surface is thin-walled: light passes through unbent.
    m.transmission_tint = base;
    m.roughness = roughness;  // the extension's transmission is as rough as the surface
    m.thin_walled = !volume.IsObject() || !(number_or(volume, "thicknessFactor", 0.0) > 0.0);
    if (m.thin_walled) m.absorption = Rgb(0.0f);
  } else if (metallic == 1.0f && roughness * roughness <= scene::kMinGgxAlpha && pbr.metallicRoughnessTexture.index < 0) {
    m = scene::Material::make_mirror(name, base);  // narrower than the GGX lobe can be: a delta lobe
  } else if (metallic == 0.0f &&
             number_or(extension(gm.extensions, "KHR_materials_specular"), "specularFactor", 1.0) == 0.0) {
    m = scene::Material::make_diffuse(name, base);  // F0 = 0: the specification's BRDF is exactly Lambertian
  } else {
    m = scene::Material::make_metallic_roughness(name, base, metallic, roughness, ior);
  }
  const float strength =
      float(number_or(extension(gm.extensions, "KHR_materials_emissive_strength"), "emissiveStrength", 1.0));
  m.emission = clamp(rgb_or(gm.emissiveFactor, Rgb(0.0f)), 0.0f, kInfinity) * std::max(0.0f, strength);
  m.two_sided_emission = gm.doubleSided;
  return m;
}

/// One glTF file being appended to a scene.
class GltfLoader {
 public:
  GltfLoader(const tinygltf::Model& model, std::string file, scene::Scene& scene)
      : model_(model), file_(std::move(file)), scene_(scene), on_path_(model.nodes.size(), false) {}

  /// A driver over named passes (below): check the required extensions, convert the materials
  /// (naming what is ignored), then walk the default scene's node trees into meshes, cameras
  /// and lights.
  void load() {
    check_required_extensions();
    first_material_ = static_cast<uint32_t>(scene_.materials.size());
    file_index_ = int32_t(scene_.model_files.size());
    scene_.model_files.push_back(file_);
    image_files_.assign(model_.images.size(), ImageFile{});
    Ignored ignored;
    for (size_t i = 0; i < model_.materials.size(); ++i) add_material(i, ignored);
    report_ignored(ignored);
    for (int root : scene_roots()) visit(root, glm::mat4(1.0f));
    if (scene_.meshes.empty()) scene_.warnings.push_back(file_ + ": no triangles");
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_ + ": " + what); }

  /// A glTF image as a file OpenImageIO can open: `path` empty when there is none (warned once).
  struct ImageFile {
    bool resolved = false;
    std::string path;
  };

  // --- load's passes, in the order it runs them. ---

  /// What the file has and gilt does not read, each named once in load's warnings.
  struct Ignored {
    std::vector<std::string> textures;    ///< kinds of texture the file has and gilt does not read
    std::vector<std::string> extensions;  ///< material extensions gilt does not model
  };

  /// Adds `kind` to `kinds` when `present`, unless it is there already.
  static void note_ignored(std::vector<std::string>& kinds, bool present, const std::string& kind) {
    if (present && std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) kinds.push_back(kind);
  }

  /// Pass 1. Reads extensionsRequired; writes nothing. Fails on an extension a file cannot be
  /// read without (e.g. quantized attributes). Draco-compressed primitives were decoded into
  /// ordinary accessors while the file was read (gltf_draco.h).
  void check_required_extensions() const {
    for (const std::string& required : model_.extensionsRequired)
      if (!gltf_extension_supported(required))
        fail("requires extension " + required + ", which gilt does not support");
  }

  /// One texture of a material (`where` names it, `key` the texture) through texture_ref, or an
  /// invalid reference when it reads another UV set than the material's earlier textures, with
  /// a warning. Reads and writes `uv_set`: the material's set so far (−1: none yet).
  scene::TextureRef material_texture(const tinygltf::TextureInfo& info, const std::string& where, const std::string& key,
                              bool srgb, int& uv_set) {
    int set = 0;
    scene::TextureRef ref = texture_ref(info, where + "." + key, set, srgb);
    if (!ref.valid()) return ref;
    if (uv_set >= 0 && set != uv_set) {
      scene_.warnings.push_back(file_ + ": " + where + "." + key + " reads texture coordinate set " +
                                std::to_string(set) + " but the material's other textures read set " +
                                std::to_string(uv_set) + "; it is ignored");
      return scene::TextureRef{};
    }
    uv_set = set;
    return ref;
  }

  /// Pass 2a, for material gm (`where` names it). Reads its base colour, metallic-roughness,
  /// emissive and normal textures; writes m's textures (and normal scale), the kinds it leaves
  /// out to `ignored`; returns the material's UV set: its first texture's (0 when it has none).
  int read_material_textures(const tinygltf::Material& gm, const std::string& where, scene::Material& m,
                             std::vector<std::string>& ignored) {
    int uv_set = -1;  // one UV set per material: the first texture's; a texture on another is left out
    // A mirror's or glass's base colour tints what it reflects or transmits, which a texture on
    // Material::albedo cannot express: left out, as the OBJ loader leaves out their map_Kd.
    const bool has_base_texture = gm.pbrMetallicRoughness.baseColorTexture.index >= 0;
    note_ignored(ignored, has_base_texture && m.is_traced_through(), "base colour of mirror and glass materials");
    if (has_base_texture && !m.is_traced_through())
      m.albedo_texture = material_texture(gm.pbrMetallicRoughness.baseColorTexture, where,
                                          "pbrMetallicRoughness.baseColorTexture", true, uv_set);
    const bool has_mr_texture = gm.pbrMetallicRoughness.metallicRoughnessTexture.index >= 0;
    // Rough glass reads the texture's roughness (green); its metalness has no meaning there.
    const bool reads_mr = m.kind == scene::MaterialKind::metallic_roughness || m.is_rough_dielectric();
    if (has_mr_texture && reads_mr)
      m.metallic_roughness_texture = material_texture(gm.pbrMetallicRoughness.metallicRoughnessTexture, where,
                                                      "pbrMetallicRoughness.metallicRoughnessTexture", false, uv_set);
    note_ignored(ignored, has_mr_texture && !reads_mr, "metallic-roughness of mirror and smooth glass materials");
    if (gm.emissiveTexture.index >= 0 && m.is_emissive())
      m.emission_texture = material_texture(gm.emissiveTexture, where, "emissiveTexture", true, uv_set);
    if (gm.normalTexture.index >= 0) {
      tinygltf::TextureInfo info;
      info.index = gm.normalTexture.index;
      info.texCoord = gm.normalTexture.texCoord;
      info.extensions = gm.normalTexture.extensions;
      m.normal_texture = material_texture(info, where, "normalTexture", false, uv_set);
      m.normal_scale = float(gm.normalTexture.scale);
      if (!std::isfinite(m.normal_scale)) fail(where + ".normalTexture.scale: must be a finite number");
    }
    return std::max(uv_set, 0);
  }

  /// Pass 2b, for material gm (`where` names it). Reads its alphaMode, alphaCutoff and base
  /// colour alpha; writes m's coverage: baseColorFactor's alpha times the base colour texture's.
  /// Fails on an unknown mode or a cutoff outside [0, 1].
  void read_alpha_mode(const tinygltf::Material& gm, const std::string& where, scene::Material& m) const {
    if (gm.alphaMode == "MASK" || gm.alphaMode == "BLEND") {
      m.alpha_mode = gm.alphaMode == "MASK" ? scene::AlphaMode::mask : scene::AlphaMode::blend;
      const auto& factor = gm.pbrMetallicRoughness.baseColorFactor;
      m.alpha = factor.size() == 4 ? std::clamp(float(factor[3]), 0.0f, 1.0f) : 1.0f;
      if (!(gm.alphaCutoff >= 0.0 && gm.alphaCutoff <= 1.0)) fail(where + ".alphaCutoff: must lie in [0, 1]");
      m.alpha_cutoff = float(gm.alphaCutoff);
      m.alpha_texture = m.albedo_texture;
    } else if (!gm.alphaMode.empty() && gm.alphaMode != "OPAQUE") {
      fail(where + ".alphaMode: unknown mode " + gm.alphaMode);
    }
  }

  /// Pass 2, for material i: convert_material, then passes 2a and 2b. Reads model_.materials[i];
  /// writes the material to scene_.materials, its UV set to uv_set_of_material_, and what it has
  /// that gilt does not read to `ignored`.
  void add_material(size_t i, Ignored& ignored) {
    const tinygltf::Material& gm = model_.materials[i];
    scene::Material m = convert_material(gm, gm.name.empty() ? "material " + std::to_string(i) : gm.name);
    const std::string where = "materials[" + std::to_string(i) + "]";
    uv_set_of_material_.push_back(read_material_textures(gm, where, m, ignored.textures));
    read_alpha_mode(gm, where, m);
    // Material extensions gilt does not model are named, so that a look that differs from
    // other renderers' is explained. KHR_materials_unlit's surfaces are lit like the rest.
    for (const auto& [name, value] : gm.extensions) {
      const bool read = name == "KHR_materials_transmission" || name == "KHR_materials_ior" ||
                        name == "KHR_materials_volume" || name == "KHR_materials_emissive_strength" ||
                        (name == "KHR_materials_specular" && m.kind == scene::MaterialKind::diffuse);
      note_ignored(ignored.extensions, !read, name);
    }
    scene_.materials.push_back(std::move(m));
    note_ignored(ignored.textures, gm.occlusionTexture.index >= 0, "occlusion");
    // Extensions' textures, e.g. KHR_materials_transmission's transmissionTexture.
    for (const auto& [name, value] : gm.extensions)
      if (value.IsObject())
        for (const std::string& key : value.Keys())
          note_ignored(ignored.textures,
                       key.size() > 7 && key.compare(key.size() - 7, 7, "Texture") == 0 && value.Get(key).IsObject(),
                       name + " " + key);
  }

  /// Pass 3. Reads `ignored`; writes one warning to scene_.warnings for the textures and one for
  /// the material extensions, when there are any.
  void report_ignored(const Ignored& ignored) {
    if (!ignored.textures.empty()) {
      std::string list;
      for (const std::string& kind : ignored.textures) list += (list.empty() ? "" : ", ") + kind;
      scene_.warnings.push_back(file_ + ": these textures are ignored: " + list);
    }
    if (!ignored.extensions.empty()) {
      std::string list;
      for (const std::string& name : ignored.extensions)
        list += (list.empty() ? "" : ", ") + name + (name == "KHR_materials_unlit" ? " (its surfaces are lit)" : "");
      scene_.warnings.push_back(file_ + ": these material extensions are ignored: " + list);
    }
  }

  /// Pass 4. Reads the scenes and nodes; returns the nodes to walk from: the default scene's
  /// (the first when none is named), or without scenes every node that is nobody's child.
  /// Fails when the default scene does not exist.
  std::vector<int> scene_roots() const {
    std::vector<int> roots;
    if (!model_.scenes.empty()) {
      const int s = model_.defaultScene >= 0 ? model_.defaultScene : 0;
      if (size_t(s) >= model_.scenes.size()) fail("default scene " + std::to_string(s) + " does not exist");
      roots = model_.scenes[size_t(s)].nodes;
    } else {  // no scenes: every node that is nobody's child is a root
      std::vector<bool> is_child(model_.nodes.size(), false);
      for (const tinygltf::Node& node : model_.nodes)
        for (int c : node.children)
          if (c >= 0 && size_t(c) < is_child.size()) is_child[size_t(c)] = true;
      for (size_t i = 0; i < model_.nodes.size(); ++i)
        if (!is_child[i]) roots.push_back(int(i));
    }
    return roots;
  }

  /// The reference a base colour textureInfo (at JSON path `where`) makes, or an invalid one when
  /// its image cannot be had; `uv_set` is set to the TEXCOORD set it reads.
  scene::TextureRef texture_ref(const tinygltf::TextureInfo& info, const std::string& where, int& uv_set, bool srgb) {
    if (size_t(info.index) >= model_.textures.size())
      fail(where + ".index: texture " + std::to_string(info.index) + " does not exist");
    uv_set = info.texCoord;
    scene::TextureRef ref;
    const tinygltf::Value& transform = extension(info.extensions, "KHR_texture_transform");
    if (transform.IsObject())
      ref.map = texture_transform(transform, where + ".extensions.KHR_texture_transform", uv_set);
    if (uv_set < 0) fail(where + ".texCoord: must not be negative");

    const std::string texture_where = "textures[" + std::to_string(info.index) + "]";
    const tinygltf::Texture& texture = model_.textures[size_t(info.index)];
    if (texture.source < 0) {  // e.g. only a KHR_texture_basisu or EXT_texture_webp source
      if (std::find(sourceless_.begin(), sourceless_.end(), info.index) == sourceless_.end()) {
        sourceless_.push_back(info.index);
        scene_.warnings.push_back(file_ + ": " + texture_where +
                                  " has no image gilt can read; its materials are untextured");
      }
      return scene::TextureRef{};
    }
    if (size_t(texture.source) >= model_.images.size())
      fail(texture_where + ".source: image " + std::to_string(texture.source) + " does not exist");
    scene::TextureImage image;
    image.file = image_file(texture.source);
    if (image.file.empty()) return scene::TextureRef{};
    image.srgb = srgb;  // glTF stores colours (base, emissive) sRGB-encoded, data linear
    if (texture.sampler >= 0) {
      if (size_t(texture.sampler) >= model_.samplers.size())
        fail(texture_where + ".sampler: sampler " + std::to_string(texture.sampler) + " does not exist");
      const tinygltf::Sampler& sampler = model_.samplers[size_t(texture.sampler)];
      const std::string sampler_where = "samplers[" + std::to_string(texture.sampler) + "]";
      if (!wrap_mode(sampler.wrapS, image.wrap_s))
        fail(sampler_where + ".wrapS: unknown wrap mode " + std::to_string(sampler.wrapS));
      if (!wrap_mode(sampler.wrapT, image.wrap_t))
        fail(sampler_where + ".wrapT: unknown wrap mode " + std::to_string(sampler.wrapT));
    }
    // Textures sharing a file and wrap modes share one opened image (the Cesium truck's body and
    // wheels read one atlas through two textures).
    for (size_t i = 0; i < scene_.textures.size() && !ref.valid(); ++i) {
      const scene::TextureImage& t = scene_.textures[i];
      if (t.file == image.file && t.srgb == image.srgb && t.wrap_s == image.wrap_s &&
          t.wrap_t == image.wrap_t)
        ref.image = int32_t(i);
    }
    if (!ref.valid()) {
      ref.image = int32_t(scene_.textures.size());
      scene_.textures.push_back(std::move(image));
    }
    return ref;
  }

  /// KHR_texture_transform as the affine map from UV to (s, t): offset · rotation · scale. The
  /// rotation turns UVs counter-clockwise as seen in UV space, whose v axis points down:
  ///   s =  cos r · sx u + sin r · sy v + ox
  ///   t = −sin r · sx u + cos r · sy v + oy
  /// This is the extension's own example (offset [0, 1], rotation π/2, scale 0.5 reads the
  /// image's lower-left quadrant turned a quarter clockwise) and what its sample model and the
  /// common viewers do. (The README's GLSL listing, read as column-major, is the transpose; that
  /// listing is the known erratum, KhronosGroup/glTF#1563.) A texCoord given here overrides the
  /// textureInfo's.
  std::array<float, 6> texture_transform(const tinygltf::Value& t, const std::string& where,
                                         int& uv_set) const {
    const auto pair = [&](const char* key, double fallback) -> std::array<double, 2> {
      if (!t.Has(key)) return {fallback, fallback};
      const tinygltf::Value& v = t.Get(key);
      if (!v.IsArray() || v.ArrayLen() != 2 || !v.Get(0).IsNumber() || !v.Get(1).IsNumber())
        fail(where + "." + key + ": expected an array of two numbers");
      return {v.Get(0).GetNumberAsDouble(), v.Get(1).GetNumberAsDouble()};
    };
    const std::array<double, 2> offset = pair("offset", 0.0), scale = pair("scale", 1.0);
    double rotation = 0.0;
    if (t.Has("rotation")) {
      if (!t.Get("rotation").IsNumber()) fail(where + ".rotation: expected a number");
      rotation = t.Get("rotation").GetNumberAsDouble();
    }
    if (t.Has("texCoord")) {
      const tinygltf::Value& v = t.Get("texCoord");
      if (!v.IsNumber() || v.GetNumberAsDouble() != std::floor(v.GetNumberAsDouble()) ||
          v.GetNumberAsDouble() < 0.0 || v.GetNumberAsDouble() > 1e6)
        fail(where + ".texCoord: expected a non-negative integer");
      uv_set = int(v.GetNumberAsDouble());
    }
    const double c = std::cos(rotation), s = std::sin(rotation);
    const std::array<float, 6> map{float(c * scale[0]),  float(s * scale[1]), float(offset[0]),
                                   float(-s * scale[0]), float(c * scale[1]), float(offset[1])};
    for (float x : map)
      if (!std::isfinite(x)) fail(where + ": offset, rotation and scale must be finite");
    return map;
  }

  /// The file of glTF image `index` (checked by the caller), resolved on first use; empty, with a
  /// warning the first time, when there is none.
  const std::string& image_file(int index) {
    ImageFile& out = image_files_[size_t(index)];
    if (out.resolved) return out.path;
    out.resolved = true;
    const tinygltf::Image& image = model_.images[size_t(index)];
    const std::string where = "images[" + std::to_string(index) + "]";
    const auto unusable = [&](const std::string& why) -> const std::string& {
      scene_.warnings.push_back(file_ + ": " + where + ": " + why + "; materials using it are untextured");
      return out.path;
    };
    if (image.bufferView >= 0) {
      if (size_t(image.bufferView) >= model_.bufferViews.size())
        fail(where + ".bufferView: buffer view " + std::to_string(image.bufferView) + " does not exist");
      const tinygltf::BufferView& view = model_.bufferViews[size_t(image.bufferView)];
      if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
        fail(where + ".bufferView: buffer view has no buffer");
      const std::vector<unsigned char>& buffer = model_.buffers[size_t(view.buffer)].data;
      if (view.byteOffset > buffer.size() || view.byteLength > buffer.size() - view.byteOffset)
        fail(where + ".bufferView: reaches past the end of its buffer");
      if (view.byteLength == 0) return unusable("empty buffer view");
      out.path = cached_image(buffer.data() + view.byteOffset, view.byteLength, image.mimeType, where);
      if (out.path.empty()) return unusable("image of unknown type (mimeType '" + image.mimeType + "')");
      return out.path;
    }
    if (image.as_is && !image.image.empty()) {  // a data: URI, decoded by tinygltf
      out.path = cached_image(image.image.data(), image.image.size(), image.mimeType, where);
      if (out.path.empty()) return unusable("embedded image of unknown type");
      return out.path;
    }
    if (image.uri.rfind("data:", 0) == 0)  // a data: URI of a type tinygltf does not take, e.g. image/webp
      return unusable("data URI of a type gilt cannot read ('" + image.uri.substr(0, image.uri.find(',')) +
                      "')");
    if (image.uri.empty()) return unusable("no uri and no buffer view");
    const fs::path relative = percent_decode(image.uri);
    const fs::path path = relative.is_absolute() ? relative : fs::path(file_).parent_path() / relative;
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) return unusable("no image file '" + path.string() + "'");
    out.path = path.string();
    return out.path;
  }

  /// An embedded image's encoded bytes as a file in the texture cache folder, named by content,
  /// so one image is written once however often it is loaded. Empty when its type is unknown.
  std::string cached_image(const unsigned char* bytes, size_t size, const std::string& mime_type,
                           const std::string& where) const {
    const std::string ext = image_extension(mime_type, bytes, size);
    if (ext.empty()) return {};
    char name[64];
    std::snprintf(name, sizeof name, "gltf-%016llx-%zu",
                  static_cast<unsigned long long>(content_hash(bytes, size)), size);
    const fs::path folder = scene::texture_cache_folder();
    const fs::path target = folder / (name + ext);
    if (file_holds(target, bytes, size)) return target.string();
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec) fail(where + ": texture cache folder " + folder.string() + " cannot be made: " + ec.message());
    // Written under a name of this process and call, then renamed into place: a reader (another
    // process loading the same model) never sees a half-written image, and two writers of the
    // same one do not collide.
    static std::atomic<unsigned> counter{0};
    const fs::path partial =
        folder / (std::string(name) + ".part" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    {
      std::ofstream file(partial, std::ios::binary | std::ios::trunc);
      file.write(reinterpret_cast<const char*>(bytes), std::streamsize(size));
      file.close();
      if (!file) {
        fs::remove(partial, ec);
        fail(where + ": texture cache file " + partial.string() + " cannot be written");
      }
    }
    fs::rename(partial, target, ec);
    if (ec) {
      const std::string why = ec.message();
      fs::remove(partial, ec);
      fail(where + ": texture cache file " + target.string() + " cannot be written: " + why);
    }
    return target.string();
  }

  static glm::mat4 local_transform(const tinygltf::Node& node) {
    glm::mat4 m(1.0f);
    if (node.matrix.size() == 16) {
      for (int i = 0; i < 16; ++i) m[i / 4][i % 4] = float(node.matrix[size_t(i)]);  // column-major
      return m;
    }
    if (node.translation.size() == 3)
      m[3] =
          glm::vec4(float(node.translation[0]), float(node.translation[1]), float(node.translation[2]), 1.0f);
    if (node.rotation.size() == 4) {
      const glm::quat q(float(node.rotation[3]), float(node.rotation[0]), float(node.rotation[1]),
                        float(node.rotation[2]));
      m = m * glm::mat4_cast(glm::normalize(q));
    }
    if (node.scale.size() == 3)
      m = m * glm::mat4(glm::vec4(float(node.scale[0]), 0, 0, 0), glm::vec4(0, float(node.scale[1]), 0, 0),
                        glm::vec4(0, 0, float(node.scale[2]), 0), glm::vec4(0, 0, 0, 1));
    return m;
  }

  void visit(int index, const glm::mat4& parent) {
    if (index < 0 || size_t(index) >= model_.nodes.size())
      fail("node " + std::to_string(index) + " does not exist");
    if (on_path_[size_t(index)]) fail("node " + std::to_string(index) + " is its own ancestor");
    on_path_[size_t(index)] = true;
    const tinygltf::Node& node = model_.nodes[size_t(index)];
    const glm::mat4 world = parent * local_transform(node);
    if (node.mesh >= 0) {
      if (size_t(node.mesh) >= model_.meshes.size())
        fail("node " + std::to_string(index) + ": no mesh " + std::to_string(node.mesh));
      const tinygltf::Mesh& mesh = model_.meshes[size_t(node.mesh)];
      const std::string name = mesh.name.empty() ? "mesh" + std::to_string(node.mesh) : mesh.name;
      for (size_t p = 0; p < mesh.primitives.size(); ++p) {
        const size_t before = scene_.meshes.size();
        add_primitive(mesh.primitives[p], world, name + "#" + std::to_string(p),
                      "mesh '" + name + "' primitive " + std::to_string(p));
        if (scene_.meshes.size() > before) {
          scene::MeshOrigin& origin = scene_.meshes.back().origin;
          origin.file = file_index_;
          origin.node = index;
          origin.mesh = node.mesh;
          origin.primitive = int32_t(p);
        }
      }
    }
    if (node.camera >= 0) add_camera(node.camera, node.name, world);
    const tinygltf::Value& light = extension(node.extensions, "KHR_lights_punctual");
    if (light.IsObject() && light.Has("light")) add_light(light.Get("light").GetNumberAsInt(), world);
    for (int child : node.children) visit(child, world);
    on_path_[size_t(index)] = false;
  }

  /// Checked view of an accessor's elements: base pointer and byte stride.
  const unsigned char* elements(int index, const std::string& what, size_t& stride) const {
    if (index < 0 || size_t(index) >= model_.accessors.size())
      fail(what + ": accessor " + std::to_string(index) + " does not exist");
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    if (a.sparse.isSparse) fail(what + ": sparse accessors are not supported");
    if (a.bufferView < 0 || size_t(a.bufferView) >= model_.bufferViews.size())
      fail(what + ": accessor has no buffer view");
    const tinygltf::BufferView& view = model_.bufferViews[size_t(a.bufferView)];
    if (view.buffer < 0 || size_t(view.buffer) >= model_.buffers.size())
      fail(what + ": buffer view has no buffer");
    const size_t buffer_size = model_.buffers[size_t(view.buffer)].data.size();
    const int component = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
    const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
    if (component <= 0 || components <= 0) fail(what + ": unknown accessor component type or type");
    const size_t element = size_t(component) * size_t(components);
    stride = view.byteStride != 0 ? view.byteStride : element;
    const bool fits = view.byteOffset <= buffer_size && view.byteLength <= buffer_size - view.byteOffset &&
                      stride >= element && a.byteOffset <= view.byteLength &&
                      (a.count == 0 || (a.count - 1 <= (view.byteLength - a.byteOffset) / stride &&
                                        a.byteOffset + (a.count - 1) * stride + element <= view.byteLength));
    if (!fits) fail(what + ": accessor " + std::to_string(index) + " reaches past the end of its buffer");
    return model_.buffers[size_t(view.buffer)].data.data() + view.byteOffset + a.byteOffset;
  }

  template <int N>
  std::vector<glm::vec<N, float>> read_floats(int index, const std::string& what) const {
    size_t stride = 0;
    const unsigned char* data = elements(index, what, stride);
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT ||
        a.type != (N == 2 ? TINYGLTF_TYPE_VEC2 : N == 3 ? TINYGLTF_TYPE_VEC3 : TINYGLTF_TYPE_VEC4))
      fail(what + ": expected float VEC" + std::to_string(N) + ", not component type " +
           std::to_string(a.componentType) + " of type " + std::to_string(a.type));
    std::vector<glm::vec<N, float>> out(a.count);
    for (size_t i = 0; i < a.count; ++i) std::memcpy(&out[i][0], data + i * stride, sizeof(float) * N);
    return out;
  }

  /// Texture coordinates: float, or normalized unsigned byte or short scaled to [0, 1] (the
  /// three component types glTF allows for TEXCOORD_n). Empty for anything else.
  std::vector<Vec2> read_uvs(int index, const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size()) return {};
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    if (a.type != TINYGLTF_TYPE_VEC2) return {};
    if (a.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) return read_floats<2>(index, what);
    const bool byte = a.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
    if (!a.normalized || (!byte && a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT)) return {};
    size_t stride = 0;
    const unsigned char* data = elements(index, what, stride);
    std::vector<Vec2> out(a.count);
    for (size_t i = 0; i < a.count; ++i) {
      const unsigned char* p = data + i * stride;
      if (byte) {
        out[i] = Vec2(float(p[0]) / 255.0f, float(p[1]) / 255.0f);
      } else {
        uint16_t v[2];
        std::memcpy(v, p, sizeof v);
        out[i] = Vec2(float(v[0]) / 65535.0f, float(v[1]) / 65535.0f);
      }
    }
    return out;
  }

  std::vector<uint32_t> read_indices(int index, const std::string& what) const {
    size_t stride = 0;
    const unsigned char* data = elements(index, what, stride);
    const tinygltf::Accessor& a = model_.accessors[size_t(index)];
    if (a.type != TINYGLTF_TYPE_SCALAR) fail(what + ": indices must be scalars");
    std::vector<uint32_t> out(a.count);
    for (size_t i = 0; i < a.count; ++i) {
      const unsigned char* p = data + i * stride;
      switch (a.componentType) {
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
          out[i] = *p;
          break;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
          uint16_t v;
          std::memcpy(&v, p, sizeof v);
          out[i] = v;
          break;
        }
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
          std::memcpy(&out[i], p, sizeof(uint32_t));
          break;
        default:
          fail(what + ": indices must be unsigned byte, short or int, not component type " +
               std::to_string(a.componentType));
      }
    }
    return out;
  }

  uint32_t material_for(int index, const std::string& what) {
    if (index >= 0) {
      if (size_t(index) >= model_.materials.size())
        fail(what + ": material " + std::to_string(index) + " does not exist");
      return first_material_ + uint32_t(index);
    }
    if (default_material_ < 0) {  // glTF's default (white metal) would be a perfect reflector; use grey
      default_material_ = int(scene_.materials.size());
      scene_.materials.push_back(scene::Material::make_diffuse("default", Rgb(0.8f)));
    }
    return uint32_t(default_material_);
  }

  void add_primitive(const tinygltf::Primitive& prim, const glm::mat4& world, const std::string& name,
                     const std::string& what) {
    const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
    if (mode < TINYGLTF_MODE_TRIANGLES) {
      scene_.warnings.push_back(file_ + ": " + what + ": points and lines are skipped");
      return;
    }
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN) fail(what + ": unknown primitive mode " + std::to_string(mode));
    const auto position = prim.attributes.find("POSITION");
    if (position == prim.attributes.end()) fail(what + ": no POSITION attribute");
    scene::TriangleMesh mesh;
    mesh.name = name;
    mesh.positions = read_floats<3>(position->second, what + " POSITION");
    const size_t n = mesh.positions.size();
    if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      mesh.normals = read_floats<3>(it->second, what + " NORMAL");
      if (mesh.normals.size() != n) fail(what + ": NORMAL and POSITION counts differ");
    }
    // The UV set the material's base colour texture reads (TEXCOORD_0 when it has none).
    const int uv_set = prim.material >= 0 && size_t(prim.material) < uv_set_of_material_.size()
                           ? uv_set_of_material_[size_t(prim.material)]
                           : 0;
    const std::string uv_name = "TEXCOORD_" + std::to_string(uv_set);
    if (const auto it = prim.attributes.find(uv_name); it != prim.attributes.end()) {
      mesh.uvs = read_uvs(it->second, what + " " + uv_name);
      if (mesh.uvs.size() != n) {
        mesh.uvs.clear();
        scene_.warnings.push_back(
            file_ + ": " + what + ": " + uv_name +
            " is not float or normalized unsigned byte or short VEC2 per vertex; dropped");
      }
    } else if (uv_set != 0) {
      scene_.warnings.push_back(file_ + ": " + what + ": has no " + uv_name +
                                ", which its material's base colour texture reads");
    }
    std::vector<uint32_t> corners(n);
    if (prim.indices >= 0) {
      corners = read_indices(prim.indices, what + " indices");
    } else {
      for (size_t i = 0; i < n; ++i) corners[i] = uint32_t(i);
    }
    for (uint32_t c : corners)
      if (c >= n)
        fail(what + ": index " + std::to_string(c) + " refers past the " + std::to_string(n) + " vertices");
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      if (corners.size() % 3 != 0)
        fail(what + ": index count " + std::to_string(corners.size()) + " is not a multiple of 3");
      mesh.indices = std::move(corners);
    } else {
      for (size_t i = 0; i + 2 < corners.size(); ++i) {
        if (mode == TINYGLTF_MODE_TRIANGLE_FAN)
          mesh.indices.insert(mesh.indices.end(), {corners[0], corners[i + 1], corners[i + 2]});
        else  // strip: every other triangle swaps two corners to keep the winding
          mesh.indices.insert(mesh.indices.end(),
                              {corners[i], corners[i + 1 + i % 2], corners[i + 2 - i % 2]});
      }
    }
    mesh.material = material_for(prim.material, what);
    // The file's tangents serve the normal texture when it reads the UVs as they are (a
    // KHR_texture_transform would turn the frame they were made in); else commit() makes them.
    if (const auto it = prim.attributes.find("TANGENT"); it != prim.attributes.end() && !mesh.uvs.empty()) {
      const scene::TextureRef& normal = scene_.materials[mesh.material].normal_texture;
      if (normal.valid() && normal.map == scene::TextureRef{}.map) {
        mesh.tangents = read_floats<4>(it->second, what + " TANGENT");
        if (mesh.tangents.size() != n) fail(what + ": TANGENT and POSITION counts differ");
      }
    }
    transform_mesh(mesh, world);
    scene_.meshes.push_back(std::move(mesh));
  }

  void add_camera(int index, const std::string& node_name, const glm::mat4& world) {
    if (size_t(index) >= model_.cameras.size()) fail("camera " + std::to_string(index) + " does not exist");
    const tinygltf::Camera& c = model_.cameras[size_t(index)];
    const std::string what = file_ + ": camera " + std::to_string(index);
    // A glTF camera looks down its node's −z with +y up.
    const Vec3 forward(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
    const Vec3 up(world * glm::vec4(0.0f, 1.0f, 0.0f, 0.0f));
    if (!(glm::length(forward) > 0.0f) || !(glm::length(up) > 0.0f))
      fail("camera node has a singular transform");
    scene::NamedCamera named;
    named.name = !c.name.empty() ? c.name : !node_name.empty() ? node_name : "camera " + std::to_string(scene_.cameras.size());
    scene::Camera& camera = named.camera;
    camera.look_from = Vec3(world[3]);
    camera.look_at = camera.look_from + glm::normalize(forward);
    camera.up = glm::normalize(up);
    if (c.type == "perspective") {
      camera.vfov_degrees = float(c.perspective.yfov * 180.0 / kPi);
      if (c.perspective.aspectRatio > 0.0) named.aspect = float(c.perspective.aspectRatio);
    } else if (c.type == "orthographic") {
      // ymag and xmag are half the view's height and width, in the node's units.
      camera.orthographic = true;
      camera.ortho_height = float(2.0 * std::abs(c.orthographic.ymag)) * glm::length(up);
      if (c.orthographic.ymag != 0.0 && c.orthographic.xmag != 0.0)
        named.aspect = float(std::abs(c.orthographic.xmag / c.orthographic.ymag));
    } else {
      scene_.warnings.push_back(what + " of unknown type '" + c.type + "' ignored");
      return;
    }
    try {
      camera.validate();
    } catch (const InputError& e) {
      scene_.warnings.push_back(what + " ('" + named.name + "') ignored: " + e.what());
      return;
    }
    scene_.cameras.push_back(named);
    if (scene_.camera) return;  // the first camera frames the scene
    scene_.camera = camera;
    if (named.aspect > 0.0f) scene_.render.width = std::max(1, int(std::lround(scene_.render.height * named.aspect)));
  }

  void add_light(int index, const glm::mat4& world) {
    if (index < 0 || size_t(index) >= model_.lights.size())
      fail("KHR_lights_punctual light " + std::to_string(index) + " does not exist");
    const tinygltf::Light& gl = model_.lights[size_t(index)];
    const Rgb value = rgb_or(gl.color, Rgb(1.0f)) * float(gl.intensity);
    scene::Light light;
    light.position = Vec3(world[3]);
    const Vec3 axis(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));  // lights shine down the node's −z
    light.direction = glm::length(axis) > 0.0f ? glm::normalize(axis) : axis;
    if (gl.type == "point") {
      light.kind = scene::LightKind::point;
      light.intensity = value;
    } else if (gl.type == "spot") {
      light.kind = scene::LightKind::spot;
      light.intensity = value;
      light.cos_inner = float(std::cos(gl.spot.innerConeAngle));
      light.cos_outer = float(std::cos(gl.spot.outerConeAngle));
    } else if (gl.type == "directional") {
      light.kind = scene::LightKind::directional;
      light.irradiance = value;
    } else {
      scene_.warnings.push_back(file_ + ": light " + std::to_string(index) + " of unknown type '" + gl.type +
                                "' ignored");
      return;
    }
    if (gl.range > 0.0) scene_.warnings.push_back(file_ + ": light range ignored (inverse-square falloff)");
    scene_.punctual_lights.push_back(light);
  }

  const tinygltf::Model& model_;
  std::string file_;
  scene::Scene& scene_;
  std::vector<bool> on_path_;  // nodes on the current root-to-node path, to catch cycles
  uint32_t first_material_ = 0;
  std::vector<int> uv_set_of_material_;  // TEXCOORD set each glTF material's base colour texture reads
  std::vector<ImageFile> image_files_;   // per glTF image, resolved on first use
  std::vector<int> sourceless_;          // textures without an image, warned about already
  int default_material_ = -1;
  int32_t file_index_ = -1;
};


}  // namespace

void load_gltf(const fs::path& path, scene::Scene& scene) {
  const std::string file = path.string();
  const tinygltf::Model model = read_gltf_file(file, &scene.warnings);
  GltfLoader(model, file, scene).load();
}

}  // namespace gilt::raytrace_core::io
