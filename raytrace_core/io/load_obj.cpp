// Wavefront OBJ + MTL through tinyobjloader, split into one triangle mesh per material.
//
// tinyobjloader reads "nan" as 0 and skips faces with out-of-range indices with a warning, so a
// first pass over the text checks coordinates and face indices and reports the offending line.
//
// MTL → Material (documented in docs/scene-format.md):
//   Ke                                  → emission (emitted radiance, front face only)
//   illum 4, 6, 7 or 9, or d < 1        → dielectric, ior = Ni (1.5 when Ni ≤ 1, i.e. unset);
//                                         σa = −ln(Tf) per scene unit when Tf is neither black
//                                         (unset) nor white
//   illum 3, 5 or 8 and max(Ks) ≥ 0.5   → mirror, reflectance Ks (ray-traced reflection models)
//   Ks ≠ 0, Ns < 1000                   → glossy: albedo Kd, specular Ks, Phong exponent Ns
//   Ks ≠ 0, Ns ≥ 1000, Kd = 0           → mirror, reflectance Ks (a lobe that sharp is a mirror)
//   Ks ≠ 0, Ns ≥ 1000, Kd ≠ 0           → glossy with exponent Ns
//   otherwise                           → diffuse, albedo Kd
// Kd and Ks are clamped to [0, 1] and, where Kd + Ks > 1 in a channel, both are scaled down so the
// sum is 1 (energy conservation), with a warning. Ka and texture maps are ignored.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include <tiny_obj_loader.h>

#include "raytrace_core/error.h"
#include "raytrace_core/io/loaders.h"

namespace gilt::raytrace_core {

namespace fs = std::filesystem;

namespace {

/// The line's tokens before any '#': OBJ and MTL comments may follow the numbers on a line
/// ("Kd 0.63 0.065 0.05 # Red", as McGuire's Cornell boxes have them).
std::vector<std::string_view> split_whitespace(std::string_view line) {
  line = line.substr(0, line.find('#'));
  std::vector<std::string_view> tokens;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    const size_t start = i;
    while (i < line.size() && !std::isspace(static_cast<unsigned char>(line[i]))) ++i;
    if (i > start) tokens.push_back(line.substr(start, i - start));
  }
  return tokens;
}

/// Parses a whole token as a finite number (a leading '+' allowed).
bool finite_number(std::string_view token, double& x) {
  const char* first = token.data() + (!token.empty() && token.front() == '+' ? 1 : 0);
  const char* last = token.data() + token.size();
  const auto [end, err] = std::from_chars(first, last, x);
  return err == std::errc() && end == last && std::isfinite(static_cast<float>(x));
}

/// Checks an MTL file's numbers, which tinyobjloader reads as 0 when it cannot parse them:
/// colours (Ka, Kd, Ks, Ke, Tf) need three finite, non-negative numbers, scalars (Ns, Ni, d, Tr)
/// one finite number. Throws InputError "file:line: ...". A missing file is left to the loader.
void check_mtl_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return;
  std::string line;
  for (size_t line_no = 1; std::getline(in, line); ++line_no) {
    const std::vector<std::string_view> tokens = split_whitespace(line);
    if (tokens.empty()) continue;
    const std::string_view tag = tokens[0];
    const bool colour = tag == "Ka" || tag == "Kd" || tag == "Ks" || tag == "Ke" || tag == "Tf";
    const bool scalar = tag == "Ns" || tag == "Ni" || tag == "d" || tag == "Tr";
    if (!colour && !scalar) continue;
    const size_t needed = colour ? 3 : 1;
    auto fail = [&](const std::string& what) {
      throw InputError(path.string() + ":" + std::to_string(line_no) + ": " + std::string(tag) + " " + what);
    };
    if (tokens.size() != needed + 1)
      fail(colour ? "needs three numbers r g b (spectral and xyz forms are not supported)"
                  : "needs one number");
    for (size_t k = 1; k <= needed; ++k) {
      double x = 0.0;
      if (!finite_number(tokens[k], x)) fail("value '" + std::string(tokens[k]) + "' is not a finite number");
      if (colour && x < 0.0) fail("value '" + std::string(tokens[k]) + "' is negative");
    }
  }
}

/// Checks what tinyobjloader would silently repair: non-finite numbers, face indices that do
/// not refer to an existing v / vt / vn, and the numbers of the MTL files it names. Throws
/// InputError "file:line: ...".
void check_obj_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open file");
  const char* kinds[3] = {"vertex", "texture coordinate", "normal"};
  size_t counts[3] = {0, 0, 0};  // v, vt, vn seen so far
  struct Forward {               // a positive index past what is defined so far, checked at the end
    size_t line;
    int part;
    long index;
  };
  std::vector<Forward> forward;
  const auto fail = [&](size_t line_no, const std::string& what) {
    throw InputError(path.string() + ":" + std::to_string(line_no) + ": " + what);
  };
  const auto out_of_range = [&](size_t line_no, int part, long index) {
    fail(line_no, "face refers to " + std::string(kinds[part]) + " " + std::to_string(index) + " of " +
                      std::to_string(counts[part]));
  };
  std::string line;
  size_t line_no = 1;
  for (; std::getline(in, line); ++line_no) {
    const std::vector<std::string_view> tokens = split_whitespace(line);
    if (tokens.empty()) continue;
    const std::string_view tag = tokens[0];
    if (tag == "mtllib") {
      for (size_t k = 1; k < tokens.size(); ++k) check_mtl_text(path.parent_path() / std::string(tokens[k]));
    } else if (tag == "v" || tag == "vt" || tag == "vn") {
      const size_t needed = tag == "vt" ? 1 : 3;
      if (tokens.size() < needed + 1)
        fail(line_no, std::string(tag) + " needs " + std::to_string(needed) + " number(s)");
      for (size_t k = 1; k <= needed; ++k) {
        double x = 0.0;
        const char* first = tokens[k].data() + (tokens[k].front() == '+' ? 1 : 0);
        const char* last = tokens[k].data() + tokens[k].size();
        const auto [end, err] = std::from_chars(first, last, x);
        if (err != std::errc() || end != last || !std::isfinite(static_cast<float>(x)))
          fail(line_no, "coordinate '" + std::string(tokens[k]) + "' is not a finite number");
      }
      ++counts[tag == "v" ? 0 : (tag == "vt" ? 1 : 2)];
    } else if (tag == "f") {
      if (tokens.size() < 4)
        fail(line_no, "face has " + std::to_string(tokens.size() - 1) + " vertices; at least 3 needed");
      for (size_t k = 1; k < tokens.size(); ++k) {
        // v, v/vt, v//vn or v/vt/vn; indices are 1-based, negative ones count back from the end.
        std::string_view rest = tokens[k];
        for (int part = 0; part < 3 && !rest.empty(); ++part) {
          const size_t slash = rest.find('/');
          const std::string_view field = rest.substr(0, slash);
          rest = slash == std::string_view::npos ? std::string_view() : rest.substr(slash + 1);
          if (field.empty() && part > 0) continue;
          long index = 0;
          const auto [end, err] = std::from_chars(field.data(), field.data() + field.size(), index);
          if (err != std::errc() || end != field.data() + field.size())
            fail(line_no, "malformed face corner '" + std::string(tokens[k]) + "'");
          const long n = static_cast<long>(counts[part]);
          if (index == 0 || index < -n) out_of_range(line_no, part, index);
          if (index > n) forward.push_back({line_no, part, index});
        }
      }
    }
  }
  for (const Forward& f : forward)
    if (f.index > static_cast<long>(counts[f.part])) out_of_range(f.line, f.part, f.index);
}

Rgb rgb(const tinyobj::real_t c[3]) { return {float(c[0]), float(c[1]), float(c[2])}; }

bool is_one_of(int value, std::initializer_list<int> set) {
  for (int v : set)
    if (v == value) return true;
  return false;
}

Material convert_material(const tinyobj::material_t& mtl, const std::string& file,
                          std::vector<std::string>& warnings) {
  const std::string where = file + ": material '" + mtl.name + "'";
  Rgb kd = clamp(rgb(mtl.diffuse), 0.0f, 1.0f);
  Rgb ks = clamp(rgb(mtl.specular), 0.0f, 1.0f);
  const Rgb tf = rgb(mtl.transmittance);
  const float ns = std::max(0.0f, float(mtl.shininess));
  Material m;

  if (is_one_of(mtl.illum, {4, 6, 7, 9}) || mtl.dissolve < 1.0f) {
    float ior = float(mtl.ior);
    if (!(ior > 1.0f)) {
      warnings.push_back(where + ": transparent without Ni > 1; using ior 1.5");
      ior = 1.5f;
    }
    Rgb absorption(0.0f);
    if (!tf.is_black() && !(tf == Rgb(1.0f)))
      for (int c = 0; c < 3; ++c) absorption[c] = -std::log(std::clamp(tf[c], 1e-4f, 1.0f));
    m = Material::make_dielectric(mtl.name, ior, absorption);
  } else if (is_one_of(mtl.illum, {3, 5, 8}) && ks.max_component() >= 0.5f) {
    if (!kd.is_black())
      warnings.push_back(where + ": mirror (illum " + std::to_string(mtl.illum) + ") ignores Kd");
    m = Material::make_mirror(mtl.name, ks);
  } else if (!ks.is_black() && ns >= 1000.0f && kd.is_black()) {
    m = Material::make_mirror(mtl.name, ks);
  } else if (!ks.is_black()) {
    bool scaled = false;
    for (int c = 0; c < 3; ++c) {
      const float sum = kd[c] + ks[c];
      if (sum > 1.0f) {
        kd[c] /= sum;
        ks[c] /= sum;
        scaled = true;
      }
    }
    if (scaled) warnings.push_back(where + ": Kd + Ks exceeds 1; both scaled down to conserve energy");
    m = Material::make_glossy(mtl.name, kd, ks, ns);
  } else {
    m = Material::make_diffuse(mtl.name, kd);
  }
  m.emission = Rgb(std::max(0.0f, float(mtl.emission[0])), std::max(0.0f, float(mtl.emission[1])),
                   std::max(0.0f, float(mtl.emission[2])));
  return m;
}

/// Key of one OBJ corner: position, texture coordinate and normal indices.
using Corner = std::tuple<int, int, int>;

}  // namespace

void load_obj(const fs::path& path, Scene& scene) {
  const std::string file = path.string();
  check_obj_text(path);

  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(file, config)) {
    const std::string error = reader.Error();
    throw InputError(file + ": " + (error.empty() ? std::string("cannot read OBJ file") : error));
  }
  std::istringstream warnings(reader.Warning());
  for (std::string w; std::getline(warnings, w);)
    if (!w.empty()) scene.warnings.push_back(file + ": " + w);

  const tinyobj::attrib_t& attrib = reader.GetAttrib();
  const std::vector<tinyobj::material_t>& mtls = reader.GetMaterials();
  const auto first_material = static_cast<uint32_t>(scene.materials.size());
  bool textures = false;
  for (const tinyobj::material_t& mtl : mtls) {
    scene.materials.push_back(convert_material(mtl, file, scene.warnings));
    textures = textures || !mtl.diffuse_texname.empty() || !mtl.specular_texname.empty() ||
               !mtl.bump_texname.empty() || !mtl.emissive_texname.empty() || !mtl.alpha_texname.empty();
  }
  if (textures) scene.warnings.push_back(file + ": texture maps are ignored");

  // Gather the triangles of each material (−1: faces without usemtl, or with an unknown name).
  std::map<int, std::vector<tinyobj::index_t>> corners_of;
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const tinyobj::mesh_t& mesh = shape.mesh;
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const size_t n = mesh.num_face_vertices[f];
      if (n == 3) {
        const int material = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
        auto& corners = corners_of[material >= 0 && size_t(material) < mtls.size() ? material : -1];
        corners.insert(corners.end(), mesh.indices.begin() + offset, mesh.indices.begin() + offset + 3);
      }
      offset += n;
    }
  }

  const std::string stem = path.stem().string();
  const auto file_index = int32_t(scene.model_files.size());
  scene.model_files.push_back(file);
  if (corners_of.empty()) scene.warnings.push_back(file + ": no faces");
  for (const auto& [material, corners] : corners_of) {
    TriangleMesh mesh;
    mesh.origin.file = file_index;
    if (material >= 0) {
      mesh.material = first_material + uint32_t(material);
      mesh.name = stem + ":" + mtls[size_t(material)].name;
    } else {
      mesh.material = static_cast<uint32_t>(scene.materials.size());
      mesh.name = stem + ":default";
      scene.materials.push_back(Material::make_diffuse("default", Rgb(0.8f)));
    }
    // Shading normals and uvs only when every corner of the mesh has one.
    bool has_normals = true, has_uvs = true;
    for (const tinyobj::index_t& c : corners) {
      has_normals = has_normals && c.normal_index >= 0;
      has_uvs = has_uvs && c.texcoord_index >= 0;
    }
    std::map<Corner, uint32_t> vertex_of;
    mesh.indices.reserve(corners.size());
    for (const tinyobj::index_t& c : corners) {
      const Corner key{c.vertex_index, has_uvs ? c.texcoord_index : -1, has_normals ? c.normal_index : -1};
      auto [it, inserted] = vertex_of.try_emplace(key, static_cast<uint32_t>(mesh.positions.size()));
      if (inserted) {
        const size_t v = size_t(c.vertex_index), t = size_t(c.texcoord_index), n = size_t(c.normal_index);
        // check_obj_text vouches for the indices; this guards against the two parsers disagreeing.
        if (3 * v + 2 >= attrib.vertices.size() || (has_normals && 3 * n + 2 >= attrib.normals.size()) ||
            (has_uvs && 2 * t + 1 >= attrib.texcoords.size()))
          throw InputError(file +
                           ": a face refers to a vertex, normal or texture coordinate that does not exist");
        mesh.positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1],
                                    attrib.vertices[3 * v + 2]);
        mesh.origin.vertex.push_back(uint32_t(v));
        if (has_normals)
          mesh.normals.emplace_back(attrib.normals[3 * n], attrib.normals[3 * n + 1],
                                    attrib.normals[3 * n + 2]);
        if (has_uvs) mesh.uvs.emplace_back(attrib.texcoords[2 * t], attrib.texcoords[2 * t + 1]);
      }
      mesh.indices.push_back(it->second);
    }
    scene.meshes.push_back(std::move(mesh));
  }
}

}  // namespace gilt::raytrace_core
