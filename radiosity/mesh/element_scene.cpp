#include "radiosity/mesh/element_scene.h"

#include <utility>

namespace gilt::radiosity::mesh {

rc::scene::Scene element_scene(const rc::scene::Scene& scene, const RadiosityMesh& mesh) {
  rc::scene::Scene out;
  out.name = scene.name;
  out.materials = scene.materials;
  // Its rays ask only whether something is in the way; textures are read in the input scene.
  for (rc::scene::Material& m : out.materials) {
    for (rc::scene::TextureRef* t : m.texture_refs()) *t = rc::scene::TextureRef{};
    m.alpha_mode = rc::scene::AlphaMode::opaque;
  }
  rc::scene::TriangleMesh elements;
  elements.name = "radiosity elements";
  // Hit::prim_id is the element index: an element that rounds to no area in float must keep its
  // place, or every later element is read as its successor (on Šibenik the view and the vertex
  // bake read elements metres away from where their rays landed).
  elements.keep_degenerate = true;
  elements.positions = mesh.positions;
  elements.indices.reserve(3 * mesh.element_count());
  for (const auto& e : mesh.elements) elements.indices.insert(elements.indices.end(), e.begin(), e.end());
  elements.material = static_cast<uint32_t>(out.materials.size());
  out.materials.push_back(rc::scene::Material::make_diffuse("radiosity elements", rc::Rgb(0.0f)));
  out.meshes.push_back(std::move(elements));
  for (const rc::scene::TriangleMesh& m : scene.meshes)
    if (scene.materials[m.material].is_traced_through()) out.meshes.push_back(m);
  for (const rc::scene::Sphere& s : scene.spheres)
    if (scene.materials[s.material].is_traced_through()) out.spheres.push_back(s);
  out.commit();
  return out;
}

}  // namespace gilt::radiosity::mesh
