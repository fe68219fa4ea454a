// gilt's own JSON scene format (docs/scene-format.md) through nlohmann::json. Mesh files are
// loaded relative to the scene file. Every error names the file and the JSON pointer of the
// field, e.g. "scene.json: /materials/glass/ior: expected a number"; unknown fields are warnings.

#include <fstream>
#include <initializer_list>
#include <map>
#include <optional>
#include <sstream>
#include <string>

#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::raytrace_core::io {

namespace fs = std::filesystem;

namespace {

using Json = nlohmann::ordered_json;

/// `pointer` extended by one object key, escaped as RFC 6901 asks.
std::string at(const std::string& pointer, const std::string& key) {
  std::string token;
  for (char c : key) token += c == '~' ? "~0" : (c == '/' ? "~1" : std::string(1, c));
  return pointer + "/" + token;
}
std::string at(const std::string& pointer, size_t index) { return pointer + "/" + std::to_string(index); }

class JsonSceneReader {
 public:
  JsonSceneReader(const fs::path& path, scene::Scene& scene)
      : path_(path), file_(path.string()), scene_(scene) {}

  void read(const Json& root) {
    object(root, "", {"materials", "meshes", "shapes", "lights", "camera", "render"});
    own_camera_ = root.contains("camera");
    if (const Json* j = field(root, "materials")) read_materials(*j);
    if (const Json* j = field(root, "meshes"))
      for_each(*j, "/meshes", [&](const Json& e, const std::string& p) { read_mesh(e, p); });
    if (const Json* j = field(root, "shapes"))
      for_each(*j, "/shapes", [&](const Json& e, const std::string& p) { read_shape(e, p); });
    if (const Json* j = field(root, "lights"))
      for_each(*j, "/lights", [&](const Json& e, const std::string& p) { read_light(e, p); });
    if (const Json* j = field(root, "camera")) read_camera(*j);
    if (const Json* j = field(root, "render")) read_render(*j);
  }

 private:
  [[noreturn]] void fail(const std::string& pointer, const std::string& what) const {
    throw InputError(file_ + ": " + (pointer.empty() ? std::string("/") : pointer) + ": " + what);
  }

  static const Json* field(const Json& object, const char* key) {
    const auto it = object.find(key);
    return it == object.end() ? nullptr : &*it;
  }

  /// Checks `j` is an object and warns about keys outside `known`.
  void object(const Json& j, const std::string& pointer, std::initializer_list<const char*> known) {
    if (!j.is_object()) fail(pointer, "expected an object");
    for (const auto& item : j.items()) {
      bool found = false;
      for (const char* k : known) found = found || item.key() == k;
      if (!found)
        scene_.warnings.push_back(file_ + ": " + at(pointer, item.key()) + ": unknown field, ignored");
    }
  }

  template <typename F>
  void for_each(const Json& j, const std::string& pointer, F&& read_one) {
    if (!j.is_array()) fail(pointer, "expected an array");
    for (size_t i = 0; i < j.size(); ++i) read_one(j[i], at(pointer, i));
  }

  float number(const Json& j, const std::string& pointer) const {
    if (!j.is_number()) fail(pointer, "expected a number");
    const auto x = static_cast<float>(j.get<double>());
    if (!std::isfinite(x)) fail(pointer, "number out of range");
    return x;
  }
  float number(const Json& object, const char* key, const std::string& pointer, float fallback) const {
    const Json* j = field(object, key);
    return j ? number(*j, at(pointer, key)) : fallback;
  }

  Vec3 vec3(const Json& j, const std::string& pointer) const {
    if (!j.is_array() || j.size() != 3) fail(pointer, "expected an array of 3 numbers");
    return {number(j[0], at(pointer, 0)), number(j[1], at(pointer, 1)), number(j[2], at(pointer, 2))};
  }
  Vec3 vec3(const Json& object, const char* key, const std::string& pointer,
            std::optional<Vec3> fallback) const {
    const Json* j = field(object, key);
    if (!j && !fallback) fail(at(pointer, key), "missing");
    return j ? vec3(*j, at(pointer, key)) : *fallback;
  }

  /// A colour: one number (grey) or [r, g, b], each ≥ 0.
  Rgb colour(const Json& object, const char* key, const std::string& pointer,
             std::optional<Rgb> fallback) const {
    const Json* j = field(object, key);
    const std::string p = at(pointer, key);
    if (!j && !fallback) fail(p, "missing");
    if (!j) return *fallback;
    Rgb c;
    if (j->is_number()) {
      c = Rgb(number(*j, p));
    } else {
      if (!j->is_array() || j->size() != 3) fail(p, "expected a number or an array of 3 numbers");
      c = Rgb(number((*j)[0], at(p, 0)), number((*j)[1], at(p, 1)), number((*j)[2], at(p, 2)));
    }
    if (c.r < 0.0f || c.g < 0.0f || c.b < 0.0f) fail(p, "must not be negative");
    return c;
  }
  Rgb reflectance(const Json& object, const char* key, const std::string& pointer, Rgb fallback) const {
    const Rgb c = colour(object, key, pointer, fallback);
    if (c.max_component() > 1.0f) fail(at(pointer, key), "a reflectance must lie in [0, 1]");
    return c;
  }

  std::string string(const Json& object, const char* key, const std::string& pointer) const {
    const Json* j = field(object, key);
    if (!j) fail(at(pointer, key), "missing");
    if (!j->is_string()) fail(at(pointer, key), "expected a string");
    return j->get<std::string>();
  }

  uint32_t material_ref(const Json& object, const std::string& pointer) const {
    const std::string name = string(object, "material", pointer);
    const auto it = material_index_.find(name);
    if (it == material_index_.end()) fail(at(pointer, "material"), "unknown material '" + name + "'");
    return it->second;
  }

  void read_materials(const Json& materials) {
    if (!materials.is_object()) fail("/materials", "expected an object of named materials");
    for (const auto& item : materials.items()) {
      const std::string& name = item.key();
      const Json& j = item.value();
      const std::string p = at("/materials", name);
      if (!j.is_object()) fail(p, "expected an object");
      const std::string kind = field(j, "kind") ? string(j, "kind", p) : "diffuse";
      scene::Material m;
      if (kind == "diffuse") {
        object(j, p, {"kind", "albedo", "emission", "two_sided"});
        m = scene::Material::make_diffuse(name, reflectance(j, "albedo", p, Rgb(0.8f)));
      } else if (kind == "glossy") {
        object(j, p, {"kind", "albedo", "specular", "exponent", "emission", "two_sided"});
        m = scene::Material::make_glossy(name, reflectance(j, "albedo", p, Rgb(0.5f)),
                                  reflectance(j, "specular", p, Rgb(0.3f)), number(j, "exponent", p, 100.0f));
        if (m.exponent < 0.0f) fail(at(p, "exponent"), "must not be negative");
        if ((m.albedo + m.specular).max_component() > 1.0f)
          fail(p, "albedo + specular exceeds 1: energy is not conserved");
      } else if (kind == "mirror") {
        object(j, p, {"kind", "specular", "emission", "two_sided"});
        m = scene::Material::make_mirror(name, reflectance(j, "specular", p, Rgb(1.0f)));
      } else if (kind == "dielectric") {
        object(j, p, {"kind", "ior", "absorption", "roughness", "emission", "two_sided"});
        m = scene::Material::make_dielectric(name, number(j, "ior", p, 1.5f),
                                             colour(j, "absorption", p, Rgb(0.0f)));
        m.roughness = number(j, "roughness", p, 0.0f);
        if (!(m.ior > 0.0f)) fail(at(p, "ior"), "must be positive");
        if (!(m.roughness >= 0.0f && m.roughness <= 1.0f)) fail(at(p, "roughness"), "must lie in [0, 1]");
      } else if (kind == "metallic_roughness") {
        object(j, p, {"kind", "albedo", "metallic", "roughness", "ior", "emission", "two_sided"});
        m = scene::Material::make_metallic_roughness(name, reflectance(j, "albedo", p, Rgb(0.8f)), number(j, "metallic", p, 0.0f),
                                              number(j, "roughness", p, 0.5f), number(j, "ior", p, 1.5f));
        if (!(m.metallic >= 0.0f && m.metallic <= 1.0f)) fail(at(p, "metallic"), "must lie in [0, 1]");
        if (!(m.roughness >= 0.0f && m.roughness <= 1.0f)) fail(at(p, "roughness"), "must lie in [0, 1]");
        if (!(m.ior >= 1.0f)) fail(at(p, "ior"), "must be at least 1");
      } else {
        fail(at(p, "kind"),
             "unknown kind '" + kind + "' (expected diffuse, glossy, mirror, dielectric or metallic_roughness)");
      }
      m.emission = colour(j, "emission", p, Rgb(0.0f));
      if (const Json* two_sided = field(j, "two_sided")) {
        if (!two_sided->is_boolean()) fail(at(p, "two_sided"), "expected true or false");
        m.two_sided_emission = two_sided->get<bool>();
      }
      material_index_[name] = static_cast<uint32_t>(scene_.materials.size());
      scene_.materials.push_back(std::move(m));
    }
  }

  /// {"scale": s or [sx, sy, sz], "rotate_deg_axis": [degrees, x, y, z], "translate": [x, y, z]},
  /// applied in that order.
  glm::mat4 read_transform(const Json& j, const std::string& p) {
    object(j, p, {"scale", "rotate_deg_axis", "translate"});
    glm::mat4 m(1.0f);
    m = glm::translate(m, vec3(j, "translate", p, Vec3(0.0f)));
    if (const Json* r = field(j, "rotate_deg_axis")) {
      const std::string rp = at(p, "rotate_deg_axis");
      if (!r->is_array() || r->size() != 4) fail(rp, "expected [degrees, x, y, z]");
      const Vec3 axis(number((*r)[1], at(rp, 1)), number((*r)[2], at(rp, 2)), number((*r)[3], at(rp, 3)));
      if (!(glm::length(axis) > 0.0f)) fail(rp, "the rotation axis must not be zero");
      m = glm::rotate(m, glm::radians(number((*r)[0], at(rp, 0))), glm::normalize(axis));
    }
    if (const Json* s = field(j, "scale")) {
      const Vec3 scale = s->is_number() ? Vec3(number(*s, at(p, "scale"))) : vec3(*s, at(p, "scale"));
      if (scale.x == 0.0f || scale.y == 0.0f || scale.z == 0.0f) fail(at(p, "scale"), "must not be zero");
      m = glm::scale(m, scale);
    }
    return m;
  }

  void read_mesh(const Json& j, const std::string& p) {
    object(j, p, {"file", "material", "transform"});
    const fs::path relative = string(j, "file", p);
    const fs::path mesh_path = relative.is_absolute() ? relative : path_.parent_path() / relative;
    if (lower_extension(mesh_path) == ".json") fail(at(p, "file"), "a JSON scene cannot be used as a mesh");
    std::error_code ec;
    if (!fs::is_regular_file(mesh_path, ec)) fail(at(p, "file"), "no such file '" + mesh_path.string() + "'");
    const bool override_material = field(j, "material") != nullptr;  // replaces the file's own materials
    const uint32_t material = override_material ? material_ref(j, p) : 0;
    const glm::mat4 transform =
        field(j, "transform") ? read_transform(j["transform"], at(p, "transform")) : glm::mat4(1.0f);

    scene::Scene part;
    try {
      part = load_scene_file(mesh_path.string());
    } catch (const InputError& e) {
      fail(at(p, "file"), e.what());
    }
    const auto offset = static_cast<uint32_t>(scene_.materials.size());
    if (!override_material) {
      // The file's images join the scene's, its materials' references shifted past those there.
      const auto texture_offset = int32_t(scene_.textures.size());
      for (scene::TextureImage& t : part.textures) scene_.textures.push_back(std::move(t));
      for (scene::Material& m : part.materials) {
        for (scene::TextureRef* t : m.texture_refs())
          if (t->valid()) t->image += texture_offset;
        scene_.materials.push_back(std::move(m));
      }
    }
    const auto file_offset = int32_t(scene_.model_files.size());
    for (std::string& f : part.model_files) scene_.model_files.push_back(std::move(f));
    for (scene::TriangleMesh& mesh : part.meshes) {
      if (mesh.origin.file >= 0) mesh.origin.file += file_offset;
      mesh.material = override_material ? material : mesh.material + offset;
      transform_mesh(mesh, transform);
      scene_.meshes.push_back(std::move(mesh));
    }
    for (scene::Light light : part.punctual_lights) {
      light.position = Vec3(transform * glm::vec4(light.position, 1.0f));
      const Vec3 direction = glm::mat3(transform) * light.direction;
      if (glm::length(direction) > 0.0f) light.direction = glm::normalize(direction);
      scene_.punctual_lights.push_back(light);
    }
    // The first included file's camera frames the scene, moved with the file, unless the JSON has
    // its own; its image size (a glTF camera's aspect ratio) comes with it.
    // Every camera of the file is kept, moved with it, for --camera to choose from.
    const auto moved = [&transform](scene::Camera camera) {
      camera.look_from = Vec3(transform * glm::vec4(camera.look_from, 1.0f));
      camera.look_at = Vec3(transform * glm::vec4(camera.look_at, 1.0f));
      const Vec3 up = glm::mat3(transform) * camera.up;
      if (glm::length(up) > 0.0f) {
        camera.ortho_height *= glm::length(up) / std::max(glm::length(camera.up), 1e-30f);
        camera.up = glm::normalize(up);
      }
      return camera;
    };
    for (scene::NamedCamera named : part.cameras) {
      named.camera = moved(named.camera);
      scene_.cameras.push_back(std::move(named));
    }
    if (part.camera && !own_camera_ && !scene_.camera) {
      scene_.camera = moved(*part.camera);
      scene_.render = part.render;
    } else if (part.camera) {
      scene_.warnings.push_back(file_ + ": " + p + ": the camera of '" + relative.string() + "' frames nothing (" +
                                (own_camera_ ? "the scene's own" : "an earlier file's") +
                                " is used; --camera chooses another)");
    }
    // A PLY's own material is replaced by the one given here: its note about it would mislead.
    const std::string replaced = override_material ? ply_default_material_note(mesh_path.string()) : std::string();
    for (std::string& w : part.warnings)
      if (w != replaced) scene_.warnings.push_back(std::move(w));
  }

  void read_shape(const Json& j, const std::string& p) {
    if (!j.is_object()) fail(p, "expected an object");
    const std::string type = string(j, "type", p);
    if (type == "sphere") {
      object(j, p, {"type", "center", "radius", "material"});
      const float radius = number(j, "radius", p, 0.0f);
      if (!(radius > 0.0f)) fail(at(p, "radius"), "must be given and positive");
      scene_.spheres.push_back({vec3(j, "center", p, std::nullopt), radius, material_ref(j, p)});
      return;
    }
    if (type != "quad" && type != "triangle")
      fail(at(p, "type"), "unknown shape '" + type + "' (expected sphere, quad or triangle)");
    object(j, p, {"type", "vertices", "material"});
    const size_t corners = type == "quad" ? 4 : 3;
    const Json* vertices = field(j, "vertices");
    if (!vertices || !vertices->is_array() || vertices->size() != corners)
      fail(at(p, "vertices"), "expected an array of " + std::to_string(corners) +
                                  " points, counter-clockwise seen from the front");
    const uint32_t material = material_ref(j, p);
    // Quads and triangles of one material share a mesh.
    auto [it, added] = shape_mesh_of_material_.try_emplace(material, scene_.meshes.size());
    if (added) {
      scene_.meshes.emplace_back();
      scene_.meshes.back().name = "shapes:" + scene_.materials[material].name;
      scene_.meshes.back().material = material;
    }
    scene::TriangleMesh& mesh = scene_.meshes[it->second];
    const auto base = static_cast<uint32_t>(mesh.positions.size());
    for (size_t i = 0; i < corners; ++i)
      mesh.positions.push_back(vec3((*vertices)[i], at(at(p, "vertices"), i)));
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    if (corners == 4) mesh.indices.insert(mesh.indices.end(), {base, base + 2, base + 3});
  }

  void read_light(const Json& j, const std::string& p) {
    if (!j.is_object()) fail(p, "expected an object");
    const std::string type = string(j, "type", p);
    scene::Light light;
    if (type == "point") {
      object(j, p, {"type", "position", "intensity"});
      light.kind = scene::LightKind::point;
      light.position = vec3(j, "position", p, std::nullopt);
      light.intensity = colour(j, "intensity", p, std::nullopt);
    } else if (type == "spot") {
      object(j, p, {"type", "position", "direction", "intensity", "inner_angle_deg", "outer_angle_deg"});
      light.kind = scene::LightKind::spot;
      light.position = vec3(j, "position", p, std::nullopt);
      light.direction = vec3(j, "direction", p, std::nullopt);
      light.intensity = colour(j, "intensity", p, std::nullopt);
      const float inner = number(j, "inner_angle_deg", p, 0.0f),
                  outer = number(j, "outer_angle_deg", p, 45.0f);
      if (!(0.0f <= inner && inner <= outer && outer <= 90.0f))
        fail(p, "need 0 ≤ inner_angle_deg ≤ outer_angle_deg ≤ 90 (half-angles from the axis)");
      light.cos_inner = std::cos(glm::radians(inner));
      light.cos_outer = std::cos(glm::radians(outer));
    } else if (type == "directional") {
      object(j, p, {"type", "direction", "irradiance", "angular_radius_deg"});
      light.kind = scene::LightKind::directional;
      light.direction = vec3(j, "direction", p, std::nullopt);
      light.irradiance = colour(j, "irradiance", p, std::nullopt);
      // A disk rather than a point at infinity (the sun's is 0.27°): soft shadows, and seen.
      const float radius = number(j, "angular_radius_deg", p, 0.0f);
      if (!(radius >= 0.0f && radius <= 45.0f)) fail(at(p, "angular_radius_deg"), "must lie in [0, 45] degrees");
      light.cos_angle = radius > 0.0f ? std::cos(glm::radians(radius)) : 1.0f;
    } else if (type == "environment") {
      object(j, p, {"type", "radiance", "file", "scale", "rotate_deg"});
      light.kind = scene::LightKind::environment;
      if (field(j, "file")) {  // an image: its texels times `scale`, tinted by `radiance` (default 1)
        const fs::path relative = string(j, "file", p);
        const fs::path image = relative.is_absolute() ? relative : path_.parent_path() / relative;
        std::error_code ec;
        if (!fs::is_regular_file(image, ec)) fail(at(p, "file"), "no such file '" + image.string() + "'");
        const float scale = number(j, "scale", p, 1.0f), rotate = number(j, "rotate_deg", p, 0.0f);
        if (!(scale >= 0.0f)) fail(at(p, "scale"), "must not be negative");
        light.radiance = colour(j, "radiance", p, Rgb(1.0f));
        light.map = scene::EnvironmentMap::load(image.string(), scale, rotate);
      } else {
        for (const char* key : {"scale", "rotate_deg"})
          if (field(j, key)) fail(at(p, key), "needs \"file\" (an environment image)");
        light.radiance = colour(j, "radiance", p, std::nullopt);
      }
    } else {
      fail(at(p, "type"), "unknown light '" + type + "' (expected point, spot, directional or environment)");
    }
    if ((type == "spot" || type == "directional") && !(glm::length(light.direction) > 0.0f))
      fail(at(p, "direction"), "must not be zero");
    if (glm::length(light.direction) > 0.0f) light.direction = glm::normalize(light.direction);
    scene_.punctual_lights.push_back(light);
  }

  void read_camera(const Json& j) {
    const std::string p = "/camera";
    object(j, p, {"name", "look_from", "look_at", "up", "vfov", "aperture_radius", "focus_distance", "orthographic_height"});
    scene::Camera camera;
    camera.look_from = vec3(j, "look_from", p, std::nullopt);
    camera.look_at = vec3(j, "look_at", p, std::nullopt);
    camera.up = vec3(j, "up", p, Vec3(0.0f, 1.0f, 0.0f));
    camera.vfov_degrees = number(j, "vfov", p, camera.vfov_degrees);
    camera.aperture_radius = number(j, "aperture_radius", p, 0.0f);
    camera.focus_distance = number(j, "focus_distance", p, 0.0f);
    if (camera.focus_distance < 0.0f) fail(at(p, "focus_distance"), "must not be negative");
    if (j.contains("orthographic_height")) {
      camera.orthographic = true;
      camera.ortho_height = number(j, "orthographic_height", p, 0.0f);
    }
    try {
      camera.validate();
    } catch (const InputError& e) {
      fail(p, e.what());
    }
    scene_.camera = camera;
    // The scene's own camera comes first among those --camera chooses from.
    scene_.cameras.insert(scene_.cameras.begin(), scene::NamedCamera{j.contains("name") ? string(j, "name", p) : "scene", camera, 0.0f});
  }

  void read_render(const Json& j) {
    const std::string p = "/render";
    object(j, p, {"width", "height", "spp"});
    const auto positive = [&](const char* key, int fallback) {
      const Json* v = field(j, key);
      if (!v) return fallback;
      if (!v->is_number_integer() || v->get<long long>() <= 0 || v->get<long long>() > 1 << 20)
        fail(at(p, key), "expected a positive integer");
      return static_cast<int>(v->get<long long>());
    };
    scene_.render.width = positive("width", scene_.render.width);
    scene_.render.height = positive("height", scene_.render.height);
    scene_.render.spp = positive("spp", scene_.render.spp);
  }

  fs::path path_;
  std::string file_;
  bool own_camera_ = false;  // the JSON names its own camera, which wins over its files'
  scene::Scene& scene_;
  std::map<std::string, uint32_t> material_index_;
  std::map<uint32_t, size_t> shape_mesh_of_material_;
};

}  // namespace

void load_json(const fs::path& path, scene::Scene& scene) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();

  Json root;
  try {
    root = Json::parse(text, nullptr, /*allow_exceptions=*/true, /*ignore_comments=*/true);
  } catch (const Json::parse_error& e) {
    // e.byte is the 1-based offset where parsing stopped; report it as line:column.
    size_t line = 1, column = 1;
    for (size_t i = 0; i + 1 < e.byte && i < text.size(); ++i) {
      column = text[i] == '\n' ? 1 : column + 1;
      line += text[i] == '\n';
    }
    std::string detail = e.what();
    const size_t colon = detail.find(": ", detail.find("column"));
    if (colon != std::string::npos) detail = detail.substr(colon + 2);
    throw InputError(file + ":" + std::to_string(line) + ":" + std::to_string(column) +
                     ": malformed JSON: " + detail);
  } catch (const Json::exception& e) {  // the parser's other errors, e.g. a number past double's range
    throw InputError(file + ": malformed JSON: " + e.what());
  }
  try {
    JsonSceneReader(path, scene).read(root);
  } catch (const Json::exception& e) {  // a type mismatch the checks above missed
    throw InputError(file + ": " + e.what());
  }
}

}  // namespace gilt::raytrace_core::io
