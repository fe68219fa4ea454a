// Built-in scenes: the Cornell box (with blocks, or with a glass and a mirror sphere), a white
// furnace with a closed-form answer, and Kevin Beason's smallpt scene.

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"

namespace gilt::raytrace_core::io {

namespace {

using Quad = std::array<Vec3, 4>;

/// Appends a planar convex quad as two triangles, wound counter-clockwise seen from the side
/// `facing` points to (any vector with a positive component along the wanted front normal).
void add_quad(scene::TriangleMesh& mesh, const Quad& q, const Vec3& facing) {
  const Vec3 normal = glm::cross(q[1] - q[0], q[2] - q[0]);
  const bool flip = glm::dot(normal, facing) < 0.0f;
  // Corners shared with quads already in the mesh are reused, so the mesh is connected (the
  // radiosity mesher would otherwise report merging them).
  uint32_t corner[4];
  for (int i = 0; i < 4; ++i) {
    const Vec3& p = q[flip ? 3 - i : i];
    const auto found = std::find(mesh.positions.begin(), mesh.positions.end(), p);
    corner[i] = static_cast<uint32_t>(found - mesh.positions.begin());
    if (found == mesh.positions.end()) mesh.positions.push_back(p);
  }
  mesh.indices.insert(mesh.indices.end(), {corner[0], corner[1], corner[2], corner[0], corner[2], corner[3]});
}

uint32_t add_material(scene::Scene& scene, scene::Material material) {
  scene.materials.push_back(std::move(material));
  return static_cast<uint32_t>(scene.materials.size() - 1);
}

scene::TriangleMesh& add_mesh(scene::Scene& scene, std::string name, uint32_t material) {
  scene::TriangleMesh& mesh = scene.meshes.emplace_back();
  mesh.name = std::move(name);
  mesh.material = material;
  return mesh;
}

/// Appends a block whose faces (listed in the data, bottom omitted) face away from `center`.
void add_block(scene::Scene& scene, std::string name, uint32_t material, const std::vector<Quad>& faces) {
  Vec3 center(0.0f);
  for (const Quad& q : faces)
    for (const Vec3& p : q) center += p;
  center /= float(4 * faces.size());
  scene::TriangleMesh& mesh = add_mesh(scene, std::move(name), material);
  for (const Quad& q : faces) add_quad(mesh, q, q[0] - center);
}

// Geometry in millimetres from the Cornell Program of Computer Graphics, "Cornell Box Data"
// (https://www.graphics.cornell.edu/online/box/data.html). RGB reflectances and the light's
// radiance are the values commonly derived from its measured spectra, as in Benedikt Bitterli's
// "Rendering Resources" Cornell box: white (.725,.71,.68), red (.63,.065,.05),
// green (.14,.45,.091), light radiance (17,12,4).
constexpr float kCeiling = 548.8f;
const Vec3 kBoxInside(278.0f, 274.4f, 279.6f);

/// The empty box: floor, ceiling with a hole for the light, back wall, red and green walls, light.
/// Returns the index of the white material.
uint32_t add_cornell_box(scene::Scene& scene) {
  const uint32_t white =
      add_material(scene, scene::Material::make_diffuse("white", Rgb(0.725f, 0.71f, 0.68f)));
  const uint32_t red = add_material(scene, scene::Material::make_diffuse("red", Rgb(0.63f, 0.065f, 0.05f)));
  const uint32_t green =
      add_material(scene, scene::Material::make_diffuse("green", Rgb(0.14f, 0.45f, 0.091f)));
  const uint32_t light = add_material(scene, scene::Material::make_emitter("light", Rgb(17.0f, 12.0f, 4.0f)));

  const auto add_wall = [&](const char* name, uint32_t material, const Quad& q) {
    add_quad(add_mesh(scene, name, material), q, kBoxInside - q[0]);
  };
  add_wall("floor", white, {Vec3(552.8f, 0, 0), Vec3(0, 0, 0), Vec3(0, 0, 559.2f), Vec3(549.6f, 0, 559.2f)});
  add_wall(
      "back_wall", white,
      {Vec3(549.6f, 0, 559.2f), Vec3(0, 0, 559.2f), Vec3(0, kCeiling, 559.2f), Vec3(556, kCeiling, 559.2f)});
  add_wall(
      "left_wall", red,
      {Vec3(552.8f, 0, 0), Vec3(549.6f, 0, 559.2f), Vec3(556, kCeiling, 559.2f), Vec3(556, kCeiling, 0)});
  add_wall("right_wall", green,
           {Vec3(0, 0, 559.2f), Vec3(0, 0, 0), Vec3(0, kCeiling, 0), Vec3(0, kCeiling, 559.2f)});

  // The light is coplanar with the ceiling and fills a hole in it: the ceiling is the ring of four
  // trapezoids between its outline and the light's, sharing the light's edges (no T-junctions,
  // no overlap, no double-counted emission).
  const Quad outer = {Vec3(556, kCeiling, 0), Vec3(556, kCeiling, 559.2f), Vec3(0, kCeiling, 559.2f),
                      Vec3(0, kCeiling, 0)};
  const Quad inner = {Vec3(343, kCeiling, 227), Vec3(343, kCeiling, 332), Vec3(213, kCeiling, 332),
                      Vec3(213, kCeiling, 227)};
  const Vec3 down(0.0f, -1.0f, 0.0f);
  scene::TriangleMesh& ceiling = add_mesh(scene, "ceiling", white);
  for (int i = 0; i < 4; ++i)
    add_quad(ceiling, {outer[i], outer[(i + 1) % 4], inner[(i + 1) % 4], inner[i]}, down);
  add_quad(add_mesh(scene, "light", light), inner, down);  // emits downwards only

  scene.camera =
      scene::Camera{.look_from = Vec3(278, 273, -800), .look_at = Vec3(278, 273, 0), .vfov_degrees = 39.3f};
  scene.render.width = 512;
  scene.render.height = 512;
  return white;
}

scene::Scene cornell() {
  scene::Scene scene;
  scene.name = "cornell";
  const uint32_t white = add_cornell_box(scene);
  add_block(scene, "short_block", white,
            {{Vec3(130, 165, 65), Vec3(82, 165, 225), Vec3(240, 165, 272), Vec3(290, 165, 114)},
             {Vec3(290, 0, 114), Vec3(290, 165, 114), Vec3(240, 165, 272), Vec3(240, 0, 272)},
             {Vec3(130, 0, 65), Vec3(130, 165, 65), Vec3(290, 165, 114), Vec3(290, 0, 114)},
             {Vec3(82, 0, 225), Vec3(82, 165, 225), Vec3(130, 165, 65), Vec3(130, 0, 65)},
             {Vec3(240, 0, 272), Vec3(240, 165, 272), Vec3(82, 165, 225), Vec3(82, 0, 225)}});
  add_block(scene, "tall_block", white,
            {{Vec3(423, 330, 247), Vec3(265, 330, 296), Vec3(314, 330, 456), Vec3(472, 330, 406)},
             {Vec3(423, 0, 247), Vec3(423, 330, 247), Vec3(472, 330, 406), Vec3(472, 0, 406)},
             {Vec3(472, 0, 406), Vec3(472, 330, 406), Vec3(314, 330, 456), Vec3(314, 0, 456)},
             {Vec3(314, 0, 456), Vec3(314, 330, 456), Vec3(265, 330, 296), Vec3(265, 0, 296)},
             {Vec3(265, 0, 296), Vec3(265, 330, 296), Vec3(423, 330, 247), Vec3(423, 0, 247)}});
  return scene;
}

scene::Scene cornell_caustics() {
  scene::Scene scene;
  scene.name = "cornell-caustics";
  add_cornell_box(scene);
  // Both spheres rest on the floor (y = radius): the mirror at the back by the red wall, the
  // glass in front by the green wall, where its caustic falls on the floor.
  const uint32_t glass = add_material(scene, scene::Material::make_dielectric("glass", 1.5f));
  const uint32_t mirror = add_material(scene, scene::Material::make_mirror("mirror", Rgb(0.95f)));
  scene.spheres.push_back({Vec3(400.0f, 100.0f, 370.0f), 100.0f, mirror});
  scene.spheres.push_back({Vec3(170.0f, 100.0f, 200.0f), 100.0f, glass});
  return scene;
}

scene::Scene smallpt() {
  // Kevin Beason, smallpt: "Global Illumination in 99 lines of C++" (2008), its scene and camera.
  // The light is a real emitter here, so next-event estimation samples it; smallpt itself only
  // finds it when a path happens to hit it.
  scene::Scene scene;
  scene.name = "smallpt";
  const uint32_t red = add_material(scene, scene::Material::make_diffuse("red", Rgb(0.75f, 0.25f, 0.25f)));
  const uint32_t blue = add_material(scene, scene::Material::make_diffuse("blue", Rgb(0.25f, 0.25f, 0.75f)));
  const uint32_t grey = add_material(scene, scene::Material::make_diffuse("grey", Rgb(0.75f)));
  const uint32_t mirror = add_material(scene, scene::Material::make_mirror("mirror", Rgb(0.999f)));
  const uint32_t glass =
      add_material(scene, scene::Material::make_dielectric("glass", 1.5f));  // transmittance .999 ≈ 1
  const uint32_t light = add_material(scene, scene::Material::make_emitter("light", Rgb(12.0f)));
  // The walls are huge spheres whose insides (diffuse reflects on both sides) enclose the room.
  // smallpt's black front wall, the sphere of radius 1e5 at (50, 40.8, −1e5 + 170), is left out:
  // its camera sits behind that wall and starts each ray 140 units ahead, inside the room, which
  // a pinhole camera cannot do. A wall that neither reflects nor emits changes no radiance in the
  // room, so the open front gives the same image.
  scene.spheres = {
      {Vec3(1e5f + 1.0f, 40.8f, 81.6f), 1e5f, red},    {Vec3(-1e5f + 99.0f, 40.8f, 81.6f), 1e5f, blue},
      {Vec3(50.0f, 40.8f, 1e5f), 1e5f, grey},          {Vec3(50.0f, 1e5f, 81.6f), 1e5f, grey},
      {Vec3(50.0f, -1e5f + 81.6f, 81.6f), 1e5f, grey}, {Vec3(27.0f, 16.5f, 47.0f), 16.5f, mirror},
      {Vec3(73.0f, 16.5f, 78.0f), 16.5f, glass},       {Vec3(50.0f, 681.6f - 0.27f, 81.6f), 600.0f, light},
  };
  // smallpt's primary ray is d = cx·(x/w − ½) + cy·(y/h − ½) + view with |cy| = 0.5135 and
  // |cx| = 0.5135·w/h: the film spans ±0.5135/2 vertically at unit distance.
  const Vec3 eye(50.0f, 52.0f, 295.6f);
  const Vec3 view = glm::normalize(Vec3(0.0f, -0.042612f, -1.0f));
  const float vfov = 2.0f * std::atan(0.5f * 0.5135f) * 180.0f / kPi;
  scene.camera = scene::Camera{.look_from = eye, .look_at = eye + 140.0f * view, .vfov_degrees = vfov};
  scene.render.width = 1024;
  scene.render.height = 768;
  return scene;
}

}  // namespace

std::vector<std::string> builtin_scene_names() {
  return {"cornell", "cornell-caustics", "furnace", "smallpt"};
}

bool is_builtin_scene(const std::string& name) {
  for (const std::string& n : builtin_scene_names())
    if (n == name) return true;
  return false;
}

scene::Scene builtin_scene(const std::string& name) {
  if (name == "cornell") return cornell();
  if (name == "cornell-caustics") return cornell_caustics();
  if (name == "furnace") return furnace_scene(0.5f, 0.8f);
  if (name == "smallpt") return smallpt();
  throw InputError(name + ": no such built-in scene (try cornell, cornell-caustics, furnace or smallpt)");
}

scene::Scene furnace_scene(float le, float rho) {
  if (!(le >= 0.0f) || !std::isfinite(le) || !(rho >= 0.0f && rho < 1.0f))
    throw InputError("furnace: need finite emission le ≥ 0 and albedo 0 ≤ rho < 1");
  // A closed cube whose inner faces all emit le and reflect rho diffusely: every ray sees
  // L = le + rho·L, so every pixel converges to le / (1 − rho) (2.5 for the defaults 0.5, 0.8).
  scene::Scene scene;
  scene.name = "furnace";
  scene.materials.push_back(scene::Material::make_emitter("furnace", Rgb(le), Rgb(rho)));
  scene::TriangleMesh& box = add_mesh(scene, "box", 0);
  for (int axis = 0; axis < 3; ++axis) {
    for (float side : {-1.0f, 1.0f}) {
      // The face at coordinate `side` on `axis`, spanned by the other two axes.
      const int u = (axis + 1) % 3, v = (axis + 2) % 3;
      Quad q;
      for (int i = 0; i < 4; ++i) {
        q[i][axis] = side;
        q[i][u] = (i == 1 || i == 2) ? 1.0f : -1.0f;
        q[i][v] = (i >= 2) ? 1.0f : -1.0f;
      }
      Vec3 inward(0.0f);
      inward[axis] = -side;
      add_quad(box, q, inward);
    }
  }
  scene.camera = scene::Camera{.look_from = Vec3(0.0f), .look_at = Vec3(1.0f), .vfov_degrees = 70.0f};
  scene.render.width = 128;
  scene.render.height = 128;
  return scene;
}

}  // namespace gilt::raytrace_core::io
