// Writing a radiosity solution as a mesh with one colour per vertex.
//
// PLY is written directly (binary little-endian); OBJ + MTL are written as text, since no OBJ writer among
// gilt's libraries emits `v x y z r g b` vertex colours; glTF and GLB go through tinygltf. Every
// file is encoded in memory first, then written to a hidden temporary beside its destination,
// flushed to disk and renamed into place (the scheme of raytrace_core/util/image_io.cpp): a failure
// leaves the destination as it was and no temporary behind.
//
// Materials are written so that gilt's own loaders read them back as the same kind:
//   MTL   Kd albedo, Ks specular, Ns exponent (1000, the sharpest, for a mirror), Ni ior, d 1,
//         Tf = exp(−σa) for a dielectric, Ke emission; illum 1 diffuse, 2 glossy, 3 mirror,
//         7 dielectric (a rough one with the PBR extension's Pr); metallic-roughness as illum 2
//         with Pr and Pm. Two-sided emission has no MTL equivalent.
//   glTF  baseColorFactor albedo; metallic-roughness materials their metallicFactor and
//         roughnessFactor; others metallicFactor 0, roughnessFactor 1 and
//         KHR_materials_specular's specularFactor 0, which makes the specification's BRDF exactly
//         Lambertian (F0 = 0); emissiveFactor emission
//         scaled into [0, 1] with KHR_materials_emissive_strength carrying the scale when the
//         emission exceeds 1, doubleSided for two-sided emission.
// Only materials that some element uses are written.

#include "radiosity/bake/export.h"

#include <fcntl.h>
#include <unistd.h>

#include <tiny_gltf.h>

#include <algorithm>
#include <unordered_map>
#include <array>
#include <atomic>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <vector>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/staged_file.h"

namespace gilt::radiosity::bake {

using mesh::RadiosityMesh;
using solver::Solution;

namespace fs = std::filesystem;
using rc::InputError;
using rc::scene::Material;
using rc::util::StagedFile;

// glTF buffers and binary PLY are little-endian; the buffers below are copied raw.
static_assert(std::endian::native == std::endian::little, "mesh export assumes a little-endian host");

namespace {

enum class Format { ply, obj, gltf, glb, unsupported };

/// write_forecast's fixed part and its parts per element, binary files and OBJ's text (see
/// write_forecast).
constexpr double kWriteSeconds = 0.3, kWriteSecondsPerElement = 4.5e-6, kObjSecondsPerElement = 5.5e-6;
/// onto_input_forecast's parts per input triangle and per lightmap texel.
constexpr double kOntoSecondsPerTriangle = 8e-6, kLightmapSecondsPerTexel = 1.7e-6;

Format format_of(const fs::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".ply") return Format::ply;
  if (ext == ".obj") return Format::obj;
  if (ext == ".gltf") return Format::gltf;
  if (ext == ".glb") return Format::glb;
  return Format::unsupported;
}

// --- Atomic files ---------------------------------------------------------------------------

/// Throws InputError unless the folder `destination` goes into exists.
void require_folder(const fs::path& destination) {
  const fs::path folder = destination.parent_path().empty() ? fs::path(".") : destination.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw InputError("cannot write '" + destination.string() + "': '" + folder.string() +
                     "' is not an existing directory");
  }
}

// --- What gets written ----------------------------------------------------------------------


const char* quantity_units(Quantity quantity) {
  return quantity == Quantity::radiance ? "W/(sr m^2)" : "W/m^2";
}

/// Checks that the mesh is consistent and finite: anything else is a bug upstream.
void check_mesh(const RadiosityMesh& mesh, size_t material_count) {
  const size_t n = mesh.vertex_count();
  if (mesh.normals.size() != n || mesh.element_material.size() != mesh.element_count()) {
    throw std::logic_error("write_solution: mesh arrays disagree in size");
  }
  for (size_t v = 0; v < n; ++v) {
    if (!rc::is_finite(mesh.positions[v]) || !rc::is_finite(mesh.normals[v])) {
      throw std::logic_error("write_solution: vertex " + std::to_string(v) + " is not finite");
    }
  }
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& tri = mesh.elements[e];
    if (tri[0] >= n || tri[1] >= n || tri[2] >= n || mesh.element_material[e] >= material_count) {
      throw std::logic_error("write_solution: element " + std::to_string(e) +
                             " refers to a missing vertex or material");
    }
  }
}

/// The colour of every vertex: the chosen quantity. The solver guarantees finite values, so a
/// non-finite one is a bug, never written.
std::vector<Rgb> vertex_colours(const Solution& solution, Quantity quantity) {
  const size_t n = solution.mesh.vertex_count();
  const std::vector<Rgb>& source =
      quantity == Quantity::irradiance ? solution.vertex_irradiance : solution.vertex_radiosity;
  if (source.size() != n) {
    throw std::logic_error(std::string("write_solution: ") + to_string(quantity) + " is not per vertex");
  }
  std::vector<Rgb> colours(n);
  for (size_t v = 0; v < n; ++v) {
    switch (quantity) {
      case Quantity::radiance:
        colours[v] = solution.vertex_radiance(v);
        break;
      case Quantity::irradiance:
        colours[v] = solution.vertex_irradiance[v];
        break;
      case Quantity::radiosity:
        colours[v] = solution.vertex_radiosity[v];
        break;
    }
    if (!colours[v].is_finite()) {
      throw std::logic_error("write_solution: " + std::string(to_string(quantity)) + " of vertex " +
                             std::to_string(v) + " is not finite");
    }
  }
  return colours;
}

/// The elements of each material, in mesh order.
std::vector<std::vector<uint32_t>> elements_by_material(const RadiosityMesh& mesh, size_t material_count) {
  std::vector<std::vector<uint32_t>> groups(material_count);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    groups[mesh.element_material[e]].push_back(static_cast<uint32_t>(e));
  }
  return groups;
}

/// One name per scene material, unique and without white space or '#' (an MTL name is one token).
std::vector<std::string> material_names(const std::vector<Material>& materials) {
  std::vector<std::string> names;
  std::set<std::string> taken;
  for (size_t i = 0; i < materials.size(); ++i) {
    std::string name = materials[i].name;
    for (char& c : name) {
      if (std::isspace(static_cast<unsigned char>(c)) || std::iscntrl(static_cast<unsigned char>(c)) ||
          c == '#')
        c = '_';
    }
    if (name.empty()) name = "material_" + std::to_string(i);
    while (!taken.insert(name).second) name.append("_").append(std::to_string(i));
    names.push_back(name);
  }
  return names;
}

// --- PLY ------------------------------------------------------------------------------------

/// Appends the raw little-endian bytes of `value`.
template <typename T>
void append_raw(std::string& out, const T& value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

/// Binary little-endian PLY: per vertex x y z, nx ny nz and the colours (write_solution says
/// which), per element a three-index list. PLY is a face list, so it is written directly: a
/// half-edge writer such as OpenMesh's must refuse or duplicate the vertices of non-manifold
/// elements, and Debian's OpenMesh 9.0 aborts on an assertion for some of them (Khronos'
/// 24_animation_pointer.gltf round-trip test scene).
std::string encode_ply(const RadiosityMesh& mesh, const std::vector<Rgb>& colours, const ExportSettings& settings) {
  const bool bytes = !settings.linear_float, floats = settings.linear_float || !settings.srgb8;
  std::string out = "ply\nformat binary_little_endian 1.0\ncomment gilt radiosity export: ";
  out += bytes ? "red green blue are the " : "red green blue are the linear ";
  out += to_string(settings.quantity);
  out += bytes ? " times 2^exposure as 8-bit sRGB" : "";
  if (bytes && floats) {
    out += ", ";
    out += to_string(settings.quantity);
    out += "_* the value itself";
  }
  out += "\nelement vertex " + std::to_string(mesh.vertex_count()) + "\n";
  for (const char* name : {"x", "y", "z", "nx", "ny", "nz"}) out += std::string("property float ") + name + "\n";
  for (const char* name : {"red", "green", "blue"}) out += std::string("property ") + (bytes ? "uchar " : "float ") + name + "\n";
  if (bytes && floats)
    for (const char* name : {"_red", "_green", "_blue"}) {
      out += "property float ";
      out += to_string(settings.quantity);
      out += name;
      out += '\n';
    }
  out += "element face " + std::to_string(mesh.element_count()) + "\n";
  out += "property list uchar int vertex_indices\nend_header\n";
  out.reserve(out.size() + mesh.vertex_count() * (24 + 3 + 12) + mesh.element_count() * 13);
  const float scale = std::exp2(settings.exposure);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    for (int k = 0; k < 3; ++k) append_raw(out, mesh.positions[v][k]);
    for (int k = 0; k < 3; ++k) append_raw(out, mesh.normals[v][k]);
    if (bytes)
      for (int k = 0; k < 3; ++k) append_raw(out, to_srgb8(colours[v][k], scale));
    if (floats)
      for (int k = 0; k < 3; ++k) append_raw(out, colours[v][k]);
  }
  for (const auto& element : mesh.elements) {
    append_raw(out, uint8_t{3});
    for (uint32_t v : element) append_raw(out, static_cast<int32_t>(v));
  }
  return out;
}

// --- OBJ + MTL ------------------------------------------------------------------------------

void append_line(std::string& out, const char* key, const Rgb& c) {
  out += key;
  for (int i = 0; i < 3; ++i) append_float(out, c[i]);
  out += '\n';
}

std::string encode_mtl(const std::vector<Material>& materials, const std::vector<std::string>& names,
                       const std::vector<std::vector<uint32_t>>& groups) {
  std::string out = "# gilt radiosity export: materials\n";
  for (size_t m = 0; m < materials.size(); ++m) {
    if (groups[m].empty()) continue;
    const Material& mat = materials[m];
    int illum = 1;
    float ns = 0.0f;
    switch (mat.kind) {
      case rc::scene::MaterialKind::diffuse:
        break;
      case rc::scene::MaterialKind::glossy:
        illum = 2;
        ns = mat.exponent;
        break;
      case rc::scene::MaterialKind::mirror:
        illum = 3;
        ns = 1000.0f;
        break;
      case rc::scene::MaterialKind::dielectric:
        illum = 7;
        break;
      case rc::scene::MaterialKind::metallic_roughness:  // Pr and Pm below; Ns the Phong equivalent of α
        illum = 2;
        ns = std::clamp(2.0f / std::max(1e-6f, rc::sqr(rc::sqr(mat.roughness))) - 2.0f, 1.0f, 1e4f);
        break;
    }
    out += "\nnewmtl " + names[m] + "\n";
    append_line(out, "Kd", mat.albedo);
    append_line(out, "Ks", mat.specular);
    out += "Ns";
    append_float(out, ns);
    out += "\nNi";
    append_float(out, mat.ior);
    out += "\nd 1\n";
    if (mat.kind == rc::scene::MaterialKind::dielectric)
      append_line(out, "Tf", rc::exp(mat.absorption * -1.0f));
    append_line(out, "Ke", mat.emission);
    if (mat.kind == rc::scene::MaterialKind::metallic_roughness) {
      out += "Pr";
      append_float(out, mat.roughness);
      out += "\nPm";
      append_float(out, mat.metallic);
      out += "\n";
    } else if (mat.is_rough_dielectric()) {  // frosted glass: its roughness as the PBR extension's Pr
      out += "Pr";
      append_float(out, mat.roughness);
      out += "\n";
    }
    out += "illum " + std::to_string(illum) + "\n";
  }
  return out;
}

std::string encode_obj(const RadiosityMesh& mesh, const std::vector<Rgb>& colours, const ExportSettings& settings,
                       const std::string& mtl_name, const std::vector<std::string>& names,
                       const std::vector<std::vector<uint32_t>>& groups) {
  std::string out;
  out.reserve(96 * mesh.vertex_count() + 40 * mesh.element_count());
  out += settings.linear_float ? "# gilt radiosity export: vertex colours are linear "
                               : "# gilt radiosity export: vertex colours are display values, the ";
  out += to_string(settings.quantity);
  out += " in ";
  out += quantity_units(settings.quantity);
  if (!settings.linear_float) {
    out += " times 2^exposure, clamped to 0..1 and sRGB-encoded; exposure";
    append_float(out, settings.exposure);
  }
  out += "\nmtllib " + mtl_name + "\n";
  const float scale = std::exp2(settings.exposure);
  for (size_t v = 0; v < mesh.vertex_count(); ++v) {
    out += 'v';
    for (int i = 0; i < 3; ++i) append_float(out, mesh.positions[v][i]);
    for (int i = 0; i < 3; ++i) append_float(out, settings.linear_float ? colours[v][i] : to_srgb(colours[v][i], scale));
    out += '\n';
  }
  for (const Vec3& n : mesh.normals) {
    out += "vn";
    for (int i = 0; i < 3; ++i) append_float(out, n[i]);
    out += '\n';
  }
  for (size_t m = 0; m < groups.size(); ++m) {
    if (groups[m].empty()) continue;
    out += "usemtl " + names[m] + "\n";
    for (const uint32_t e : groups[m]) {
      out += 'f';
      for (const uint32_t v : mesh.elements[e]) {
        const std::string index = std::to_string(v + 1);
        out += ' ' + index + "//" + index;
      }
      out += '\n';
    }
  }
  return out;
}

// --- glTF / GLB -----------------------------------------------------------------------------

/// Appends `count` items of `bytes_per_item` bytes to the buffer as a new buffer view with one
/// accessor over it; returns the accessor's index.
int add_accessor(tinygltf::Model& model, std::vector<unsigned char>& buffer, const void* data, size_t count,
                 size_t bytes_per_item, int component_type, int type, int target) {
  tinygltf::BufferView view;
  view.buffer = 0;
  view.byteOffset = buffer.size();
  view.byteLength = count * bytes_per_item;
  view.target = target;
  const auto* bytes = static_cast<const unsigned char*>(data);
  buffer.insert(buffer.end(), bytes, bytes + view.byteLength);
  model.bufferViews.push_back(std::move(view));

  tinygltf::Accessor accessor;
  accessor.bufferView = static_cast<int>(model.bufferViews.size()) - 1;
  accessor.componentType = component_type;
  accessor.type = type;
  accessor.count = count;
  model.accessors.push_back(std::move(accessor));
  return static_cast<int>(model.accessors.size()) - 1;
}

tinygltf::Material gltf_material(const Material& m, const std::string& name, tinygltf::Model& model) {
  tinygltf::Material out;
  out.name = name;
  out.pbrMetallicRoughness.baseColorFactor = {m.albedo.r, m.albedo.g, m.albedo.b, 1.0};
  const bool pbr = m.kind == rc::scene::MaterialKind::metallic_roughness;
  out.pbrMetallicRoughness.metallicFactor = pbr ? m.metallic : 0.0;
  out.pbrMetallicRoughness.roughnessFactor = pbr ? m.roughness : 1.0;
  const auto use_extension = [&](const std::string& used) {
    if (std::find(model.extensionsUsed.begin(), model.extensionsUsed.end(), used) == model.extensionsUsed.end())
      model.extensionsUsed.push_back(used);
  };
  if (!pbr) {  // Lambertian: no specular layer at all
    tinygltf::Value::Object specular;
    specular["specularFactor"] = tinygltf::Value(0.0);
    out.extensions["KHR_materials_specular"] = tinygltf::Value(std::move(specular));
    use_extension("KHR_materials_specular");
  }
  out.doubleSided = m.two_sided_emission;
  const float strength = m.emission.max_component();
  if (strength > 1.0f) {
    out.emissiveFactor = {m.emission.r / double(strength), m.emission.g / double(strength),
                          m.emission.b / double(strength)};
    tinygltf::Value::Object extension;
    extension["emissiveStrength"] = tinygltf::Value(double(strength));
    out.extensions["KHR_materials_emissive_strength"] = tinygltf::Value(std::move(extension));
    use_extension("KHR_materials_emissive_strength");
  } else if (strength > 0.0f) {
    out.emissiveFactor = {m.emission.r, m.emission.g, m.emission.b};
  }
  return out;
}

/// One mesh with one primitive per material; each primitive holds the vertices its elements use.
std::string encode_gltf(const rc::scene::Scene& scene, const RadiosityMesh& mesh,
                        const std::vector<Rgb>& colours, const std::vector<std::string>& names,
                        const std::vector<std::vector<uint32_t>>& groups, const ExportSettings& settings,
                        bool binary) {
  const float scale = std::exp2(settings.exposure);
  tinygltf::Model model;
  model.asset.version = "2.0";
  model.asset.generator = "gilt radiosity export";
  std::vector<unsigned char> buffer;
  tinygltf::Mesh gltf_mesh;
  gltf_mesh.name = scene.name.empty() ? "radiosity" : scene.name;

  for (size_t m = 0; m < groups.size(); ++m) {
    if (groups[m].empty()) continue;
    std::vector<uint32_t> vertices;  // mesh vertex of each primitive vertex, ascending
    for (const uint32_t e : groups[m])
      vertices.insert(vertices.end(), mesh.elements[e].begin(), mesh.elements[e].end());
    std::sort(vertices.begin(), vertices.end());
    vertices.erase(std::unique(vertices.begin(), vertices.end()), vertices.end());

    std::vector<float> positions, normals, rgb, hdr;
    positions.reserve(3 * vertices.size());
    normals.reserve(3 * vertices.size());
    rgb.reserve(3 * vertices.size());
    hdr.reserve(3 * vertices.size());
    Vec3 lo(rc::kInfinity), hi(-rc::kInfinity);
    for (const uint32_t v : vertices) {
      const Vec3& p = mesh.positions[v];
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
      for (int i = 0; i < 3; ++i) {
        positions.push_back(p[i]);
        normals.push_back(mesh.normals[v][i]);
        rgb.push_back(std::clamp(colours[v][i] * scale, 0.0f, 1.0f));
        hdr.push_back(colours[v][i]);
      }
    }
    std::vector<uint32_t> indices;
    indices.reserve(3 * groups[m].size());
    for (const uint32_t e : groups[m]) {
      for (const uint32_t v : mesh.elements[e]) {
        indices.push_back(
            static_cast<uint32_t>(std::lower_bound(vertices.begin(), vertices.end(), v) - vertices.begin()));
      }
    }

    tinygltf::Primitive primitive;
    primitive.mode = TINYGLTF_MODE_TRIANGLES;
    const size_t n = vertices.size();
    const int position = add_accessor(model, buffer, positions.data(), n, 12, TINYGLTF_COMPONENT_TYPE_FLOAT,
                                      TINYGLTF_TYPE_VEC3, TINYGLTF_TARGET_ARRAY_BUFFER);
    model.accessors[position].minValues = {lo.x, lo.y, lo.z};
    model.accessors[position].maxValues = {hi.x, hi.y, hi.z};
    primitive.attributes["POSITION"] = position;
    primitive.attributes["NORMAL"] =
        add_accessor(model, buffer, normals.data(), n, 12, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                     TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.attributes["COLOR_0"] =
        add_accessor(model, buffer, rgb.data(), n, 12, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                     TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.attributes[gltf_attribute(settings.quantity)] =
        add_accessor(model, buffer, hdr.data(), n, 12, TINYGLTF_COMPONENT_TYPE_FLOAT, TINYGLTF_TYPE_VEC3,
                     TINYGLTF_TARGET_ARRAY_BUFFER);
    primitive.indices =
        add_accessor(model, buffer, indices.data(), indices.size(), 4, TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT,
                     TINYGLTF_TYPE_SCALAR, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    primitive.material = static_cast<int>(model.materials.size());
    model.materials.push_back(gltf_material(scene.materials[m], names[m], model));
    gltf_mesh.primitives.push_back(std::move(primitive));
  }

  tinygltf::Scene gltf_scene;
  if (!gltf_mesh.primitives.empty()) {
    // A .gltf embeds the buffer as a base64 data: URI, so it stays a single file.
    tinygltf::Buffer gltf_buffer;
    gltf_buffer.data = std::move(buffer);
    model.buffers.push_back(std::move(gltf_buffer));
    model.meshes.push_back(std::move(gltf_mesh));
    tinygltf::Node node;
    node.name = model.meshes[0].name;
    node.mesh = 0;
    model.nodes.push_back(std::move(node));
    gltf_scene.nodes.push_back(0);
  }
  model.scenes.push_back(std::move(gltf_scene));
  model.defaultScene = 0;

  tinygltf::TinyGLTF writer;
  std::ostringstream stream(std::ios::out | std::ios::binary);
  if (!writer.WriteGltfSceneToStream(&model, stream, /*prettyPrint=*/!binary, /*writeBinary=*/binary)) {
    throw std::runtime_error("write_solution: tinygltf could not encode the mesh");
  }
  return std::move(stream).str();
}

}  // namespace

RadiosityMesh snapped_to_input(const rc::scene::Scene& scene, const RadiosityMesh& mesh, float reach,
                               SnapStats* stats, rc::util::Progress* progress) {
  RadiosityMesh out = mesh;
  if (mesh.element_surface.size() != mesh.element_count() || mesh.element_normal.size() != mesh.element_count() ||
      mesh.normals.size() != mesh.vertex_count()) {
    // A mesh built by hand without its surfaces: nothing tells where its vertices belong.
    if (stats) *stats = SnapStats{mesh.vertex_count(), 0, 0, 0.0};
    return out;
  }
  // The input meshes each vertex's elements were meshed from (a few at most: surfaces meet at
  // contact lines, where the mesher splits vertices by side anyway).
  constexpr size_t kMaxSurfaces = 4;
  std::vector<std::array<uint32_t, kMaxSurfaces>> surfaces(mesh.vertex_count());
  std::vector<uint8_t> count(mesh.vertex_count(), 0);
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const uint32_t s = mesh.element_surface[e];
    if (s >= scene.meshes.size()) continue;  // a sphere: its tessellation lies on it already
    for (uint32_t v : mesh.elements[e]) {
      const auto first = surfaces[v].begin(), last = first + count[v];
      if (std::find(first, last, s) == last && count[v] < kMaxSurfaces) surfaces[v][count[v]++] = s;
    }
  }
  std::vector<float> moved(mesh.vertex_count(), -1.0f);
  rc::util::parallel_for(mesh.vertex_count(), [&](size_t v) {
    if (progress) progress->advance(1);
    std::optional<rc::scene::Hit> best;
    // A vertex of an element turned over, or of the back twin of one, faces against its input.
    for (const float side : {1.0f, -1.0f}) {
      for (uint8_t k = 0; k < count[v]; ++k) {
        const std::optional<rc::scene::Hit> h = scene.nearest_triangle(
            surfaces[v][k], mesh.positions[v], best ? best->t : reach, side * mesh.normals[v], 0.5f);
        if (h && (!best || h->t < best->t)) best = h;
      }
      if (best) break;
    }
    if (!best) return;
    const rc::scene::TriangleMesh& m = scene.meshes[best->geom_id];
    const uint32_t* c = &m.indices[3 * size_t(best->prim_id)];
    out.positions[v] = (1.0f - best->u - best->v) * m.positions[c[0]] + best->u * m.positions[c[1]] +
                       best->v * m.positions[c[2]];
    moved[v] = best->t;
  });
  // A vertex whose move turns one of its elements over goes back: the export must not fold.
  for (size_t e = 0; e < mesh.element_count(); ++e) {
    const auto& el = mesh.elements[e];
    const Vec3 n = glm::cross(out.positions[el[1]] - out.positions[el[0]], out.positions[el[2]] - out.positions[el[0]]);
    if (glm::dot(n, mesh.element_normal[e]) > 0.0f) continue;
    for (uint32_t v : el) {
      out.positions[v] = mesh.positions[v];
      moved[v] = -1.0f;
      if (stats) ++stats->kept_to_avoid_folds;
    }
  }
  if (stats) {
    const float diagonal = glm::length(scene.bounds().diagonal());
    const size_t folds = stats->kept_to_avoid_folds;
    *stats = SnapStats{};
    stats->kept_to_avoid_folds = folds;
    for (float d : moved) {
      if (d < 0.0f)
        ++stats->not_moved;
      else
        stats->largest = std::max(stats->largest, double(d));
      if (d > 1e-3f * diagonal) ++stats->moved_far;
    }
  }
  return out;
}

void append_float(std::string& out, float x) {
  char buffer[40];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, x, std::chars_format::general, 9);
  out += ' ';
  out.append(buffer, result.ptr);
}

float to_srgb(float linear, float scale) {
  // The sRGB transfer function (IEC 61966-2-1) of the clamped value.
  const float x = std::clamp(linear * scale, 0.0f, 1.0f);
  const float encoded = x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f;
  return std::clamp(encoded, 0.0f, 1.0f);
}

uint8_t to_srgb8(float linear, float scale) {
  return static_cast<uint8_t>(std::lround(to_srgb(linear, scale) * 255.0f));
}

const char* gltf_attribute(Quantity q) {
  return q == Quantity::irradiance ? "_IRRADIANCE" : q == Quantity::radiosity ? "_RADIOSITY" : "_RADIANCE";
}

const char* to_string(Quantity quantity) {
  switch (quantity) {
    case Quantity::radiance:
      return "radiance";
    case Quantity::irradiance:
      return "irradiance";
    case Quantity::radiosity:
      return "radiosity";
  }
  return "?";
}

Quantity parse_quantity(const std::string& name) {
  if (name == "radiance") return Quantity::radiance;
  if (name == "irradiance") return Quantity::irradiance;
  if (name == "radiosity") return Quantity::radiosity;
  throw InputError("unknown quantity '" + name + "' (expected radiance, irradiance or radiosity)");
}

RadiosityMesh without_coincident(const RadiosityMesh& mesh, SnapStats* stats) {
  // Each element's corners by bits, turned so the smallest comes first: equal keys are the same
  // face with the same orientation; the key of the reversed order finds the opposite face.
  using Key = std::array<uint32_t, 9>;
  struct Hash {
    size_t operator()(const Key& k) const {
      size_t h = 0xcbf29ce484222325ull;
      for (uint32_t x : k) h = (h ^ x) * 0x100000001b3ull;
      return h;
    }
  };
  const auto key = [&](const std::array<uint32_t, 3>& e, bool reversed) {
    std::array<std::array<uint32_t, 3>, 3> corner;
    for (int k = 0; k < 3; ++k) std::memcpy(corner[size_t(k)].data(), &mesh.positions[e[size_t(reversed ? 2 - k : k)]], 12);
    const size_t first = size_t(std::min_element(corner.begin(), corner.end()) - corner.begin());
    Key out;
    for (size_t k = 0; k < 3; ++k)
      for (size_t c = 0; c < 3; ++c) out[3 * k + c] = corner[(first + k) % 3][c];
    return out;
  };
  std::unordered_map<Key, uint32_t, Hash> seen;
  seen.reserve(mesh.element_count());
  std::vector<char> keep(mesh.element_count(), 1);
  size_t merged = 0, back_to_back = 0;
  for (uint32_t e = 0; e < mesh.element_count(); ++e) {
    if (!seen.emplace(key(mesh.elements[e], false), e).second) {
      keep[e] = 0;
      ++merged;
    } else if (seen.count(key(mesh.elements[e], true))) {
      ++back_to_back;
    }
  }
  if (stats) stats->coincident_merged = merged, stats->back_to_back = back_to_back;
  if (merged == 0) return mesh;
  RadiosityMesh out = mesh;
  const auto compact = [&](auto& per_element) {
    if (per_element.size() != mesh.element_count()) return;
    size_t n = 0;
    for (size_t e = 0; e < keep.size(); ++e)
      if (keep[e]) per_element[n++] = per_element[e];
    per_element.resize(n);
  };
  compact(out.elements);
  compact(out.element_material);
  compact(out.element_surface);
  compact(out.element_normal);
  compact(out.element_area);
  return out;
}

WriteForecast write_forecast(const std::string& path) {
  // The slowest rate measured, 0.11-3.0 M elements on four scenes, with 30 % for the machine's
  // noise (bench/README.md, "The solver's budget" and "The biggest rooms under --time"): 1.6 µs
  // per element for binary PLY on a room whose furniture kept its input triangles, 3.5 µs where
  // it was imprinted and remeshed (the snap onto the input is most of it), OBJ's text a fifth more.
  switch (format_of(fs::path(path))) {
    case Format::ply:
    case Format::gltf:
    case Format::glb: return {kWriteSeconds, kWriteSecondsPerElement};
    case Format::obj: return {kWriteSeconds, kObjSecondsPerElement};
    default: return {};
  }
}

WriteForecast onto_input_forecast(size_t input_triangles, int lightmap_size) {
  // Šibenik (75,277 triangles) at `--time 20`: the fit and write took 0.47 s, a 1024² lightmap
  // 1.33 s; the rates with 30 % for the machine's noise (bench/README.md, "The solver's budget").
  const double texels = lightmap_size > 0 ? double(lightmap_size) * double(lightmap_size) : 0.0;
  return {kWriteSeconds + kOntoSecondsPerTriangle * double(input_triangles) + kLightmapSecondsPerTexel * texels, 0.0};
}

void write_solution(const std::string& path, const rc::scene::Scene& scene, const Solution& solution,
                    const ExportSettings& settings, SnapStats* snap) {
  const fs::path destination(path);
  const Format format = format_of(destination);
  if (format == Format::unsupported) {
    throw InputError("cannot write '" + path + "': unsupported mesh format '" +
                     destination.extension().string() + "' (expected .ply, .obj, .gltf or .glb)");
  }
  require_folder(destination);
  // Vertices on the input's own surface: remeshing, contact imprints and repairs leave some a
  // little off it, and a viewer shows the model, not gilt's approximation of it.
  rc::util::Progress snapping("export: snapping onto the input", solution.mesh.vertex_count(), "vertices",
                              settings.progress);
  const RadiosityMesh mesh = without_coincident(
      snapped_to_input(scene, solution.mesh, 0.5f * solution.mesh_report.max_edge, snap, &snapping), snap);
  check_mesh(mesh, scene.materials.size());
  const std::vector<Rgb> colours = vertex_colours(solution, settings.quantity);
  const auto groups = elements_by_material(mesh, scene.materials.size());
  const auto names = material_names(scene.materials);

  // Display colours in every format (PLY bytes, OBJ, glTF COLOR_0) show the quantity × 2^exposure.
  switch (format) {
    case Format::ply:
      StagedFile(destination, encode_ply(mesh, colours, settings)).commit();
      break;
    case Format::obj: {
      // Both files are staged before either is renamed, so a failure while encoding or writing
      // leaves both as they were; each rename is atomic on its own. The MTL goes first, so the OBJ
      // never names a material its MTL lacks.
      fs::path mtl_path = destination;
      mtl_path.replace_extension(".mtl");
      StagedFile mtl(mtl_path, encode_mtl(scene.materials, names, groups));
      StagedFile obj(destination, encode_obj(mesh, colours, settings, mtl_path.filename().string(),
                                             names, groups));
      mtl.commit();
      obj.commit();
      break;
    }
    case Format::gltf:
    case Format::glb:
      StagedFile(destination, encode_gltf(scene, mesh, colours, names, groups, settings, format == Format::glb))
          .commit();
      break;
    case Format::unsupported:
      break;
  }
}

}  // namespace gilt::radiosity::bake
