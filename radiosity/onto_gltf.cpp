// `--onto input` for glTF: the input's JSON is edited rather than re-encoded, so whatever gilt
// does not understand (animations, skins, extensions, extras, texture samplers) passes through
// as it was, and the input's buffers are copied byte for byte. New data (the colour accessors)
// go in one buffer: the GLB binary chunk, extended, or a new buffer.

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>

#include <nlohmann/json.hpp>

#include "radiosity/onto_input.h"
#include "raytrace_core/error.h"
#include "raytrace_core/loaders.h"
#include "raytrace_core/staged_file.h"

namespace gilt::radiosity {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using rc::InputError;

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A, kChunkBin = 0x004E4942;
constexpr int kArrayBuffer = 34962, kFloat = 5126;

struct GltfFile {
  Json json;
  std::string bin;  ///< a GLB's binary chunk
  bool has_bin = false;
};

uint32_t read_u32(const std::string& bytes, size_t at) {
  uint32_t v = 0;
  std::memcpy(&v, bytes.data() + at, 4);
  return v;
}

void append_u32(std::string& out, uint32_t v) {
  char b[4];
  std::memcpy(b, &v, 4);
  out.append(b, 4);
}

GltfFile read_gltf_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open file");
  const std::string bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  GltfFile file;
  std::string json_text = bytes;
  if (rc::lower_extension(path) == ".glb") {
    if (bytes.size() < 20 || read_u32(bytes, 0) != kGlbMagic || read_u32(bytes, 4) != 2)
      throw InputError(path + ": not a GLB 2.0 file");
    const size_t total = std::min<size_t>(read_u32(bytes, 8), bytes.size());
    json_text.clear();
    bool first = true;
    for (size_t at = 12; at + 8 <= total;) {
      const size_t length = read_u32(bytes, at), type = read_u32(bytes, at + 4);
      if (length > total - at - 8) throw InputError(path + ": GLB chunk reaches past the end of the file");
      if (first && type != kChunkJson) throw InputError(path + ": GLB does not start with its JSON chunk");
      if (first) json_text = bytes.substr(at + 8, length);
      if (!first && type == kChunkBin && !file.has_bin) {
        file.bin = bytes.substr(at + 8, length);
        file.has_bin = true;
      }
      first = false;
      at += 8 + length;
    }
    if (first) throw InputError(path + ": GLB has no chunks");
  }
  try {
    file.json = Json::parse(json_text);
  } catch (const std::exception& e) {
    throw InputError(path + ": invalid glTF JSON (" + std::string(e.what()) + ")");
  }
  if (!file.json.is_object()) throw InputError(path + ": glTF JSON is not an object");
  return file;
}

/// The array `key` of the top-level object, created empty when missing.
Json& array(Json& j, const char* key) {
  if (!j.contains(key) || !j[key].is_array()) j[key] = Json::array();
  return j[key];
}

std::string percent_decode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += char(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

std::string percent_encode(const std::string& s) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (const unsigned char c : s) {
    if (std::isalnum(c) || std::strchr("-._~/!$&'()*+,;=:@", c) != nullptr) {
      out += char(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

bool is_relative_uri(const std::string& uri) {
  if (uri.rfind("data:", 0) == 0) return false;
  const size_t colon = uri.find(':'), slash = uri.find('/');
  return (colon == std::string::npos || (slash != std::string::npos && slash < colon)) && !uri.empty() &&
         uri[0] != '/';
}

/// Points each relative buffer and image URI at the same file from `to_folder`; collects the
/// files they name.
void rebase_uris(Json& j, const fs::path& from_folder, const fs::path& to_folder, std::vector<fs::path>& files) {
  for (const char* key : {"buffers", "images"}) {
    if (!j.contains(key) || !j[key].is_array()) continue;
    for (Json& item : j[key]) {
      if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
      const std::string uri = item["uri"];
      if (!is_relative_uri(uri)) continue;
      const fs::path target = (from_folder / percent_decode(uri)).lexically_normal();
      files.push_back(target);
      const fs::path relative = target.lexically_relative(to_folder);
      item["uri"] = percent_encode((relative.empty() ? target : relative).generic_string());
    }
  }
}

void align4(std::string& bytes, char pad) {
  while (bytes.size() % 4 != 0) bytes += pad;
}

std::string read_bytes(const fs::path& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(what + ": cannot read " + path.string());
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// For a GLB output: moves the buffers and images the input keeps in files beside it into the
/// binary chunk (buffer 0), so the GLB stands alone as GLB files are expected to. Buffer views
/// are redirected with their offsets; images get a buffer view and a MIME type (PNG, JPEG, WebP
/// and KTX2 by extension; others keep their URI).
void pack_into_binary_chunk(GltfFile& file, const fs::path& in_folder, const std::string& input) {
  Json& j = file.json;
  Json& buffers = array(j, "buffers");
  Json& views = array(j, "bufferViews");
  if (!file.has_bin) {  // buffer 0 becomes the binary chunk
    buffers.insert(buffers.begin(), Json{{"byteLength", 0}});
    for (Json& v : views)
      if (v.contains("buffer") && v["buffer"].is_number_integer()) v["buffer"] = v["buffer"].get<int64_t>() + 1;
    file.has_bin = true;
  }
  std::vector<int64_t> moved_to(buffers.size(), 0);
  std::vector<size_t> offset(buffers.size(), 0);
  Json kept = Json::array();
  kept.push_back(buffers[0]);
  for (size_t k = 1; k < buffers.size(); ++k) {
    const Json& b = buffers[k];
    const std::string uri = b.contains("uri") && b["uri"].is_string() ? b["uri"].get<std::string>() : "";
    if (!is_relative_uri(uri)) {
      moved_to[k] = int64_t(kept.size());
      kept.push_back(b);
      continue;
    }
    align4(file.bin, '\0');
    offset[k] = file.bin.size();
    file.bin += read_bytes(in_folder / percent_decode(uri), input + ": buffer " + std::to_string(k));
  }
  for (Json& v : views) {
    if (!v.contains("buffer") || !v["buffer"].is_number_integer()) continue;
    const auto b = size_t(v["buffer"].get<int64_t>());
    if (b >= moved_to.size() || b == 0) continue;
    v["buffer"] = moved_to[b];
    if (moved_to[b] == 0) v["byteOffset"] = v.value("byteOffset", size_t(0)) + offset[b];
  }
  buffers = std::move(kept);
  if (!j.contains("images") || !j["images"].is_array()) return;
  for (Json& image : j["images"]) {
    if (!image.is_object() || !image.contains("uri") || !image["uri"].is_string()) continue;
    const std::string uri = image["uri"];
    if (!is_relative_uri(uri)) continue;
    const std::string ext = rc::lower_extension(percent_decode(uri));
    const char* mime = ext == ".png"                      ? "image/png"
                       : ext == ".jpg" || ext == ".jpeg" ? "image/jpeg"
                       : ext == ".webp"                  ? "image/webp"
                       : ext == ".ktx2"                  ? "image/ktx2"
                                                         : nullptr;
    if (mime == nullptr) continue;
    align4(file.bin, '\0');
    const size_t at = file.bin.size();
    file.bin += read_bytes(in_folder / percent_decode(uri), input + ": image " + uri);
    views.push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", file.bin.size() - at}});
    image.erase("uri");
    image["bufferView"] = views.size() - 1;
    image["mimeType"] = mime;
  }
  buffers[0]["byteLength"] = file.bin.size();
}

const char* attribute_name(Quantity q) {
  return q == Quantity::irradiance ? "_IRRADIANCE" : q == Quantity::radiosity ? "_RADIOSITY" : "_RADIANCE";
}

}  // namespace

void write_onto_gltf(const std::string& input, const std::string& output, const rc::Scene& scene,
                     const InputColours& colours, const ExportSettings& settings) {
  GltfFile file = read_gltf_file(input);
  Json& j = file.json;
  const bool glb_out = rc::lower_extension(output) == ".glb";
  const fs::path out_path = fs::absolute(output).lexically_normal();
  const fs::path out_folder = out_path.parent_path();
  const fs::path in_folder = fs::absolute(input).lexically_normal().parent_path();

  if (glb_out) pack_into_binary_chunk(file, in_folder, input);
  std::vector<fs::path> input_files;
  rebase_uris(j, in_folder, out_folder, input_files);

  // The primitives to colour, by node, and the nodes that place each mesh.
  std::map<int32_t, std::vector<size_t>> scene_meshes_of_node;
  std::map<int32_t, std::vector<int32_t>> nodes_of_mesh;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const rc::MeshOrigin& o = scene.meshes[m].origin;
    if (o.file != colours.file || colours.per_mesh[m].empty()) continue;
    auto& list = scene_meshes_of_node[o.node];
    if (list.empty()) {
      auto& nodes = nodes_of_mesh[o.mesh];
      if (std::find(nodes.begin(), nodes.end(), o.node) == nodes.end()) nodes.push_back(o.node);
    }
    list.push_back(m);
  }

  Json& meshes = array(j, "meshes");
  Json& nodes = array(j, "nodes");
  Json& accessors = array(j, "accessors");
  Json& views = array(j, "bufferViews");
  Json& buffers = array(j, "buffers");

  // A mesh placed by several coloured nodes: every node after the first gets its own copy.
  std::map<int32_t, int32_t> mesh_of_node;
  for (const auto& [mesh, placed_by] : nodes_of_mesh)
    for (size_t k = 0; k < placed_by.size(); ++k) {
      int32_t index = mesh;
      if (k > 0) {
        index = int32_t(meshes.size());
        Json copy = meshes[size_t(mesh)];
        const std::string name = copy.value("name", std::string("mesh") + std::to_string(mesh));
        copy["name"] = name + " (node " + std::to_string(placed_by[k]) + ")";
        meshes.push_back(std::move(copy));
        nodes[size_t(placed_by[k])]["mesh"] = index;
      }
      mesh_of_node[placed_by[k]] = index;
    }

  // The new buffer's bytes, and where they go.
  const bool extend_bin = file.has_bin;
  std::string data;
  const size_t base = extend_bin ? (file.bin.size() + 3) / 4 * 4 : 0;
  std::vector<Json> new_views;
  const float scale = std::exp2(settings.exposure);
  const auto add_accessor = [&](const std::vector<Rgb>& values, bool clamp) {
    align4(data, '\0');
    Json view = {{"byteOffset", base + data.size()}, {"byteLength", values.size() * 12}, {"target", kArrayBuffer}};
    for (const Rgb& c : values)
      for (int k = 0; k < 3; ++k) {
        const float x = clamp ? std::clamp(c[k] * scale, 0.0f, 1.0f) : c[k];
        char b[4];
        std::memcpy(b, &x, 4);
        data.append(b, 4);
      }
    new_views.push_back(std::move(view));
    accessors.push_back({{"bufferView", views.size() + new_views.size() - 1},
                         {"componentType", kFloat},
                         {"count", values.size()},
                         {"type", "VEC3"}});
    return accessors.size() - 1;
  };
  for (const auto& [node, list] : scene_meshes_of_node) {
    Json& primitives = meshes[size_t(mesh_of_node.at(node))]["primitives"];
    for (size_t m : list) {
      const std::vector<Rgb>& values = colours.per_mesh[m];
      Json& attributes = primitives[size_t(scene.meshes[m].origin.primitive)]["attributes"];
      const Json& position = accessors[size_t(attributes["POSITION"].get<int64_t>())];
      if (position.value("count", size_t(0)) != values.size())
        throw std::logic_error("write_onto_gltf: vertex count of a primitive changed while loading");
      attributes["COLOR_0"] = add_accessor(values, true);
      attributes[attribute_name(settings.quantity)] = add_accessor(values, false);
    }
  }

  if (data.empty())
    throw InputError(input + ": no surface of the model holds a solution (mirrors and glass are not baked)");

  // Place the buffer: the GLB chunk, extended; or a new buffer (first in a GLB, whose binary chunk
  // is buffer 0; last in a .gltf, with a .bin beside it).
  size_t buffer_index = 0;
  std::string bin;
  if (extend_bin) {
    bin = std::move(file.bin);
    align4(bin, '\0');
    bin += data;
  } else {
    bin = std::move(data);
    if (glb_out) {
      buffers.insert(buffers.begin(), Json::object());
      for (Json& v : views)
        if (v.contains("buffer") && v["buffer"].is_number_integer()) v["buffer"] = v["buffer"].get<int64_t>() + 1;
    } else {
      buffers.push_back(Json::object());
      buffer_index = buffers.size() - 1;
    }
  }
  for (Json& v : new_views) {
    v["buffer"] = buffer_index;
    views.push_back(std::move(v));
  }
  buffers[buffer_index]["byteLength"] = bin.size();
  fs::path sidecar;
  if (!glb_out) {
    sidecar = out_path;
    sidecar.replace_extension(".bin");
    for (const fs::path& f : input_files) {
      std::error_code ec;
      if (f == sidecar || fs::equivalent(f, sidecar, ec))
        throw InputError("-o " + output + ": its buffer " + sidecar.string() + " would overwrite the input's " +
                         f.string() + "; choose another name or folder");
    }
    buffers[buffer_index]["uri"] = percent_encode(sidecar.filename().string());
  } else {
    buffers[buffer_index].erase("uri");
  }

  if (glb_out) {
    std::string json_text = j.dump();
    align4(json_text, ' ');
    align4(bin, '\0');
    if (12 + 8 + json_text.size() + 8 + bin.size() > UINT32_MAX)
      throw InputError("-o " + output + ": a GLB holds at most 4 GiB; write .gltf instead");
    std::string out;
    append_u32(out, kGlbMagic);
    append_u32(out, 2);
    append_u32(out, uint32_t(12 + 8 + json_text.size() + 8 + bin.size()));
    append_u32(out, uint32_t(json_text.size()));
    append_u32(out, kChunkJson);
    out += json_text;
    append_u32(out, uint32_t(bin.size()));
    append_u32(out, kChunkBin);
    out += bin;
    rc::StagedFile(out_path, out).commit();
  } else {
    rc::StagedFile bin_file(sidecar, bin);
    rc::StagedFile gltf_file(out_path, j.dump(2) + "\n");
    bin_file.commit();  // the .bin first: the .gltf never names a buffer that is not there
    gltf_file.commit();
  }
}

}  // namespace gilt::radiosity
