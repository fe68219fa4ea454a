// Wavefront OBJ + MTL through tinyobjloader, split into one triangle mesh per material.
//
// tinyobjloader reads "nan" as 0 and skips faces with out-of-range indices with a warning, so a
// first pass over the text checks coordinates and face indices and reports the offending line.
// It also takes a name (newmtl, usemtl, map_Kd) to run to the end of its line and a '#' after a
// face for one more corner, so it is handed the text with every comment already cut off.
//
// MTL → Material (documented in docs/scene-format.md):
//   Ke                                  → emission (emitted radiance, front face only)
//   illum 4, 6, 7 or 9, or d < 1        → dielectric, ior = Ni (1.5 when Ni ≤ 1, i.e. unset),
//                                         GGX roughness Pr (0 when unset: a perfect interface);
//                                         σa = −ln(Tf) per scene unit when Tf is neither black
//                                         (unset) nor white
//   illum 3, 5 or 8 and max(Ks) ≥ 0.5   → mirror, reflectance Ks (ray-traced reflection models)
//   Ks ≠ 0, Ns < 1000                   → glossy: albedo Kd, specular Ks, Phong exponent Ns
//   Ks ≠ 0, Ns ≥ 1000, Kd = 0           → mirror, reflectance Ks (a lobe that sharp is a mirror)
//   Ks ≠ 0, Ns ≥ 1000, Kd ≠ 0           → glossy with exponent Ns
//   otherwise                           → diffuse, albedo Kd
//   map_Kd (diffuse and glossy)         → albedo texture: albedo = Kd × texel; -o, -s, -clamp kept
//   map_d (not on mirrors and glass)    → alpha MASK at 0.5 (a cut-out), the image read as data
// Kd and Ks are clamped to [0, 1] and, where Kd + Ks > 1 in a channel, both are scaled down so the
// sum is 1 (energy conservation), with a warning. Ka and map_Ka are ignored; other maps are
// ignored with one warning per file.

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

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/loaders.h"

namespace gilt::raytrace_core::io {

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

/// The file's text with each line cut at its first '#' and stripped of trailing blanks (a '\r'
/// included, which tinyobjloader would otherwise keep at the end of a texture name). Line breaks
/// stay, so the line numbers in tinyobjloader's messages still match the file. False when the
/// file cannot be opened.
bool read_without_comments(const fs::path& path, std::string& text) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  text.clear();
  std::string line;
  while (std::getline(in, line)) {
    size_t end = std::min(line.find('#'), line.size());
    while (end > 0 && std::isspace(static_cast<unsigned char>(line[end - 1]))) --end;
    text.append(line, 0, end);
    text += '\n';
  }
  return true;
}

/// A map_Kd statement: the file name as written and the options the loader honours.
struct DiffuseMap {
  std::string name;                 ///< empty: the material has no map_Kd
  float scale[2] = {1.0f, 1.0f};    ///< -s u v
  float offset[2] = {0.0f, 0.0f};   ///< -o u v
  bool clamp = false;               ///< -clamp on
  bool linear = false;              ///< -colorspace linear (tinyobjloader's extension)
  bool kd_given = false;            ///< the material has a Kd line of its own
  bool pbr_given = false;           ///< the material has a Pr or Pm line (the PBR extension)
};

/// Parses what follows "map_Kd" on a comment-free line: options, then the file name, which runs
/// to the end of the line (names may hold spaces). We read the options ourselves because
/// tinyobjloader always takes three numbers after -o, -s and -t, so "-s 2 2 -o 0.5 0" loses
/// the -o; the MTL format lets the v and w numbers be left out. Throws InputError "file:line".
DiffuseMap parse_map_kd(std::string_view rest, const fs::path& path, size_t line_no) {
  const auto fail = [&](const std::string& what) {
    throw InputError(path.string() + ":" + std::to_string(line_no) + ": map_Kd " + what);
  };
  const auto is_blank = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  size_t i = 0;
  // The next blank-separated token, without consuming it.
  const auto peek = [&]() {
    size_t a = i;
    while (a < rest.size() && is_blank(rest[a])) ++a;
    size_t b = a;
    while (b < rest.size() && !is_blank(rest[b])) ++b;
    return std::pair<size_t, size_t>(a, b);
  };
  const auto next = [&]() {
    const auto [a, b] = peek();
    i = b;
    return rest.substr(a, b - a);
  };
  // Up to `most` numbers, at least one; the missing ones keep their defaults.
  const auto numbers = [&](std::string_view option, float* out, int most) {
    int n = 0;
    for (double x = 0.0; n < most;) {
      const auto [a, b] = peek();
      if (!finite_number(rest.substr(a, b - a), x)) break;
      if (n < 2) out[n] = float(x);  // w, the third, has no use on a surface
      i = b;
      ++n;
    }
    if (n == 0) fail(std::string(option) + " needs a number");
  };
  DiffuseMap map;
  for (;;) {
    const auto [a, b] = peek();
    const std::string_view option = rest.substr(a, b - a);
    if (option.empty()) fail("names no file");
    if (option == "-s" || option == "-o" || option == "-t") {
      i = b;
      float ignored[2] = {0.0f, 0.0f};
      numbers(option, option == "-s" ? map.scale : option == "-o" ? map.offset : ignored, 3);
    } else if (option == "-mm") {
      i = b;
      float ignored[2] = {0.0f, 1.0f};
      numbers(option, ignored, 2);
    } else if (option == "-clamp" || option == "-blendu" || option == "-blendv" || option == "-cc") {
      i = b;
      const std::string_view value = next();
      if (value != "on" && value != "off") fail(std::string(option) + " needs on or off");
      if (option == "-clamp") map.clamp = value == "on";
    } else if (option == "-colorspace" || option == "-boost" || option == "-bm" || option == "-texres" ||
               option == "-imfchan" || option == "-type") {
      i = b;
      const std::string_view value = next();
      if (value.empty()) fail(std::string(option) + " needs a value");
      if (option == "-colorspace") map.linear = value == "linear";
    } else {
      map.name = std::string(rest.substr(a));
      return map;
    }
  }
}

/// Reads the MTL files an OBJ names, from the OBJ's folder, without their comments. For each
/// material it notes the folder of its MTL file (texture names are relative to that) and its
/// map_Kd as parse_map_kd reads it.
class MtlReader : public tinyobj::MaterialReader {
 public:
  explicit MtlReader(fs::path obj_folder) : obj_folder_(std::move(obj_folder)) {}

  bool operator()(const std::string& name, std::vector<tinyobj::material_t>* materials,
                  std::map<std::string, int>* material_map, std::string* warn, std::string* err) override {
    const fs::path path = obj_folder_ / name;
    std::string text;
    if (!read_without_comments(path, text)) {
      if (warn) *warn += "material file " + path.string() + " not found\n";
      return false;
    }
    // tinyobjloader adds a material at each "newmtl" with a name, in order; so does this scan.
    std::vector<DiffuseMap> maps;
    std::istringstream lines(text);
    std::string line;
    for (size_t line_no = 1; std::getline(lines, line); ++line_no) {
      const std::vector<std::string_view> tokens = split_whitespace(line);
      if (tokens.size() >= 2 && tokens[0] == "newmtl") {
        maps.emplace_back();
      } else if (!tokens.empty() && tokens[0] == "Kd" && !maps.empty()) {
        maps.back().kd_given = true;
      } else if (!tokens.empty() && (tokens[0] == "Pr" || tokens[0] == "Pm") && !maps.empty()) {
        maps.back().pbr_given = true;
      } else if (tokens.size() >= 1 && tokens[0] == "map_Kd" && !maps.empty() && error_.empty()) {
        const size_t at = size_t(tokens[0].data() - line.data()) + tokens[0].size();
        try {
          const bool kd_given = maps.back().kd_given, pbr_given = maps.back().pbr_given;
          maps.back() = parse_map_kd(std::string_view(line).substr(at), path, line_no);
          maps.back().kd_given = kd_given;
          maps.back().pbr_given = pbr_given;
        } catch (const InputError& e) {
          error_ = e.what();  // thrown once tinyobjloader has returned, not through it
        }
      }
    }
    const size_t first = materials->size();
    std::istringstream in(text);
    tinyobj::LoadMtl(material_map, materials, &in, warn, err);
    folder_of_material.resize(materials->size(), path.parent_path());
    if (maps.size() != materials->size() - first) {
      // The two readers disagree on where materials begin: take tinyobjloader's reading.
      maps.assign(materials->size() - first, DiffuseMap{});
      for (size_t k = 0; k < maps.size(); ++k) {
        const tinyobj::material_t& mtl = (*materials)[first + k];
        const tinyobj::texture_option_t& o = mtl.diffuse_texopt;
        maps[k].name = mtl.diffuse_texname;
        maps[k].scale[0] = float(o.scale[0]), maps[k].scale[1] = float(o.scale[1]);
        maps[k].offset[0] = float(o.origin_offset[0]), maps[k].offset[1] = float(o.origin_offset[1]);
        maps[k].clamp = o.clamp;
        maps[k].linear = o.colorspace == "linear";
        maps[k].kd_given = true;
      }
    }
    // A texture without Kd gets tinyobjloader's default Kd of 0.6 (as Assimp's too), but its
    // "Kd seen" flag outlives the material that set it, leaving later ones at 0: set it here.
    for (size_t k = 0; k < maps.size(); ++k)
      if (!maps[k].name.empty() && !maps[k].kd_given)
        for (tinyobj::real_t& c : (*materials)[first + k].diffuse) c = tinyobj::real_t(0.6);
    diffuse_map_of_material.insert(diffuse_map_of_material.end(), maps.begin(), maps.end());
    return true;
  }

  /// Throws the first malformed map_Kd found, if any.
  void throw_if_failed() const {
    if (!error_.empty()) throw InputError(error_);
  }

  std::vector<fs::path> folder_of_material;        ///< the MTL file's folder, per material read
  std::vector<DiffuseMap> diffuse_map_of_material;  ///< map_Kd, per material read

 private:
  fs::path obj_folder_;
  std::string error_;
};

/// The image file an MTL names, looked for relative to the MTL's folder (or as it is, when
/// absolute). MTL files written on Windows separate folders with '\', so that spelling is tried
/// with '/' too. Empty when there is no such file.
std::string find_texture_file(const fs::path& folder, const std::string& name) {
  std::vector<std::string> spellings{name};
  if (name.find('\\') != std::string::npos) {
    std::string slashed = name;
    std::replace(slashed.begin(), slashed.end(), '\\', '/');
    spellings.push_back(slashed);
  }
  for (const std::string& spelling : spellings) {
    const fs::path candidate = (folder / spelling).lexically_normal();
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec)) return candidate.string();
  }
  return {};
}

/// Index of `image` in the scene's textures, added when no equal entry is there yet, so that
/// materials sharing a file (sibenik's walls all read kamen.png) open and cache it once.
int32_t texture_index(std::vector<scene::TextureImage>& textures, const scene::TextureImage& image) {
  for (size_t i = 0; i < textures.size(); ++i) {
    const scene::TextureImage& t = textures[i];
    if (t.file == image.file && t.srgb == image.srgb && t.wrap_s == image.wrap_s && t.wrap_t == image.wrap_t)
      return int32_t(i);
  }
  textures.push_back(image);
  return int32_t(textures.size() - 1);
}

/// The texture reference of a map_Kd: the image, and the map from OBJ's (u, v) to OpenImageIO's
/// (s, t). The -s and -o options act on (u, v) first (u' = scale·u + offset, as most MTL
/// readers take them), then v' is flipped because OBJ's v runs up the image and t runs down it.
scene::TextureRef diffuse_texture_ref(int32_t image, const DiffuseMap& map) {
  scene::TextureRef ref;
  ref.image = image;
  ref.map = {map.scale[0], 0.0f, map.offset[0], 0.0f, map.scale[1], map.offset[1]};
  return ref.then({1.0f, 0.0f, 0.0f, 0.0f, -1.0f, 1.0f});
}

/// The kinds of map the loader cannot use that `mtl` names, in words for the warning.
void unused_maps(const tinyobj::material_t& mtl, std::vector<std::string>& kinds) {
  const std::pair<const std::string*, const char*> maps[] = {
      {&mtl.specular_texname, "specular maps (map_Ks)"},
      {&mtl.specular_highlight_texname, "exponent maps (map_Ns)"},
      {&mtl.displacement_texname, "displacement maps (disp)"},
      {&mtl.reflection_texname, "reflection maps (refl)"},
      {&mtl.roughness_texname, "roughness maps (map_Pr)"},
      {&mtl.metallic_texname, "metallic maps (map_Pm)"},
      {&mtl.sheen_texname, "sheen maps (map_Ps)"},
  };
  for (const auto& [name, kind] : maps)
    if (!name->empty() && std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) kinds.push_back(kind);
}

/// "a", "a and b", "a, b and c".
std::string join_words(const std::vector<std::string>& words) {
  std::string out;
  for (size_t i = 0; i < words.size(); ++i) {
    if (i > 0) out += i + 1 == words.size() ? " and " : ", ";
    out += words[i];
  }
  return out;
}

Rgb rgb(const tinyobj::real_t c[3]) { return {float(c[0]), float(c[1]), float(c[2])}; }

bool is_one_of(int value, std::initializer_list<int> set) {
  for (int v : set)
    if (v == value) return true;
  return false;
}

scene::Material convert_material(const tinyobj::material_t& mtl, const std::string& file,
                          std::vector<std::string>& warnings) {
  const std::string where = file + ": material '" + mtl.name + "'";
  Rgb kd = clamp(rgb(mtl.diffuse), 0.0f, 1.0f);
  Rgb ks = clamp(rgb(mtl.specular), 0.0f, 1.0f);
  const Rgb tf = rgb(mtl.transmittance);
  const float ns = std::max(0.0f, float(mtl.shininess));
  scene::Material m;

  if (is_one_of(mtl.illum, {4, 6, 7, 9}) || mtl.dissolve < 1.0f) {
    float ior = float(mtl.ior);
    if (!(ior > 1.0f)) {
      warnings.push_back(where + ": transparent without Ni > 1; using ior 1.5");
      ior = 1.5f;
    }
    Rgb absorption(0.0f);
    if (!tf.is_black() && !(tf == Rgb(1.0f)))
      for (int c = 0; c < 3; ++c) absorption[c] = -std::log(std::clamp(tf[c], 1e-4f, 1.0f));
    m = scene::Material::make_dielectric(mtl.name, ior, absorption);
  } else if (is_one_of(mtl.illum, {3, 5, 8}) && ks.max_component() >= 0.5f) {
    if (!kd.is_black())
      warnings.push_back(where + ": mirror (illum " + std::to_string(mtl.illum) + ") ignores Kd");
    m = scene::Material::make_mirror(mtl.name, ks);
  } else if (!ks.is_black() && ns >= 1000.0f && kd.is_black()) {
    m = scene::Material::make_mirror(mtl.name, ks);
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
    m = scene::Material::make_glossy(mtl.name, kd, ks, ns);
  } else {
    m = scene::Material::make_diffuse(mtl.name, kd);
  }
  m.emission = Rgb(std::max(0.0f, float(mtl.emission[0])), std::max(0.0f, float(mtl.emission[1])),
                   std::max(0.0f, float(mtl.emission[2])));
  return m;
}

/// Key of one OBJ corner: position, texture coordinate and normal indices.
using Corner = std::tuple<int, int, int>;

// --- load_obj's passes, in the order it runs them. ---

/// What load_obj's passes share: the OBJ file, and what tinyobjloader reads from it and from the
/// MTL files it names (filled by read_obj).
struct ObjFile {
  explicit ObjFile(const fs::path& p) : path(p), file(p.string()), mtl_reader(p.parent_path()) {}
  const fs::path& path;
  const std::string file;  ///< path as given, for messages
  MtlReader mtl_reader;
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> mtls;
};

/// Pass 1. Reads the OBJ file (checked first by check_obj_text) and its MTL files; writes obj's
/// attrib, shapes, mtls and mtl_reader, and tinyobjloader's warnings to `warnings`. Throws
/// InputError when the file cannot be read or a map_Kd is malformed.
void read_obj(ObjFile& obj, std::vector<std::string>& warnings) {
  check_obj_text(obj.path);

  std::string obj_text;
  if (!read_without_comments(obj.path, obj_text)) throw InputError(obj.file + ": cannot open file");
  std::istringstream obj_stream(obj_text);
  std::string warning, error;
  if (!tinyobj::LoadObj(&obj.attrib, &obj.shapes, &obj.mtls, &warning, &error, &obj_stream, &obj.mtl_reader,
                        /*triangulate=*/true, /*default_vcols_fallback=*/false))
    throw InputError(obj.file + ": " + (error.empty() ? std::string("cannot read OBJ file") : error));
  std::istringstream lines(warning);
  for (std::string w; std::getline(lines, w);)
    if (!w.empty()) warnings.push_back(obj.file + ": " + w);

  obj.mtl_reader.throw_if_failed();
}

/// Adds `kind` to `kinds` unless it is there already.
void note_once(std::vector<std::string>& kinds, const char* kind) {
  if (std::find(kinds.begin(), kinds.end(), kind) == kinds.end()) kinds.push_back(kind);
}

/// Whether material i was read by the MtlReader (else tinyobjloader made it up).
bool read_by_mtl_reader(const ObjFile& obj, size_t i) { return i < obj.mtl_reader.diffuse_map_of_material.size(); }

/// The folder material i's texture names are relative to: its MTL file's, else the OBJ's.
fs::path material_folder(const ObjFile& obj, size_t i) {
  return read_by_mtl_reader(obj, i) ? obj.mtl_reader.folder_of_material[i] : obj.path.parent_path();
}

/// Pass 2a, for material i and its map_Kd `diffuse`. Reads whether the image file exists; writes
/// m's albedo texture (its image added to scene.textures), or a warning to scene.warnings when
/// it would not show or is not found, or the kind to `ignored_maps` on mirrors and glass.
void apply_map_kd(scene::Material& m, const ObjFile& obj, size_t i, const DiffuseMap& diffuse,
                  scene::Scene& scene, std::vector<std::string>& ignored_maps) {
  const tinyobj::material_t& mtl = obj.mtls[i];
  if (!diffuse.name.empty() &&
      (m.kind == scene::MaterialKind::mirror || m.kind == scene::MaterialKind::dielectric)) {
    note_once(ignored_maps, "map_Kd of mirror and glass materials");
  } else if (!diffuse.name.empty() && m.albedo.is_black()) {
    scene.warnings.push_back(obj.file + ": material '" + mtl.name + "': Kd is black, so map_Kd " + diffuse.name +
                             " would not show; left untextured");
  } else if (!diffuse.name.empty()) {
    const fs::path folder = material_folder(obj, i);
    scene::TextureImage image;
    image.file = find_texture_file(folder, diffuse.name);
    if (image.file.empty()) {
      const std::string where = folder.empty() ? std::string(".") : folder.string();
      scene.warnings.push_back(obj.file + ": material '" + mtl.name + "': texture '" + diffuse.name +
                               "' not found in " + where + "; left untextured");
    } else {
      image.srgb = !diffuse.linear;
      image.wrap_s = image.wrap_t = diffuse.clamp ? scene::TextureWrap::clamp : scene::TextureWrap::repeat;
      m.albedo_texture = diffuse_texture_ref(texture_index(scene.textures, image), diffuse);
    }
  }
}

/// A map of material i other than map_Kd, with tinyobjloader's reading of its options (-s, -o,
/// -clamp): its reference (the image added to scene.textures), or none, with a warning to
/// scene.warnings ending in `fallback`, when the file is not found.
scene::TextureRef read_texture_map(const ObjFile& obj, size_t i, const std::string& texname,
                            const tinyobj::texture_option_t& o, bool srgb, const char* key, const char* fallback,
                            scene::Scene& scene) {
  const fs::path folder = material_folder(obj, i);
  scene::TextureImage image;
  image.file = find_texture_file(folder, texname);
  if (image.file.empty()) {
    const std::string where = folder.empty() ? std::string(".") : folder.string();
    scene.warnings.push_back(obj.file + ": material '" + obj.mtls[i].name + "': " + key + " '" + texname +
                             "' not found in " + where + "; " + fallback);
    return scene::TextureRef{};
  }
  DiffuseMap map;
  map.scale[0] = float(o.scale[0]), map.scale[1] = float(o.scale[1]);
  map.offset[0] = float(o.origin_offset[0]), map.offset[1] = float(o.origin_offset[1]);
  image.srgb = srgb;
  image.wrap_s = image.wrap_t = o.clamp ? scene::TextureWrap::clamp : scene::TextureWrap::repeat;
  return diffuse_texture_ref(texture_index(scene.textures, image), map);
}

/// Pass 2b, for material i. Reads its map_d, map_Ke, norm and bump; writes m's alpha, emission
/// and normal textures (read_texture_map), warnings to scene.warnings, and the kinds it leaves
/// out to `ignored_maps`.
void apply_other_maps(scene::Material& m, const ObjFile& obj, size_t i, scene::Scene& scene,
                      std::vector<std::string>& ignored_maps) {
  const tinyobj::material_t& mtl = obj.mtls[i];
  // map_d: a cut-out (leaves, fences), its image read as data; coverage below one half is not
  // there.
  if (!mtl.alpha_texname.empty() && m.is_traced_through()) {
    note_once(ignored_maps, "map_d of mirror and glass materials");
  } else if (!mtl.alpha_texname.empty()) {
    const scene::TextureRef ref =
        read_texture_map(obj, i, mtl.alpha_texname, mtl.alpha_texopt, false, "map_d", "left opaque", scene);
    if (ref.valid()) {
      m.alpha_mode = scene::AlphaMode::mask;
      m.alpha_cutoff = 0.5f;
      m.alpha_in_colour = true;
      m.alpha_texture = ref;
    }
  }
  // map_Ke: the emission is Ke × the texel (sRGB, as colour maps are), as map_Kd scales Kd.
  if (!mtl.emissive_texname.empty() && !m.is_emissive()) {
    scene.warnings.push_back(obj.file + ": material '" + mtl.name + "': Ke is black, so map_Ke " +
                             mtl.emissive_texname + " would not show; ignored");
  } else if (!mtl.emissive_texname.empty()) {
    m.emission_texture = read_texture_map(obj, i, mtl.emissive_texname, mtl.emissive_texopt, true, "map_Ke",
                                          "emission untextured", scene);
  }
  // norm: a tangent-space normal map; bump (map_Bump): a height map, its heights times -bm.
  // Both are data, read linear.
  if (!mtl.normal_texname.empty()) {
    m.normal_texture =
        read_texture_map(obj, i, mtl.normal_texname, mtl.normal_texopt, false, "norm", "normals left smooth", scene);
    if (!mtl.bump_texname.empty()) note_once(ignored_maps, "bump maps beside a normal map (norm)");
  } else if (!mtl.bump_texname.empty()) {
    m.normal_texture =
        read_texture_map(obj, i, mtl.bump_texname, mtl.bump_texopt, false, "bump", "normals left smooth", scene);
    m.normal_is_height = true;
    m.normal_scale = float(mtl.bump_texopt.bump_multiplier);
  }
}

/// Pass 2, for material i: convert_material, the PBR extension, then passes 2a and 2b. Reads
/// its MTL entry; writes textures and warnings to `scene` and left-out kinds to `ignored_maps`.
scene::Material convert_obj_material(const ObjFile& obj, size_t i, scene::Scene& scene, std::vector<std::string>& ignored_maps) {
  const tinyobj::material_t& mtl = obj.mtls[i];
  scene::Material m = convert_material(mtl, obj.file, scene.warnings);
  unused_maps(mtl, ignored_maps);
  const bool read = read_by_mtl_reader(obj, i);
  const DiffuseMap diffuse = read ? obj.mtl_reader.diffuse_map_of_material[i] : DiffuseMap{};
  // The PBR extension (Pr roughness, Pm metallic): glTF's metallic-roughness model with base
  // colour Kd. Glass and mirrors keep their kind.
  if (diffuse.pbr_given && m.kind == scene::MaterialKind::dielectric) {
    m.roughness = std::clamp(float(mtl.roughness), 0.0f, 1.0f);  // Pr on glass: frosted glass
  } else if (diffuse.pbr_given && !m.is_traced_through()) {
    const Rgb emission = m.emission;
    m = scene::Material::make_metallic_roughness(mtl.name, clamp(rgb(mtl.diffuse), 0.0f, 1.0f),
                                          std::clamp(float(mtl.metallic), 0.0f, 1.0f),
                                          std::clamp(float(mtl.roughness), 0.0f, 1.0f));
    m.emission = emission;
  }
  apply_map_kd(m, obj, i, diffuse, scene, ignored_maps);
  apply_other_maps(m, obj, i, scene, ignored_maps);
  return m;
}

/// Pass 3. Reads the shapes' triangles; returns their corners grouped by material (−1: faces
/// without usemtl, or with an unknown name), in file order within each.
std::map<int, std::vector<tinyobj::index_t>> gather_triangles(const ObjFile& obj) {
  std::map<int, std::vector<tinyobj::index_t>> corners_of;
  for (const tinyobj::shape_t& shape : obj.shapes) {
    const tinyobj::mesh_t& mesh = shape.mesh;
    size_t offset = 0;
    for (size_t f = 0; f < mesh.num_face_vertices.size(); ++f) {
      const size_t n = mesh.num_face_vertices[f];
      if (n == 3) {
        const int material = f < mesh.material_ids.size() ? mesh.material_ids[f] : -1;
        auto& corners = corners_of[material >= 0 && size_t(material) < obj.mtls.size() ? material : -1];
        corners.insert(corners.end(), mesh.indices.begin() + offset, mesh.indices.begin() + offset + 3);
      }
      offset += n;
    }
  }
  return corners_of;
}

/// Which vertex attributes a mesh keeps.
struct CornerAttributes {
  bool normals = false;
  bool uvs = false;
};

/// Pass 4a, for mesh `mesh` of material `material`. Reads its corners: shading normals and uvs
/// only when every corner has one; but a textured material keeps the uvs its faces have, corners
/// without one reading the texture at (0, 0) (with a warning to `warnings`).
CornerAttributes corner_attributes(const std::vector<tinyobj::index_t>& corners,
                                   const scene::Material& material, const std::string& file,
                                   const scene::TriangleMesh& mesh, std::vector<std::string>& warnings) {
  bool has_normals = true, all_uvs = true, some_uvs = false;
  size_t corners_without_uv = 0;
  for (const tinyobj::index_t& c : corners) {
    has_normals = has_normals && c.normal_index >= 0;
    all_uvs = all_uvs && c.texcoord_index >= 0;
    some_uvs = some_uvs || c.texcoord_index >= 0;
    if (c.texcoord_index < 0) ++corners_without_uv;
  }
  const bool has_uvs = all_uvs || (some_uvs && material.is_textured());
  if (has_uvs && !all_uvs)
    warnings.push_back(file + ": mesh '" + mesh.name + "': " + std::to_string(corners_without_uv) +
                       " face corner(s) without texture coordinates read the texture at (0, 0)");
  return {has_normals, has_uvs};
}

/// Pass 4b. Reads the corners and obj.attrib; writes mesh's vertices (one per distinct corner
/// of the kept attributes, in order of first use), their file vertex (origin.vertex) and its
/// indices. Throws InputError on an index past tinyobjloader's arrays.
void weld_corners(scene::TriangleMesh& mesh, const std::vector<tinyobj::index_t>& corners,
                  CornerAttributes kept, const ObjFile& obj) {
  const tinyobj::attrib_t& attrib = obj.attrib;
  const bool has_normals = kept.normals, has_uvs = kept.uvs;
  std::map<Corner, uint32_t> vertex_of;
  mesh.indices.reserve(corners.size());
  for (const tinyobj::index_t& c : corners) {
    const Corner key{c.vertex_index, has_uvs ? c.texcoord_index : -1, has_normals ? c.normal_index : -1};
    auto [it, inserted] = vertex_of.try_emplace(key, static_cast<uint32_t>(mesh.positions.size()));
    if (inserted) {
      const size_t v = size_t(c.vertex_index), t = size_t(c.texcoord_index), n = size_t(c.normal_index);
      const bool uv = has_uvs && c.texcoord_index >= 0;
      // check_obj_text vouches for the indices; this guards against the two parsers disagreeing.
      if (3 * v + 2 >= attrib.vertices.size() || (has_normals && 3 * n + 2 >= attrib.normals.size()) ||
          (uv && 2 * t + 1 >= attrib.texcoords.size()))
        throw InputError(obj.file + ": a face refers to a vertex, normal or texture coordinate that does not exist");
      mesh.positions.emplace_back(attrib.vertices[3 * v], attrib.vertices[3 * v + 1], attrib.vertices[3 * v + 2]);
      mesh.origin.vertex.push_back(uint32_t(v));
      if (has_normals)
        mesh.normals.emplace_back(attrib.normals[3 * n], attrib.normals[3 * n + 1], attrib.normals[3 * n + 2]);
      if (uv) mesh.uvs.emplace_back(attrib.texcoords[2 * t], attrib.texcoords[2 * t + 1]);
      else if (has_uvs) mesh.uvs.emplace_back(0.0f, 0.0f);
    }
    mesh.indices.push_back(it->second);
  }
}

/// Pass 4. Reads the grouped corners; writes one mesh per material to scene.meshes (a default
/// material to scene.materials for faces without one), the file to scene.model_files, and
/// warnings to scene.warnings.
void build_meshes(const ObjFile& obj, const std::map<int, std::vector<tinyobj::index_t>>& corners_of,
                  uint32_t first_material, scene::Scene& scene) {
  const std::string stem = obj.path.stem().string();
  const auto file_index = int32_t(scene.model_files.size());
  scene.model_files.push_back(obj.file);
  if (corners_of.empty()) scene.warnings.push_back(obj.file + ": no faces");
  for (const auto& [material, corners] : corners_of) {
    scene::TriangleMesh mesh;
    mesh.origin.file = file_index;
    if (material >= 0) {
      mesh.material = first_material + uint32_t(material);
      mesh.name = stem + ":" + obj.mtls[size_t(material)].name;
    } else {
      mesh.material = static_cast<uint32_t>(scene.materials.size());
      mesh.name = stem + ":default";
      scene.materials.push_back(scene::Material::make_diffuse("default", Rgb(0.8f)));
    }
    const CornerAttributes kept =
        corner_attributes(corners, scene.materials[mesh.material], obj.file, mesh, scene.warnings);
    weld_corners(mesh, corners, kept, obj);
    scene.meshes.push_back(std::move(mesh));
  }
}

}  // namespace

// A driver over named passes (above): read the file, convert its materials, gather each
// material's triangles, and make a mesh of each.
void load_obj(const fs::path& path, scene::Scene& scene) {
  ObjFile obj(path);
  read_obj(obj, scene.warnings);

  const auto first_material = static_cast<uint32_t>(scene.materials.size());
  std::vector<std::string> ignored_maps;
  for (size_t i = 0; i < obj.mtls.size(); ++i)
    scene.materials.push_back(convert_obj_material(obj, i, scene, ignored_maps));
  if (!ignored_maps.empty())
    scene.warnings.push_back(obj.file + ": " + join_words(ignored_maps) + " are ignored");

  const std::map<int, std::vector<tinyobj::index_t>> corners_of = gather_triangles(obj);
  build_meshes(obj, corners_of, first_material, scene);
}

}  // namespace gilt::raytrace_core::io
