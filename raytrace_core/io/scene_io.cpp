// Scene loading entry points: a built-in name or a file dispatched by its extension, then commit.
// The format loaders live in load_*.cpp, the built-in scenes in builtin_scenes.cpp.

#include "raytrace_core/io/scene_io.h"

#include <algorithm>
#include <optional>
#include <string>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <stdexcept>
#include <utility>

#include <glm/glm.hpp>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/scene/sun_sky.h"

namespace gilt::raytrace_core::io {

namespace fs = std::filesystem;

std::string lower_extension(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void transform_mesh(scene::TriangleMesh& mesh, const glm::mat4& transform) {
  const glm::mat3 linear(transform);
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
  for (Vec3& p : mesh.positions) p = Vec3(transform * glm::vec4(p, 1.0f));
  for (Vec3& n : mesh.normals) {
    const Vec3 m = normal_matrix * n;
    const float length = glm::length(m);
    n = length > 0.0f ? m / length : Vec3(0.0f);  // commit() falls back to ng for zero normals
  }
  // Tangents turn with the surface; a mirroring transform also mirrors the bitangent n × t
  // relative to the surface, so its sign w flips.
  const float handedness = glm::determinant(linear) < 0.0f ? -1.0f : 1.0f;
  for (glm::vec4& t : mesh.tangents) {
    const Vec3 m = linear * Vec3(t);
    const float length = glm::length(m);
    t = glm::vec4(length > 0.0f ? m / length : Vec3(0.0f), t.w < 0.0f ? -handedness : handedness);
  }
  // A mirroring transform turns counter-clockwise into clockwise: swap two corners so the same
  // physical side stays the front (glTF 2.0 §3.7.4 asks the same of mirrored nodes).
  if (glm::determinant(linear) < 0.0f)
    for (size_t t = 0; t < mesh.triangle_count(); ++t)
      std::swap(mesh.indices[3 * t + 1], mesh.indices[3 * t + 2]);
}

scene::Scene load_scene_file(const std::string& path) {
  const fs::path file(path);
  std::error_code ec;
  if (!fs::exists(file, ec)) {
    std::string names;
    for (const std::string& n : builtin_scene_names()) names += (names.empty() ? "" : ", ") + n;
    throw InputError(path + ": no such file (built-in scenes are " + names + ")");
  }
  if (fs::is_directory(file, ec)) throw InputError(path + ": is a directory, not a scene file");

  scene::Scene scene;
  scene.name = path;  // commit() prefixes its messages with the name, so they name the file too
  const std::string ext = lower_extension(file);
  if (ext == ".obj") {
    load_obj(file, scene);
  } else if (ext == ".gltf" || ext == ".glb") {
    load_gltf(file, scene);
  } else if (ext == ".ply") {
    load_ply(file, scene);
  } else if (ext == ".json") {
    load_json(file, scene);
  } else {
    throw InputError(path + ": unknown scene format '" + ext +
                     "' (expected .obj, .gltf, .glb, .ply or .json)");
  }
  return scene;
}

void select_camera(scene::Scene& scene, const std::string& choice) {
  // A scene whose camera came from no file's list (a built-in scene) offers that one.
  if (scene.cameras.empty() && scene.camera) scene.cameras.push_back({"scene", *scene.camera, 0.0f});
  const auto listed = [&scene] {
    if (scene.cameras.empty()) return std::string(scene.name + " defines no camera");
    std::string list = scene.name + " has";
    for (size_t i = 0; i < scene.cameras.size(); ++i)
      list += (i ? ", " : " ") + std::to_string(i) + " '" + scene.cameras[i].name + "'";
    return list;
  };
  std::optional<size_t> index;
  for (size_t i = 0; i < scene.cameras.size() && !index; ++i)
    if (scene.cameras[i].name == choice) index = i;
  if (!index && !choice.empty() && choice.find_first_not_of("0123456789") == std::string::npos) {
    if (choice.size() > 9 || std::stoul(choice) >= scene.cameras.size())
      throw InputError("--camera " + choice + ": no such camera; " + listed());
    index = std::stoul(choice);
  }
  if (!index) throw InputError("--camera '" + choice + "': no camera of that name; " + listed());
  const scene::NamedCamera& chosen = scene.cameras[*index];
  scene.camera = chosen.camera;
  if (chosen.aspect > 0.0f) scene.render.width = std::max(1, int(std::lround(float(scene.render.height) * chosen.aspect)));
}

scene::Scene load_scene(const std::string& path_or_name) { return load_scene(path_or_name, ExtraLighting{}); }

scene::Scene load_scene(const std::string& path_or_name, const ExtraLighting& extra) {
  scene::Scene scene =
      is_builtin_scene(path_or_name) ? builtin_scene(path_or_name) : load_scene_file(path_or_name);
  if (!extra.env_file.empty() && extra.sky_turbidity > 0.0f) throw InputError("--env and --sky: give one sky, not two");
  if (extra.sky_turbidity > 0.0f && !extra.sun) throw InputError("--sky needs --sun: the sky is drawn for the sun's position");
  if (!extra.env_file.empty() || extra.sky_turbidity > 0.0f) {
    scene::Light env;
    env.kind = scene::LightKind::environment;
    env.radiance = Rgb(1.0f);
    std::string flag;
    if (!extra.env_file.empty()) {
      std::error_code ec;
      if (!fs::is_regular_file(extra.env_file, ec)) throw InputError("--env " + extra.env_file + ": no such file");
      env.map = scene::EnvironmentMap::load(extra.env_file, extra.env_scale, extra.env_rotate_degrees);
      flag = "--env " + extra.env_file;
    } else {
      env.map = scene::preetham_sky(scene::sky_direction(extra.sun_elevation_degrees, extra.sun_azimuth_degrees), extra.sky_turbidity);
      flag = "--sky";
    }
    const size_t before = scene.punctual_lights.size();
    std::erase_if(scene.punctual_lights,
                  [](const scene::Light& l) { return l.kind == scene::LightKind::environment; });
    if (scene.punctual_lights.size() != before)
      scene.warnings.push_back("the scene's own environment light is replaced by " + flag);
    scene.punctual_lights.push_back(env);
  }
  if (extra.sun) {
    if (!(extra.sun_elevation_degrees >= -90.0f && extra.sun_elevation_degrees <= 90.0f) ||
        !std::isfinite(extra.sun_azimuth_degrees) || !(extra.sun_irradiance >= 0.0f) || !std::isfinite(extra.sun_irradiance))
      throw InputError("--sun: elevation must lie in [-90, 90] degrees, azimuth be finite and irradiance ≥ 0");
    scene::Light sun;
    sun.kind = scene::LightKind::directional;
    sun.direction = -scene::sky_direction(extra.sun_elevation_degrees, extra.sun_azimuth_degrees);
    sun.irradiance = Rgb(extra.sun_irradiance);
    sun.cos_angle = std::cos(scene::kSunAngularRadiusDegrees * (kPi / 180.0f));
    scene.punctual_lights.push_back(sun);
  }
  try {
    scene.commit();
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (message.rfind(path_or_name, 0) == 0) throw;
    throw InputError(path_or_name + ": " + message);
  }
  return scene;
}

void transform_scene(scene::Scene& scene, float scale, const Vec3& offset) {
  if (scene.committed()) throw std::logic_error("transform_scene: the scene is already committed");
  if (!(scale > 0.0f) || !std::isfinite(scale) || !is_finite(offset))
    throw InputError("transform_scene: scale must be positive and finite, offset finite");
  const auto map = [&](const Vec3& p) { return scale * p + offset; };

  for (scene::TriangleMesh& mesh : scene.meshes)
    for (Vec3& p : mesh.positions) p = map(p);  // normals keep their direction under p ↦ s·p + o
  for (scene::Sphere& sphere : scene.spheres) {
    sphere.center = map(sphere.center);
    sphere.radius *= scale;
  }
  for (scene::Light& light : scene.punctual_lights) {
    if (light.kind != scene::LightKind::point && light.kind != scene::LightKind::spot) continue;
    light.position = map(light.position);
    // Irradiance from a point light falls as intensity / distance²: scaling the intensity by s²
    // keeps every image unchanged, like the radiance of area lights.
    light.intensity *= scale * scale;
  }
  // σa is per scene unit: the same optical depth through a body s times larger needs σa / s.
  for (scene::Material& material : scene.materials) material.absorption /= scale;
  if (scene.camera) {
    scene::Camera& camera = *scene.camera;
    camera.look_from = map(camera.look_from);
    camera.look_at = map(camera.look_at);
    camera.aperture_radius *= scale;
    camera.focus_distance *= scale;
  }
}

}  // namespace gilt::raytrace_core::io
