// PLY meshes (ascii and binary) through OpenMesh, with one default diffuse material.
//
// OpenMesh skips faces whose indices are out of range and reads "nan" in ascii files as garbage,
// saying so only on its own error stream. So the header and body are walked here first, checking
// that coordinates are finite and face indices name a vertex, with messages that give the line
// (ascii) or the element (binary); then OpenMesh reads the mesh, its error stream captured.

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/PolyMesh_ArrayKernelT.hh>

#include "raytrace_core/error.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/io/ply_header.h"

namespace gilt::raytrace_core {

namespace fs = std::filesystem;

namespace {

using PlyMesh = OpenMesh::PolyMesh_ArrayKernelT<>;

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

/// Checks every vertex coordinate is finite and every face index names a vertex.
void check_body(std::istream& in, const PlyHeader& header, const std::string& file) {
  size_t vertex_count = 0;
  for (const PlyElement& e : header.elements)
    if (e.name == "vertex") vertex_count = e.count;
  PlyValues values(in, header, file);
  for (const PlyElement& element : header.elements) {
    for (size_t item = 0; item < element.count; ++item) {
      values.begin_item(element.name, item);
      for (const PlyProperty& p : element.properties) {
        const bool is_list = !p.count_type.empty();
        const double length = is_list ? values.next(p.count_type) : 1.0;
        if (!(length >= 0.0 && length <= 1e6 && length == std::floor(length))) values.fail("bad list length");
        const bool coordinate = element.name == "vertex" && (p.name == "x" || p.name == "y" || p.name == "z");
        const bool indices =
            element.name == "face" && (p.name == "vertex_indices" || p.name == "vertex_index");
        if (indices && length < 3) values.fail("a face needs at least 3 vertices");
        for (size_t j = 0; j < size_t(length); ++j) {
          const double v = values.next(p.type);
          if (coordinate && !std::isfinite(float(v)))
            values.fail("coordinate " + p.name + " is not a finite number");
          if (indices && !(v >= 0.0 && v < double(vertex_count) && v == std::floor(v))) {
            // Printed as the number it is: 2e62 does not fit a long long, and casting it is undefined.
            char shown[32];
            std::snprintf(shown, sizeof shown, "%.15g", v);
            values.fail("face refers to vertex " + std::string(shown) + " of " + std::to_string(vertex_count));
          }
        }
      }
    }
  }
}

/// Routes OpenMesh's global error stream into a string while alive (one reader at a time).
class CaptureOpenMeshErrors {
 public:
  CaptureOpenMeshErrors() : lock_(mutex()) {
    ::omerr().connect(captured_);
    to_cerr_ = ::omerr().disconnect(std::cerr);
  }
  ~CaptureOpenMeshErrors() {
    ::omerr().flush();
    ::omerr().disconnect(captured_);
    if (to_cerr_) ::omerr().connect(std::cerr);
  }
  std::string text() {
    ::omerr().flush();
    return captured_.str();
  }

 private:
  static std::mutex& mutex() {
    static std::mutex m;
    return m;
  }
  std::lock_guard<std::mutex> lock_;
  std::ostringstream captured_;
  bool to_cerr_ = false;
};

}  // namespace

void load_ply(const fs::path& path, Scene& scene) {
  const std::string file = path.string();
  size_t declared_faces = 0, declared_vertices = 0;
  bool has_colours = false;
  {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(file + ": cannot open file");
    const PlyHeader header = read_header(in, file);
    check_body(in, header, file);
    for (const PlyElement& e : header.elements) {
      if (e.name == "face") declared_faces = e.count;
      if (e.name == "vertex") declared_vertices = e.count;
      for (const PlyProperty& p : e.properties)
        has_colours = has_colours || (e.name == "vertex" && (p.name == "red" || p.name == "diffuse_red"));
    }
  }

  PlyMesh om;
  om.request_vertex_normals();
  OpenMesh::IO::Options options = OpenMesh::IO::Options::VertexNormal;
  {
    CaptureOpenMeshErrors capture;
    if (!OpenMesh::IO::read_mesh(om, file, options)) {
      const std::string errors = capture.text();
      const std::string first = errors.substr(0, errors.find('\n'));
      throw InputError(file + ": cannot read PLY file" + (first.empty() ? "" : " (" + first + ")"));
    }
  }
  // Indices were checked above, so the faces OpenMesh could not add repeat a vertex. (It keeps
  // non-manifold faces, giving them copies of their vertices.)
  if (om.n_faces() < declared_faces)
    scene.warnings.push_back(file + ": " + std::to_string(declared_faces - om.n_faces()) +
                             " face(s) with a repeated vertex dropped");

  TriangleMesh mesh;
  mesh.name = path.stem().string();
  mesh.origin.file = int32_t(scene.model_files.size());
  scene.model_files.push_back(file);
  mesh.positions.reserve(om.n_vertices());
  for (const auto& v : om.vertices()) {
    const auto& p = om.point(v);
    mesh.positions.emplace_back(p[0], p[1], p[2]);
  }
  // OpenMesh reads the file's vertices in order and appends the copies it makes for non-manifold
  // faces; each copy is traced back to the file's vertex at the same position.
  if (mesh.positions.size() > declared_vertices) {
    std::map<std::array<float, 3>, uint32_t> file_vertex;
    for (uint32_t v = 0; v < declared_vertices && v < mesh.positions.size(); ++v)
      file_vertex.try_emplace({mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z}, v);
    mesh.origin.vertex.resize(mesh.positions.size());
    for (uint32_t v = 0; v < mesh.positions.size(); ++v) {
      if (v < declared_vertices) {
        mesh.origin.vertex[v] = v;
        continue;
      }
      const auto it = file_vertex.find({mesh.positions[v].x, mesh.positions[v].y, mesh.positions[v].z});
      mesh.origin.vertex[v] = it != file_vertex.end() ? it->second : 0;  // a copy always has an original
    }
  }
  if (options.check(OpenMesh::IO::Options::VertexNormal))
    for (const auto& v : om.vertices()) {
      const auto& n = om.normal(v);
      mesh.normals.emplace_back(n[0], n[1], n[2]);  // copies of non-manifold vertices read 0: ng is used
    }
  for (const auto& f : om.faces()) {
    std::vector<uint32_t> loop;
    for (const auto& v : om.fv_range(f)) loop.push_back(static_cast<uint32_t>(v.idx()));
    for (size_t i = 1; i + 1 < loop.size(); ++i)
      mesh.indices.insert(mesh.indices.end(), {loop[0], loop[i], loop[i + 1]});
  }

  mesh.material = static_cast<uint32_t>(scene.materials.size());
  scene.materials.push_back(Material::make_diffuse("default", Rgb(0.8f)));
  std::string note = file + ": a PLY holds geometry only: diffuse albedo 0.8, no lights";
  if (has_colours) note += "; vertex colours ignored";
  scene.warnings.push_back(note);
  if (mesh.indices.empty()) scene.warnings.push_back(file + ": no faces");
  scene.meshes.push_back(std::move(mesh));
}

}  // namespace gilt::raytrace_core
