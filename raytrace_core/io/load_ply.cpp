// PLY meshes (ascii and binary), read by gilt's own strict parser, with one default diffuse
// material.
//
// OpenMesh's PLY reader was used before. It parses the header token by token, unlike the line by
// line format, and loops on a stream it has failed: an `obj_info` line that holds "element vertex
// 99999999999" made it allocate without end, and a value too many on an ascii line shifted every
// later one. The body is already walked here to check it (coordinates finite, face indices naming
// a vertex, with the line or element in the message), so the mesh is built from that same walk:
// one parser decides what the file says.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/io/ply_header.h"

namespace gilt::raytrace_core::io {

namespace fs = std::filesystem;

namespace {

/// The values of a PLY body one by one, ascii or binary, with where() naming the position.
class PlyValues {
 public:
  PlyValues(std::istream& in, const PlyHeader& header, std::string file)
      : in_(in), file_(std::move(file)), format_(header.format), line_(header.lines) {
    if (format_ != "ascii")
      bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }

  /// Moves to the next element item (the next non-blank line of an ascii file).
  void begin_item(const std::string& element, size_t item) {
    element_ = element;
    item_ = item;
    if (format_ != "ascii") return;
    std::string line;
    do {
      if (!std::getline(in_, line)) fail("the file ends early");
      ++line_;
    } while (line.find_first_not_of(" \t\r") == std::string::npos);
    tokens_ = tokens_of(line);
    next_token_ = 0;
  }

  /// Ends an item: an ascii line must hold exactly the values its element declares.
  void end_item() {
    if (format_ == "ascii" && next_token_ != tokens_.size())
      fail(std::to_string(tokens_.size()) + " values on the line, " + std::to_string(next_token_) +
           " declared");
  }

  double next(const std::string& type) {
    double value = 0.0;
    if (format_ == "ascii") {
      if (next_token_ >= tokens_.size()) fail("too few values on the line");
      const std::string& t = tokens_[next_token_++];
      const char* first = t.data() + (t.front() == '+' ? 1 : 0);
      const auto [end, err] = std::from_chars(first, t.data() + t.size(), value);
      if (err != std::errc() || end != t.data() + t.size())
        value = std::nan("");  // not a number: the caller reports it where it matters
      return value;
    }
    const size_t size = type_size(type);
    if (offset_ + size > bytes_.size()) fail("the file ends early");
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + offset_, size);
    offset_ += size;
    if (format_ == "binary_big_endian") std::reverse(raw, raw + size);
    const auto as = [&](auto v) {
      std::memcpy(&v, raw, sizeof v);
      return double(v);
    };
    if (type == "char" || type == "int8") return as(int8_t());
    if (type == "uchar" || type == "uint8") return as(uint8_t());
    if (type == "short" || type == "int16") return as(int16_t());
    if (type == "ushort" || type == "uint16") return as(uint16_t());
    if (type == "int" || type == "int32") return as(int32_t());
    if (type == "uint" || type == "uint32") return as(uint32_t());
    if (type == "float" || type == "float32") return as(float());
    return as(double());
  }

  [[noreturn]] void fail(const std::string& what) const {
    const std::string where = format_ == "ascii" ? file_ + ":" + std::to_string(line_) : file_;
    throw InputError(where + ": " + element_ + " " + std::to_string(item_) + ": " + what);
  }

 private:
  std::istream& in_;
  std::string file_, format_, element_;
  size_t line_ = 0, item_ = 0;
  std::vector<std::string> tokens_;
  size_t next_token_ = 0;
  std::vector<unsigned char> bytes_;
  size_t offset_ = 0;
};

/// What a PLY body holds for gilt: vertex positions (and normals, when the file has all three),
/// and the faces fanned into triangles.
struct PlyBody {
  std::vector<Vec3> positions, normals;
  std::vector<uint32_t> indices;
  size_t faces_with_repeats = 0;  // faces that name a vertex twice: their degenerate fans dropped
};

/// Walks the body value by value: checks every coordinate is finite and every face index names a
/// vertex (throwing InputError at the line or element), and keeps what the mesh needs.
PlyBody read_body(std::istream& in, const PlyHeader& header, const std::string& file) {
  size_t vertex_count = 0;
  bool has_normals = false;
  for (const PlyElement& e : header.elements) {
    if (e.name != "vertex") continue;
    vertex_count = e.count;
    int normal_axes = 0;
    for (const PlyProperty& p : e.properties)
      normal_axes += p.count_type.empty() && (p.name == "nx" || p.name == "ny" || p.name == "nz");
    has_normals = normal_axes == 3;
  }
  if (vertex_count > size_t(std::numeric_limits<uint32_t>::max()))
    throw InputError(file + ": " + std::to_string(vertex_count) + " vertices: more than 32-bit indices reach");
  PlyBody body;
  PlyValues values(in, header, file);
  std::vector<uint32_t> loop;
  for (const PlyElement& element : header.elements) {
    // An item without properties holds nothing to walk, however many the header declares.
    if (element.properties.empty()) continue;
    const bool vertex = element.name == "vertex", face = element.name == "face";
    for (size_t item = 0; item < element.count; ++item) {
      values.begin_item(element.name, item);
      Vec3 position(0.0f), normal(0.0f);
      for (const PlyProperty& p : element.properties) {
        const bool is_list = !p.count_type.empty();
        const double length = is_list ? values.next(p.count_type) : 1.0;
        if (!(length >= 0.0 && length <= 1e6 && length == std::floor(length))) values.fail("bad list length");
        const int axis = !vertex || is_list ? -1 : p.name == "x" ? 0 : p.name == "y" ? 1 : p.name == "z" ? 2 : -1;
        const int normal_axis =
            !vertex || is_list ? -1 : p.name == "nx" ? 0 : p.name == "ny" ? 1 : p.name == "nz" ? 2 : -1;
        const bool indices = face && is_list && (p.name == "vertex_indices" || p.name == "vertex_index");
        if (indices && length < 3) values.fail("a face needs at least 3 vertices");
        if (indices) loop.clear();
        for (size_t j = 0; j < size_t(length); ++j) {
          const double v = values.next(p.type);
          if (axis >= 0) {
            if (!std::isfinite(float(v))) values.fail("coordinate " + p.name + " is not a finite number");
            position[axis] = float(v);
          }
          if (normal_axis >= 0) normal[normal_axis] = std::isfinite(float(v)) ? float(v) : 0.0f;
          if (indices) {
            if (!(v >= 0.0 && v < double(vertex_count) && v == std::floor(v))) {
              // Printed as the number it is: 2e62 does not fit a long long, and casting it is undefined.
              char shown[32];
              std::snprintf(shown, sizeof shown, "%.15g", v);
              values.fail("face refers to vertex " + std::string(shown) + " of " + std::to_string(vertex_count));
            }
            loop.push_back(uint32_t(v));
          }
        }
        if (indices) {
          // A fan triangle that names a vertex twice has no area: it is left out, the rest kept.
          bool repeats = false;
          for (size_t i = 1; i + 1 < loop.size(); ++i) {
            const uint32_t a = loop[0], b = loop[i], c = loop[i + 1];
            if (a == b || b == c || a == c) {
              repeats = true;
              continue;
            }
            body.indices.insert(body.indices.end(), {a, b, c});
          }
          body.faces_with_repeats += repeats;
        }
      }
      values.end_item();
      if (vertex) {
        body.positions.push_back(position);
        if (has_normals) body.normals.push_back(normal);
      }
    }
  }
  return body;
}

}  // namespace

void load_ply(const fs::path& path, scene::Scene& scene) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file + ": cannot open file");
  const PlyHeader header = read_header(in, file);
  PlyBody body = read_body(in, header, file);
  bool has_colours = false;
  for (const PlyElement& e : header.elements)
    for (const PlyProperty& p : e.properties)
      has_colours = has_colours || (e.name == "vertex" && (p.name == "red" || p.name == "diffuse_red"));
  if (body.faces_with_repeats > 0)
    scene.warnings.push_back(file + ": " + std::to_string(body.faces_with_repeats) +
                             " face(s) name a vertex twice: their triangles without area dropped");

  scene::TriangleMesh mesh;
  mesh.name = path.stem().string();
  mesh.origin.file = int32_t(scene.model_files.size());
  scene.model_files.push_back(file);
  mesh.positions = std::move(body.positions);
  mesh.normals = std::move(body.normals);  // a zero normal (or none) makes the geometric one used
  mesh.indices = std::move(body.indices);
  mesh.material = static_cast<uint32_t>(scene.materials.size());
  scene.materials.push_back(scene::Material::make_diffuse("default", Rgb(0.8f)));
  scene.warnings.push_back(ply_default_material_note(file));
  if (has_colours) scene.warnings.push_back(file + ": vertex colours ignored");
  if (mesh.indices.empty()) scene.warnings.push_back(file + ": no faces");
  scene.meshes.push_back(std::move(mesh));
}

std::string ply_default_material_note(const std::string& file) {
  return file + ": a PLY holds geometry only: diffuse albedo 0.8, no lights";
}

}  // namespace gilt::raytrace_core::io
