// `--onto input` for OBJ: the input's text is copied line by line, and each `v` line gets its
// colour appended after the position, whose text is kept as written (so the coordinates are the
// input's to the bit). `mtllib` paths are rewritten to reach the same MTL files from the output's
// folder; the MTL files, and the textures they name relative to themselves, are not copied.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "radiosity/bake/onto_input.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/util/staged_file.h"

namespace gilt::radiosity::bake {


namespace fs = std::filesystem;
using rc::InputError;

namespace {

/// The first `n` whitespace-separated tokens of `s` with the spaces between them, as written.
std::string_view first_tokens(std::string_view s, int n) {
  size_t at = 0;
  for (int k = 0; k < n; ++k) {
    at = s.find_first_not_of(" \t", at);
    if (at == std::string_view::npos) return {};
    at = s.find_first_of(" \t", at);
    if (at == std::string_view::npos) return s;
  }
  return s.substr(0, at);
}

}  // namespace

void write_onto_obj(const std::string& input, const std::string& output, const InputColours& colours,
                    const ExportSettings& settings) {
  std::ifstream in(input, std::ios::binary);
  if (!in) throw InputError(input + ": cannot open file");
  const fs::path in_folder = fs::absolute(input).lexically_normal().parent_path();
  const fs::path out_folder = fs::absolute(output).lexically_normal().parent_path();
  const float scale = std::exp2(settings.exposure);
  std::string out = "# vertex colours by gilt radiosity --onto input: ";
  out += to_string(settings.quantity);
  out += " times 2^exposure, clamped to 0..1, sRGB-encoded (display values, as Blender and MeshLab read them); exposure";
  append_float(out, settings.exposure);
  out += '\n';
  size_t vertex = 0, line_number = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_number;
    const bool crlf = !line.empty() && line.back() == '\r';
    if (crlf) line.pop_back();
    const size_t first = line.find_first_not_of(" \t");
    const std::string_view body = first == std::string::npos ? std::string_view() : std::string_view(line).substr(first);
    if (body.size() > 1 && body[0] == 'v' && (body[1] == ' ' || body[1] == '\t')) {
      if (body.back() == '\\')
        throw InputError(input + ":" + std::to_string(line_number) + ": a `v` line continued with '\\' is not supported");
      out.append(line, 0, first);
      out += first_tokens(body, 4);  // "v x y z": any w or colour after it is replaced
      const Rgb c = vertex < colours.per_file_vertex.size() ? colours.per_file_vertex[vertex] : Rgb(0.0f);
      for (int k = 0; k < 3; ++k) append_float(out, to_srgb(c[k], scale));
      ++vertex;
    } else if (body.rfind("mtllib", 0) == 0 && body.size() > 6 && (body[6] == ' ' || body[6] == '\t')) {
      out.append(line, 0, first);
      out += "mtllib";
      std::istringstream names{std::string(body.substr(6))};
      for (std::string name; names >> name;) {
        const fs::path target = fs::path(name).is_absolute() ? fs::path(name) : (in_folder / name).lexically_normal();
        const fs::path relative = target.lexically_relative(out_folder);
        out += ' ';
        out += (relative.empty() ? target : relative).generic_string();
      }
    } else {
      out += line;
    }
    if (crlf) out += '\r';
    out += '\n';
  }
  if (vertex < colours.per_file_vertex.size())
    throw std::logic_error("write_onto_obj: the file has fewer vertices than were read from it");
  rc::util::StagedFile(output, out).commit();
}

}  // namespace gilt::radiosity::bake
