#pragma once
// The header of a PLY file (Turk's polygon file format), parsed strictly: OpenMesh's own parser
// loops forever on some malformed headers. Shared by the loader and by `--onto input`, which
// writes a PLY back with properties added.

#include <cstddef>
#include <istream>
#include <string>
#include <vector>

namespace gilt::raytrace_core::io {

struct PlyProperty {
  std::string name;
  std::string type;        // value type (of the items, for a list)
  std::string count_type;  // list length type; empty for a scalar
};

struct PlyElement {
  std::string name;
  size_t count = 0;
  std::vector<PlyProperty> properties;
};

struct PlyHeader {
  std::string format;  // ascii, binary_little_endian or binary_big_endian
  std::vector<PlyElement> elements;
  size_t lines = 0;  // header lines, so body line numbers follow on
};

/// Bytes of a PLY scalar type, or 0 for an unknown type.
size_t type_size(const std::string& t);

/// The whitespace-separated tokens of a line.
std::vector<std::string> tokens_of(const std::string& line);

/// Reads the header up to and including `end_header`, leaving `in` at the body; throws
/// InputError naming the file and line. Requires a vertex element with x, y and z, and a face
/// element (if any) with a vertex_indices (or vertex_index) list.
PlyHeader read_header(std::istream& in, const std::string& file);

}  // namespace gilt::raytrace_core::io
