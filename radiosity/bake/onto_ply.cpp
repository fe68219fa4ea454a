// `--onto input` for PLY: the input's header and body are copied, in its own format (ascii or
// binary of either byte order), with properties added to the vertex element:
//   red green blue (uchar): the quantity × 2^exposure as 8-bit sRGB, what MeshLab and Blender
//     show as a PLY's vertex colour;
//   <quantity>_red, _green, _blue (float): the quantity itself, linear and unclamped.
// Colour properties the input had under those names are replaced; every other property, element,
// comment and value is kept as written (ascii tokens as text, binary records as bytes).

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "radiosity/bake/onto_input.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/io/ply_header.h"
#include "raytrace_core/util/staged_file.h"

namespace gilt::radiosity::bake {


using rc::InputError;

namespace {

/// An unsigned integer of `size` bytes in the file's byte order.
uint64_t read_count(const std::string& bytes, size_t at, size_t size, bool big_endian) {
  unsigned char raw[8] = {};
  std::memcpy(raw, bytes.data() + at, size);
  if (big_endian) std::reverse(raw, raw + size);
  uint64_t v = 0;
  for (size_t k = 0; k < size; ++k) v |= uint64_t(raw[k]) << (8 * k);
  return v;
}

void append_float(std::string& out, float x, bool big_endian) {
  char raw[4];
  std::memcpy(raw, &x, 4);
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(raw, raw + 4);
  out.append(raw, 4);
}

/// A PLY file being rewritten with vertex colours: its bytes, header, where its body starts, and
/// what is written for each vertex.
struct PlyRewrite {
  const std::string& input;
  std::string bytes;
  rc::io::PlyHeader header;
  size_t body = 0;
  std::string quantity;
  float scale = 1.0f;
  const InputColours& colours;

  /// Whether a vertex property is one the colours replace.
  bool replaced(const std::string& name) const {
    for (const char* c : {"red", "green", "blue"})
      if (name == c || name == quantity + "_" + c) return true;
    return false;
  }
  Rgb colour(size_t v) const { return v < colours.per_file_vertex.size() ? colours.per_file_vertex[v] : Rgb(0.0f); }
};

/// Reads the input's header; appends it to `out` less the replaced vertex properties, plus the
/// new ones after the vertex element's last property.
void rewrite_header(const PlyRewrite& ply, std::string& out) {
  std::istringstream lines(ply.bytes.substr(0, ply.body));
  std::string element;
  const auto add_properties = [&] {
    for (const char* c : {"red", "green", "blue"}) out += std::string("property uchar ") + c + "\n";
    for (const char* c : {"red", "green", "blue"}) out += "property float " + ply.quantity + "_" + c + "\n";
  };
  for (std::string line; std::getline(lines, line);) {
    const std::vector<std::string> t = rc::io::tokens_of(line);
    if (!t.empty() && (t[0] == "element" || t[0] == "end_header") && element == "vertex") add_properties();
    if (!t.empty() && t[0] == "element") element = t.size() > 1 ? t[1] : "";
    if (!t.empty() && t[0] == "end_header") element.clear();
    if (element == "vertex" && t.size() >= 3 && t[0] == "property" && ply.replaced(t.back())) continue;
    if (!t.empty() && t[0] == "comment" && line.find("gilt radiosity --onto input") != std::string::npos) continue;
    out += line;
    out += '\n';
    if (!t.empty() && t[0] == "format")  // after it: OpenMesh wants the format line second
      out += "comment vertex colours by gilt radiosity --onto input: red green blue are " + ply.quantity +
             " x 2^exposure as sRGB, " + ply.quantity + "_* the linear values\n";
  }
}

/// Reads an ASCII body; appends it to `out` with each vertex's replaced values left out and its
/// colours added, and anything after the last element kept.
void rewrite_ascii_body(const PlyRewrite& ply, std::string& out) {
  const std::string& input = ply.input;
  std::istringstream lines(ply.bytes.substr(ply.body));
  std::string line;
  for (const rc::io::PlyElement& e : ply.header.elements)
    for (size_t item = 0; item < e.count; ++item) {
      do {
        if (!std::getline(lines, line)) throw InputError(input + ": " + e.name + " " + std::to_string(item) + ": the file ends early");
        if (!line.empty() && line.back() == '\r') line.pop_back();
      } while (line.find_first_not_of(" \t") == std::string::npos);
      if (e.name != "vertex") {
        out += line;
        out += '\n';
        continue;
      }
      const std::vector<std::string> t = rc::io::tokens_of(line);
      size_t at = 0;
      std::string kept;
      for (const rc::io::PlyProperty& p : e.properties) {
        size_t n = 1;
        if (!p.count_type.empty()) {
          if (at >= t.size()) throw InputError(input + ": vertex " + std::to_string(item) + ": too few values");
          n = 1 + size_t(std::max(0.0, std::stod(t[at])));
        }
        for (size_t k = 0; k < n; ++k, ++at) {
          if (at >= t.size()) throw InputError(input + ": vertex " + std::to_string(item) + ": too few values");
          if (ply.replaced(p.name)) continue;
          if (!kept.empty()) kept += ' ';
          kept += t[at];
        }
      }
      out += kept;
      const Rgb c = ply.colour(item);
      char buffer[96];
      std::snprintf(buffer, sizeof buffer, " %d %d %d %.9g %.9g %.9g", int(to_srgb8(c.r, ply.scale)),
                    int(to_srgb8(c.g, ply.scale)), int(to_srgb8(c.b, ply.scale)), double(c.r), double(c.g),
                    double(c.b));
      out += buffer;
      out += '\n';
    }
  // Anything after the last element is kept.
  out += std::string(std::istreambuf_iterator<char>(lines), std::istreambuf_iterator<char>());
}

/// Reads a binary body (either byte order); appends it to `out` with each vertex's replaced
/// properties left out and its colours added, and anything after the last element kept.
void rewrite_binary_body(const PlyRewrite& ply, std::string& out) {
  const std::string& bytes = ply.bytes;
  const bool big = ply.header.format == "binary_big_endian";
  size_t at = ply.body;
  const auto need = [&](size_t n, const std::string& what) {
    if (n > bytes.size() - at) throw InputError(ply.input + ": " + what + ": the file ends early");
  };
  for (const rc::io::PlyElement& e : ply.header.elements)
    for (size_t item = 0; item < e.count; ++item) {
      const std::string what = e.name + " " + std::to_string(item);
      const size_t start = at;
      for (const rc::io::PlyProperty& p : e.properties) {
        const size_t first = at;
        if (!p.count_type.empty()) {
          const size_t count_size = rc::io::type_size(p.count_type);
          need(count_size, what);
          const uint64_t n = read_count(bytes, at, count_size, big);
          at += count_size;
          const size_t item_size = rc::io::type_size(p.type);
          if (n > (bytes.size() - at) / item_size) throw InputError(ply.input + ": " + what + ": the file ends early");
          at += size_t(n) * item_size;
        } else {
          need(rc::io::type_size(p.type), what);
          at += rc::io::type_size(p.type);
        }
        if (e.name == "vertex" && !ply.replaced(p.name)) out.append(bytes, first, at - first);
      }
      if (e.name != "vertex") {
        out.append(bytes, start, at - start);
        continue;
      }
      const Rgb c = ply.colour(item);
      for (int k = 0; k < 3; ++k) out += char(to_srgb8(c[k], ply.scale));
      for (int k = 0; k < 3; ++k) append_float(out, c[k], big);
    }
  out.append(bytes, at, std::string::npos);
}

}  // namespace

void write_onto_ply(const std::string& input, const std::string& output, const InputColours& colours,
                    const ExportSettings& settings) {
  std::ifstream in(input, std::ios::binary);
  if (!in) throw InputError(input + ": cannot open file");
  PlyRewrite ply{input, std::string{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()}, {}, 0,
                 to_string(settings.quantity), std::exp2(settings.exposure), colours};
  std::istringstream header_stream(ply.bytes);
  ply.header = rc::io::read_header(header_stream, input);
  ply.body = size_t(header_stream.tellg());
  std::string out;
  rewrite_header(ply, out);
  if (ply.header.format == "ascii")
    rewrite_ascii_body(ply, out);
  else
    rewrite_binary_body(ply, out);
  rc::util::StagedFile(output, out).commit();
}

}  // namespace gilt::radiosity::bake
