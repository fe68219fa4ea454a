// PLY header parsing (see ply_header.h).

#include "raytrace_core/io/ply_header.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <sstream>
#include <system_error>

#include "raytrace_core/util/error.h"

namespace gilt::raytrace_core::io {

size_t type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

std::vector<std::string> tokens_of(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> tokens;
  for (std::string t; in >> t;) tokens.push_back(t);
  return tokens;
}

namespace {

bool is_identifier(const std::string& s) {
  return !s.empty() &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isalnum(c) || c == '_'; });
}

}  // namespace

PlyHeader read_header(std::istream& in, const std::string& file) {
  PlyHeader header;
  const auto fail = [&](const std::string& what) {
    throw InputError(file + ":" + std::to_string(header.lines) + ": " + what);
  };
  for (std::string line; std::getline(in, line);) {
    ++header.lines;
    const std::vector<std::string> t = tokens_of(line);
    if (header.lines == 1) {
      if (t.size() != 1 || t[0] != "ply") fail("not a PLY file (no 'ply' magic line)");
      continue;
    }
    if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
    if (!std::all_of(line.begin(), line.end(),
                     [](unsigned char c) { return (c >= 0x20 && c < 0x7f) || std::isspace(c); }))
      fail("the header holds a character that is not printable ASCII");
    if (t[0] == "end_header") break;
    if (t[0] == "format") {
      if (t.size() != 3 || t[2] != "1.0" ||
          (t[1] != "ascii" && t[1] != "binary_little_endian" && t[1] != "binary_big_endian"))
        fail("unknown PLY format (expected ascii, binary_little_endian or binary_big_endian 1.0)");
      header.format = t[1];
    } else if (t[0] == "element") {
      size_t count = 0;
      if (t.size() != 3 || !is_identifier(t[1])) fail("malformed 'element' line");
      const auto [end, error] = std::from_chars(t[2].data(), t[2].data() + t[2].size(), count);
      if (error != std::errc() || end != t[2].data() + t[2].size())
        fail("malformed 'element' line (the count must be a whole number below 2^64)");
      if (std::any_of(header.elements.begin(), header.elements.end(),
                      [&](const PlyElement& e) { return e.name == t[1]; }))
        fail("element '" + t[1] + "' declared twice");
      header.elements.push_back({t[1], count, {}});
    } else if (t[0] == "property") {
      if (header.elements.empty()) fail("'property' before any 'element'");
      const bool list = t.size() == 5 && t[1] == "list";
      const bool integer_count =
          list && type_size(t[2]) != 0 && t[2].find("float") == std::string::npos && t[2] != "double";
      if ((t.size() != 3 && !list) || (list && !integer_count) || type_size(t[t.size() - 2]) == 0 ||
          !is_identifier(t.back()))
        fail("malformed 'property' line");
      header.elements.back().properties.push_back({t.back(), t[t.size() - 2], list ? t[2] : ""});
    } else {
      fail("unknown header keyword '" + t[0] + "'");
    }
  }
  if (in.eof()) throw InputError(file + ": the header has no 'end_header'");
  if (header.format.empty()) fail("no 'format' line in the header");
  // A mesh needs vertices with x, y, z, and faces (if any) with a list of vertex indices.
  const auto has = [](const PlyElement& e, std::initializer_list<const char*> names, bool list) {
    return std::any_of(e.properties.begin(), e.properties.end(), [&](const PlyProperty& p) {
      return (p.count_type.empty() != list) && std::find(names.begin(), names.end(), p.name) != names.end();
    });
  };
  bool vertices = false;
  for (const PlyElement& e : header.elements) {
    if (e.name == "vertex") vertices = has(e, {"x"}, false) && has(e, {"y"}, false) && has(e, {"z"}, false);
    if (e.name == "face" && !has(e, {"vertex_indices", "vertex_index"}, true))
      fail("the face element has no 'vertex_indices' list");
  }
  if (!vertices) fail("no vertex element with x, y and z");
  return header;
}

}  // namespace gilt::raytrace_core::io
