// glTF 2.0 (.gltf and .glb) through tinygltf: the node hierarchy of the default scene with its
// transforms, triangle primitives, materials, the first perspective camera and
// KHR_lights_punctual lights. Textures, skins, morph targets and animations are ignored.
//
// Material mapping (documented in docs/scene-format.md); base = baseColorFactor.rgb,
// m = metallicFactor, r = roughnessFactor:
//   KHR_materials_transmission factor > 0.5 → dielectric, ior from KHR_materials_ior (1.5),
//       σa = −ln(attenuationColor) / attenuationDistance from KHR_materials_volume
//   m ≥ 0.9 and r ≤ 0.1                     → mirror, reflectance base
//   r ≥ 0.9                                 → diffuse, albedo base
//   otherwise                               → glossy: albedo 0.96·(1 − m)·base,
//       specular 0.04·(1 − m) + m·base, Phong exponent 2/α² − 2 with α = r² (the Beckmann–Phong
//       correspondence of Walter et al. 2007, "Microfacet Models for Refraction"), clamped to
//       [1, 10⁴]
//   emission = emissiveFactor × KHR_materials_emissive_strength; doubleSided → two-sided emission
// Photometric light units are read as radiometric: point/spot intensity (cd) as W·sr⁻¹,
// directional illuminance (lx) as W·m⁻², i.e. no 683 lm/W factor.

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <tiny_gltf.h>

#include "raytrace_core/io/gltf_file.h"
#include <glm/gtc/quaternion.hpp>

#include "raytrace_core/error.h"
#include "raytrace_core/io/loaders.h"

namespace gilt::raytrace_core {

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

Material convert_material(const tinygltf::Material& gm, const std::string& name) {
  const tinygltf::PbrMetallicRoughness& pbr = gm.pbrMetallicRoughness;
  const Rgb base = clamp(rgb_or(pbr.baseColorFactor, Rgb(1.0f)), 0.0f, 1.0f);
  const float metallic = std::clamp(float(pbr.metallicFactor), 0.0f, 1.0f);
  const float roughness = std::clamp(float(pbr.roughnessFactor), 0.0f, 1.0f);
  const double transmission =
      number_or(extension(gm.extensions, "KHR_materials_transmission"), "transmissionFactor", 0.0);

  Material m;
  if (transmission > 0.5) {
    const float ior = float(number_or(extension(gm.extensions, "KHR_materials_ior"), "ior", 1.5));
    Rgb absorption(0.0f);
    const tinygltf::Value& volume = extension(gm.extensions, "KHR_materials_volume");
    const double distance = number_or(volume, "attenuationDistance", 0.0);
    if (distance > 0.0 && volume.Has("attenuationColor") && volume.Get("attenuationColor").ArrayLen() == 3) {
      const tinygltf::Value& color = volume.Get("attenuationColor");
      for (int c = 0; c < 3; ++c)
        absorption[c] = float(-std::log(std::clamp(color.Get(c).GetNumberAsDouble(), 1e-4, 1.0)) / distance);
    }
    m = Material::make_dielectric(name, ior, absorption);
  } else if (metallic >= 0.9f && roughness <= 0.1f) {
    m = Material::make_mirror(name, base);
  } else if (roughness >= 0.9f) {
    m = Material::make_diffuse(name, base);
  } else {
    const float alpha = roughness * roughness;
    const float exponent = std::clamp(2.0f / (alpha * alpha) - 2.0f, 1.0f, 1e4f);
    m = Material::make_glossy(name, base * (0.96f * (1.0f - metallic)),
                              Rgb(0.04f * (1.0f - metallic)) + base * metallic, exponent);
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
  GltfLoader(const tinygltf::Model& model, std::string file, Scene& scene)
      : model_(model), file_(std::move(file)), scene_(scene), on_path_(model.nodes.size(), false) {}

  void load() {
    // Extensions a file cannot be read without (e.g. Draco compression, quantized attributes).
    for (const std::string& required : model_.extensionsRequired)
      if (required != "KHR_lights_punctual" && required.rfind("KHR_materials_", 0) != 0 &&
          required != "KHR_texture_transform")
        fail("requires extension " + required + ", which gilt does not support");
    first_material_ = static_cast<uint32_t>(scene_.materials.size());
    file_index_ = int32_t(scene_.model_files.size());
    scene_.model_files.push_back(file_);
    bool textures = false;
    for (size_t i = 0; i < model_.materials.size(); ++i) {
      const tinygltf::Material& gm = model_.materials[i];
      scene_.materials.push_back(
          convert_material(gm, gm.name.empty() ? "material " + std::to_string(i) : gm.name));
      textures = textures || gm.pbrMetallicRoughness.baseColorTexture.index >= 0 ||
                 gm.emissiveTexture.index >= 0 || gm.normalTexture.index >= 0 ||
                 gm.pbrMetallicRoughness.metallicRoughnessTexture.index >= 0;
    }
    if (textures) scene_.warnings.push_back(file_ + ": textures are ignored");

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
    for (int root : roots) visit(root, glm::mat4(1.0f));
    if (scene_.meshes.empty()) scene_.warnings.push_back(file_ + ": no triangles");
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file_ + ": " + what); }

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
          MeshOrigin& origin = scene_.meshes.back().origin;
          origin.file = file_index_;
          origin.node = index;
          origin.mesh = node.mesh;
          origin.primitive = int32_t(p);
        }
      }
    }
    if (node.camera >= 0) add_camera(node.camera, world);
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
        a.type != (N == 2 ? TINYGLTF_TYPE_VEC2 : TINYGLTF_TYPE_VEC3))
      fail(what + ": expected float VEC" + std::to_string(N) + ", not component type " +
           std::to_string(a.componentType) + " of type " + std::to_string(a.type));
    std::vector<glm::vec<N, float>> out(a.count);
    for (size_t i = 0; i < a.count; ++i) std::memcpy(&out[i][0], data + i * stride, sizeof(float) * N);
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
      scene_.materials.push_back(Material::make_diffuse("default", Rgb(0.8f)));
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
    TriangleMesh mesh;
    mesh.name = name;
    mesh.positions = read_floats<3>(position->second, what + " POSITION");
    const size_t n = mesh.positions.size();
    if (const auto it = prim.attributes.find("NORMAL"); it != prim.attributes.end()) {
      mesh.normals = read_floats<3>(it->second, what + " NORMAL");
      if (mesh.normals.size() != n) fail(what + ": NORMAL and POSITION counts differ");
    }
    if (const auto it = prim.attributes.find("TEXCOORD_0"); it != prim.attributes.end()) {
      const bool is_float =
          it->second >= 0 && size_t(it->second) < model_.accessors.size() &&
          model_.accessors[size_t(it->second)].componentType == TINYGLTF_COMPONENT_TYPE_FLOAT;
      if (is_float) mesh.uvs = read_floats<2>(it->second, what + " TEXCOORD_0");
      if (mesh.uvs.size() != n) {
        mesh.uvs.clear();
        scene_.warnings.push_back(file_ + ": " + what + ": TEXCOORD_0 is not float VEC2 per vertex; dropped");
      }
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
    transform_mesh(mesh, world);
    scene_.meshes.push_back(std::move(mesh));
  }

  void add_camera(int index, const glm::mat4& world) {
    if (camera_done_) return;
    if (size_t(index) >= model_.cameras.size()) fail("camera " + std::to_string(index) + " does not exist");
    const tinygltf::Camera& c = model_.cameras[size_t(index)];
    if (c.type != "perspective") {
      scene_.warnings.push_back(file_ + ": camera " + std::to_string(index) + " is not perspective; ignored");
      return;
    }
    // A glTF camera looks down its node's −z with +y up.
    const Vec3 forward(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
    const Vec3 up(world * glm::vec4(0.0f, 1.0f, 0.0f, 0.0f));
    if (!(glm::length(forward) > 0.0f) || !(glm::length(up) > 0.0f))
      fail("camera node has a singular transform");
    Camera camera;
    camera.look_from = Vec3(world[3]);
    camera.look_at = camera.look_from + glm::normalize(forward);
    camera.up = glm::normalize(up);
    camera.vfov_degrees = float(c.perspective.yfov * 180.0 / kPi);
    if (c.perspective.aspectRatio > 0.0)
      scene_.render.width = std::max(1, int(std::lround(scene_.render.height * c.perspective.aspectRatio)));
    scene_.camera = camera;
    camera_done_ = true;
  }

  void add_light(int index, const glm::mat4& world) {
    if (index < 0 || size_t(index) >= model_.lights.size())
      fail("KHR_lights_punctual light " + std::to_string(index) + " does not exist");
    const tinygltf::Light& gl = model_.lights[size_t(index)];
    const Rgb value = rgb_or(gl.color, Rgb(1.0f)) * float(gl.intensity);
    Light light;
    light.position = Vec3(world[3]);
    const Vec3 axis(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));  // lights shine down the node's −z
    light.direction = glm::length(axis) > 0.0f ? glm::normalize(axis) : axis;
    if (gl.type == "point") {
      light.kind = LightKind::point;
      light.intensity = value;
    } else if (gl.type == "spot") {
      light.kind = LightKind::spot;
      light.intensity = value;
      light.cos_inner = float(std::cos(gl.spot.innerConeAngle));
      light.cos_outer = float(std::cos(gl.spot.outerConeAngle));
    } else if (gl.type == "directional") {
      light.kind = LightKind::directional;
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
  Scene& scene_;
  std::vector<bool> on_path_;  // nodes on the current root-to-node path, to catch cycles
  uint32_t first_material_ = 0;
  int default_material_ = -1;
  int32_t file_index_ = -1;
  bool camera_done_ = false;
};


}  // namespace

void load_gltf(const fs::path& path, Scene& scene) {
  const std::string file = path.string();
  const tinygltf::Model model = read_gltf_file(file, &scene.warnings);
  GltfLoader(model, file, scene).load();
}

}  // namespace gilt::raytrace_core
