// `--onto input` for glTF: the input's JSON is edited rather than re-encoded, so whatever gilt
// does not understand (animations, skins, extensions, extras, texture samplers) passes through
// as it was, and the input's buffers are copied byte for byte. New data (the colour accessors)
// go in one buffer: the GLB binary chunk, extended, or a new buffer.

#include <algorithm>
#include <array>
#include <cctype>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <optional>
#include <set>
#include <unordered_map>

#include <nlohmann/json.hpp>
#include <tiny_gltf.h>

#include "raytrace_core/io/gltf_file.h"

#include "radiosity/bake/lightmap.h"
#include "radiosity/bake/onto_input.h"
#include "raytrace_core/util/error.h"
#include "raytrace_core/io/loaders.h"
#include "raytrace_core/util/staged_file.h"

namespace gilt::radiosity::bake {


namespace fs = std::filesystem;
using Json = nlohmann::json;
using rc::InputError;

namespace {

constexpr uint32_t kGlbMagic = 0x46546C67;  // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A, kChunkBin = 0x004E4942;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963, kFloat = 5126, kUnsignedInt = 5125;

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
  if (rc::io::lower_extension(path) == ".glb") {
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
    const std::string ext = rc::io::lower_extension(percent_decode(uri));
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


/// An output being made: the edited (or new) JSON, and the bytes of the new buffer.
struct GltfOutput {
  GltfFile file;
  std::string input;  ///< the model it was read from; empty for a new model
  fs::path out_path;
  bool glb = false;
  std::vector<fs::path> input_files;  ///< files the input's URIs name
  bool extend_bin = false;
  std::string data;
  size_t base = 0;
  std::vector<Json> new_views;

  Json& json() { return file.json; }

  /// Appends `bytes` as a new accessor (with the given componentType, type and count, plus
  /// `fields`), in a buffer view of its own; returns the accessor's index.
  size_t add_accessor(const void* bytes, size_t size, Json fields, bool vertex_data) {
    Json& accessors = array(json(), "accessors");
    const size_t view_count = array(json(), "bufferViews").size();
    align4(data, '\0');
    Json view = {{"byteOffset", base + data.size()}, {"byteLength", size}};
    view["target"] = vertex_data ? kArrayBuffer : kElementArrayBuffer;
    data.append(static_cast<const char*>(bytes), size);
    new_views.push_back(std::move(view));
    fields["bufferView"] = view_count + new_views.size() - 1;
    accessors.push_back(std::move(fields));
    return accessors.size() - 1;
  }
};

/// Reads the input and makes its URIs reach the same files from the output's folder; a GLB output
/// takes the input's external buffers and images into its binary chunk.
GltfOutput begin_output(const std::string& input, const std::string& output) {
  GltfOutput o;
  o.input = input;
  o.file = read_gltf_file(input);
  o.glb = rc::io::lower_extension(output) == ".glb";
  o.out_path = fs::absolute(output).lexically_normal();
  const fs::path in_folder = fs::absolute(input).lexically_normal().parent_path();
  if (o.glb) pack_into_binary_chunk(o.file, in_folder, input);
  rebase_uris(o.file.json, in_folder, o.out_path.parent_path(), o.input_files);
  o.extend_bin = o.file.has_bin;
  o.base = o.extend_bin ? (o.file.bin.size() + 3) / 4 * 4 : 0;
  return o;
}

/// The scene meshes `covered` selects, by the node that placed them; a glTF mesh placed by
/// several of those nodes is copied so that each node has its own (each instance is lit
/// differently), and the copy's index is returned for each node.
std::map<int32_t, std::vector<size_t>> split_instances(Json& j, const rc::scene::Scene& scene, int32_t file,
                                                       const std::function<bool(size_t)>& covered,
                                                       std::map<int32_t, int32_t>& mesh_of_node) {
  std::map<int32_t, std::vector<size_t>> scene_meshes_of_node;
  std::map<int32_t, std::vector<int32_t>> nodes_of_mesh;
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    const rc::scene::MeshOrigin& o = scene.meshes[m].origin;
    if (o.file != file || !covered(m)) continue;
    auto& list = scene_meshes_of_node[o.node];
    if (list.empty()) {
      auto& nodes = nodes_of_mesh[o.mesh];
      if (std::find(nodes.begin(), nodes.end(), o.node) == nodes.end()) nodes.push_back(o.node);
    }
    list.push_back(m);
  }
  Json& meshes = array(j, "meshes");
  Json& nodes = array(j, "nodes");
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
  return scene_meshes_of_node;
}

/// Places the new buffer (the GLB chunk, extended; or a new buffer: first in a GLB, whose binary
/// chunk is buffer 0; last in a .gltf, with a .bin beside it named after the output) and writes
/// the output.
void finish_output(GltfOutput& o, const std::string& output) {
  Json& j = o.json();
  const bool glb_out = o.glb;
  const fs::path& out_path = o.out_path;
  Json& views = array(j, "bufferViews");
  Json& buffers = array(j, "buffers");
  const bool extend_bin = o.extend_bin;
  std::vector<Json>& new_views = o.new_views;
  std::string& data = o.data;
  GltfFile& file = o.file;
  const std::vector<fs::path>& input_files = o.input_files;
  if (data.empty() && !extend_bin && !glb_out) {  // nothing new to store (a lightmap in the input's UVs)
    rc::util::StagedFile(out_path, j.dump(2) + "\n").commit();
    return;
  }
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
    rc::util::StagedFile(out_path, out).commit();
  } else {
    rc::util::StagedFile bin_file(sidecar, bin);
    rc::util::StagedFile gltf_file(out_path, j.dump(2) + "\n");
    bin_file.commit();  // the .bin first: the .gltf never names a buffer that is not there
    gltf_file.commit();
  }
}

}  // namespace

namespace {

/// A primitive's faces with their vertices split where the atlas's UVs differ: new vertex k is
/// the input's vertex xref[k] with atlas UV uv[k].
struct UvSplit {
  std::vector<uint32_t> xref;
  std::vector<rc::Vec2> uv;
  std::vector<uint32_t> indices;
};

UvSplit split_by_uv(const std::vector<uint32_t>& indices, const std::vector<rc::Vec2>& corner_uv) {
  UvSplit out;
  std::unordered_map<uint64_t, std::vector<uint32_t>> by_vertex;  // input vertex -> its new vertices
  out.indices.reserve(indices.size());
  for (size_t c = 0; c < indices.size(); ++c) {
    const uint32_t v = indices[c];
    std::vector<uint32_t>& copies = by_vertex[v];
    uint32_t found = UINT32_MAX;
    for (uint32_t k : copies)
      if (out.uv[k] == corner_uv[c]) found = k;
    if (found == UINT32_MAX) {
      found = uint32_t(out.xref.size());
      out.xref.push_back(v);
      out.uv.push_back(corner_uv[c]);
      copies.push_back(found);
    }
    out.indices.push_back(found);
  }
  return out;
}

/// The accessor's elements gathered at `xref`, packed (no stride).
std::string gather(const tinygltf::Model& model, int index, const std::vector<uint32_t>& xref, const std::string& what,
                   const char* option) {
  if (index < 0 || size_t(index) >= model.accessors.size()) throw InputError(what + ": no such accessor");
  const tinygltf::Accessor& a = model.accessors[size_t(index)];
  const int component = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
  if (component <= 0 || components <= 0) throw InputError(what + ": unknown component type or type");
  if (a.sparse.isSparse)
    throw InputError(what + ": a sparse accessor, which " + option + " does not rewrite");
  const size_t element = size_t(component) * size_t(components);
  std::string out(xref.size() * element, '\0');
  if (a.bufferView < 0) return out;  // all zeros, as the specification says
  const tinygltf::BufferView& view = model.bufferViews.at(size_t(a.bufferView));
  const std::vector<unsigned char>& buffer = model.buffers.at(size_t(view.buffer)).data;
  const size_t stride = view.byteStride != 0 ? view.byteStride : element;
  for (size_t k = 0; k < xref.size(); ++k) {
    const size_t at = view.byteOffset + a.byteOffset + size_t(xref[k]) * stride;
    if (xref[k] >= a.count || at + element > buffer.size() || at + element > view.byteOffset + view.byteLength)
      throw InputError(what + ": accessor " + std::to_string(index) + " reaches past its buffer");
    std::memcpy(out.data() + k * element, buffer.data() + at, element);
  }
  return out;
}

/// The accessor fields of a new float VEC3 position accessor over `bytes`, with its min and max.
Json position_fields(const std::string& bytes, size_t count) {
  std::array<float, 3> lo{FLT_MAX, FLT_MAX, FLT_MAX}, hi{-FLT_MAX, -FLT_MAX, -FLT_MAX};
  for (size_t k = 0; k < count; ++k)
    for (int c = 0; c < 3; ++c) {
      float x;
      std::memcpy(&x, bytes.data() + 12 * k + 4 * size_t(c), 4);
      lo[size_t(c)] = std::min(lo[size_t(c)], x), hi[size_t(c)] = std::max(hi[size_t(c)], x);
    }
  if (count == 0) lo = hi = {0.0f, 0.0f, 0.0f};
  return {{"componentType", kFloat}, {"count", count}, {"type", "VEC3"}, {"min", lo}, {"max", hi}};
}

/// Rewrites a primitive's attributes (and its morph targets') as new accessors holding the
/// input's vertices xref[k], k = 0, 1, …, in that order; the caller adds the index list. A
/// Draco-compressed primitive is then written decoded (its attributes were regathered from
/// tinygltf's decoded accessors): its compressed data no longer applies.
void regather_primitive(GltfOutput& o, const tinygltf::Model& model, Json& primitive,
                        const std::vector<uint32_t>& xref, const std::string& what, const char* option) {
  const auto regather = [&](Json& attributes, bool target) {
    for (auto& [name, index] : attributes.items()) {
      if (!index.is_number_integer()) continue;
      const std::string bytes = gather(model, int(index.get<int64_t>()), xref, what + " " + name, option);
      const tinygltf::Accessor& a = model.accessors[size_t(index.get<int64_t>())];
      const int components = tinygltf::GetNumComponentsInType(uint32_t(a.type));
      Json fields = {{"componentType", a.componentType},
                     {"count", xref.size()},
                     {"type", components == 1   ? "SCALAR"
                              : components == 2 ? "VEC2"
                              : components == 3 ? "VEC3"
                              : components == 4 ? "VEC4"
                                                : "MAT4"}};
      if (a.type == TINYGLTF_TYPE_MAT2 || a.type == TINYGLTF_TYPE_MAT3)
        throw InputError(what + " " + name + ": matrix vertex attributes are not supported by " + option);
      if (a.normalized) fields["normalized"] = true;
      if (name == "POSITION" && a.componentType == kFloat && a.type == TINYGLTF_TYPE_VEC3)
        fields = position_fields(bytes, xref.size());
      else if (name == "POSITION" && !target)
        throw InputError(what + ": quantized positions (KHR_mesh_quantization) are not supported by " +
                         option);
      index = o.add_accessor(bytes.data(), bytes.size(), std::move(fields), true);
    }
  };
  regather(primitive["attributes"], false);
  if (primitive.contains("targets") && primitive["targets"].is_array())
    for (Json& target : primitive["targets"])
      if (target.is_object()) regather(target, true);
  if (primitive.contains("extensions") && primitive["extensions"].is_object()) {
    primitive["extensions"].erase("KHR_draco_mesh_compression");
    if (primitive["extensions"].empty()) primitive.erase("extensions");
  }
}

/// Once no primitive is compressed any more, the file no longer needs a Draco decoder.
void drop_draco_if_unused(Json& j) {
  bool draco_left = false;
  if (j.contains("meshes") && j["meshes"].is_array())
    for (const Json& mesh : j["meshes"])
      if (mesh.is_object() && mesh.contains("primitives") && mesh["primitives"].is_array())
        for (const Json& primitive : mesh["primitives"])
          draco_left = draco_left || (primitive.is_object() && primitive.contains("extensions") &&
                                      primitive["extensions"].is_object() &&
                                      primitive["extensions"].contains("KHR_draco_mesh_compression"));
  if (!draco_left)
    for (const char* list : {"extensionsUsed", "extensionsRequired"})
      if (j.contains(list) && j[list].is_array()) {
        Json kept = Json::array();
        for (const Json& name : j[list])
          if (name != "KHR_draco_mesh_compression") kept.push_back(name);
        if (kept.empty())
          j.erase(list);
        else
          j[list] = std::move(kept);
      }
}

/// A primitive's index list as a new accessor (triangles: strips and fans were unrolled by the loader).
void add_indices(GltfOutput& o, Json& primitive, const std::vector<uint32_t>& indices) {
  primitive["indices"] =
      o.add_accessor(indices.data(), indices.size() * 4,
                     {{"componentType", kUnsignedInt}, {"count", indices.size()}, {"type", "SCALAR"}}, false);
  primitive["mode"] = 4;
}

/// Whether `w` is no split at all: wedge k is vertex k of a mesh of `vertices` vertices, and the
/// corners are the index list.
bool is_identity(const Wedges& w, const std::vector<uint32_t>& indices, size_t vertices) {
  if (w.vertex.size() != vertices) return false;
  for (size_t k = 0; k < w.vertex.size(); ++k)
    if (w.vertex[k] != k) return false;
  return w.of_corner == indices;
}

/// A vertex bake's two colour attributes: COLOR_0 display-referred, the quantity itself beside it.
void add_colour_attributes(GltfOutput& o, Json& attributes, const std::vector<Rgb>& values,
                           const ExportSettings& settings) {
  const float scale = std::exp2(settings.exposure);
  const auto add_colours = [&](bool clamp) {
    std::vector<float> floats;
    floats.reserve(3 * values.size());
    for (const Rgb& c : values)
      for (int k = 0; k < 3; ++k) floats.push_back(clamp ? std::clamp(c[k] * scale, 0.0f, 1.0f) : c[k]);
    return o.add_accessor(floats.data(), floats.size() * 4,
                          {{"componentType", kFloat}, {"count", values.size()}, {"type", "VEC3"}}, true);
  };
  attributes["COLOR_0"] = add_colours(true);
  attributes[gltf_attribute(settings.quantity)] = add_colours(false);
}

Json lightmap_extras(const std::string& uri, int tex_coord, const ExportSettings& settings) {
  return {{"uri", percent_encode(uri)},
          {"texCoord", tex_coord},
          {"quantity", to_string(settings.quantity)},
          {"units", settings.quantity == Quantity::irradiance ? "W/m^2" : settings.quantity == Quantity::radiosity ? "W/m^2" : "W/(m^2 sr)"},
          {"encoding", "linear, half-float OpenEXR"}};
}

/// Adds the lightmap's UV set to a primitive whose vertices `split` made, and the index buffer.
int add_lightmap_uvs(GltfOutput& o, Json& primitive, const UvSplit& split) {
  Json& attributes = primitive["attributes"];
  int tex_coord = 0;
  while (attributes.contains("TEXCOORD_" + std::to_string(tex_coord))) ++tex_coord;
  attributes["TEXCOORD_" + std::to_string(tex_coord)] =
      o.add_accessor(split.uv.data(), split.uv.size() * sizeof(rc::Vec2),
                     {{"componentType", kFloat}, {"count", split.uv.size()}, {"type", "VEC2"}}, true);
  add_indices(o, primitive, split.indices);
  return tex_coord;
}

Json& material_for(Json& j, Json& primitive) {
  Json& materials = array(j, "materials");
  if (!primitive.contains("material") || !primitive["material"].is_number_integer()) {
    materials.push_back({{"name", "gilt default"}});  // glTF's default material, given a place for extras
    primitive["material"] = materials.size() - 1;
  }
  return materials[size_t(primitive["material"].get<int64_t>())];
}

void write_lightmap_gltf(const std::string& input, const std::string& output, const rc::scene::Scene& scene,
                         const Lightmap& lightmap, const ExportSettings& settings, const std::string& image_uri) {
  const tinygltf::Model model = rc::io::read_gltf_file(input);
  GltfOutput o = begin_output(input, output);
  Json& j = o.json();
  std::map<int32_t, int32_t> mesh_of_node;
  const auto scene_meshes_of_node = split_instances(
      j, scene, lightmap.file, [&](size_t m) { return !lightmap.corner_uv[m].empty(); }, mesh_of_node);
  Json& meshes = array(j, "meshes");
  bool baked_any = false;
  for (const auto& [node, list] : scene_meshes_of_node) {
    Json& primitives = meshes[size_t(mesh_of_node.at(node))]["primitives"];
    for (size_t m : list) {
      const rc::scene::TriangleMesh& mesh = scene.meshes[m];
      Json& primitive = primitives[size_t(mesh.origin.primitive)];
      const std::string what = input + ": mesh " + std::to_string(mesh.origin.mesh) + " primitive " +
                               std::to_string(mesh.origin.primitive);
      baked_any = true;
      if (lightmap.stats.uv_set >= 0) {  // the input's own UV set: the primitive stays as it was
        const Json extras = lightmap_extras(image_uri, lightmap.stats.uv_set, settings);
        primitive["extras"]["gilt_lightmap"] = extras;
        Json& material = material_for(j, primitive);
        if (!material.contains("extras") || !material["extras"].is_object()) material["extras"] = Json::object();
        if (!material["extras"].contains("gilt_lightmap")) material["extras"]["gilt_lightmap"] = extras;
        continue;
      }
      const UvSplit split = split_by_uv(mesh.indices, lightmap.corner_uv[m]);
      regather_primitive(o, model, primitive, split.xref, what, "--lightmap");
      const int tex_coord = add_lightmap_uvs(o, primitive, split);
      const Json extras = lightmap_extras(image_uri, tex_coord, settings);
      primitive["extras"]["gilt_lightmap"] = extras;
      Json& material = material_for(j, primitive);
      if (!material.contains("extras") || !material["extras"].is_object()) material["extras"] = Json::object();
      if (!material["extras"].contains("gilt_lightmap")) material["extras"]["gilt_lightmap"] = extras;
    }
  }
  if (!baked_any)
    throw InputError(input + ": no surface of the model holds a solution (mirrors and glass are not baked)");
  drop_draco_if_unused(j);
  finish_output(o, output);
}

/// OBJ or PLY in, glTF out: a new model of the meshes as read, one node, one mesh, one primitive
/// per scene mesh written, one material per material used.
struct ConvertedModel {
  GltfOutput o;
  std::string input;
  std::map<uint32_t, size_t> material_index;
  bool emissive_strength = false;

  ConvertedModel(const rc::scene::Scene& scene, int32_t file, const std::string& output,
                 const char* generator) {
    o.glb = rc::io::lower_extension(output) == ".glb";
    o.out_path = fs::absolute(output).lexically_normal();
    input = scene.model_files[size_t(file)];
    const std::string name = fs::path(input).stem().string();
    o.json() = {{"asset", {{"version", "2.0"}, {"generator", generator}}},
                {"scene", 0},
                {"scenes", Json::array({Json{{"nodes", Json::array({0})}}})},
                {"nodes", Json::array({Json{{"name", name}, {"mesh", 0}}})},
                {"meshes", Json::array({Json{{"name", name}, {"primitives", Json::array()}}})},
                {"materials", Json::array()},
                {"buffers", Json::array()},
                {"bufferViews", Json::array()},
                {"accessors", Json::array()}};
  }

  /// A primitive of the mesh's vertices xref[k], k = 0, 1, …: their positions, normals and UVs
  /// (OBJ and PLY count v up from the bottom, glTF down from the top); no index list yet.
  Json primitive(const rc::scene::TriangleMesh& mesh, const std::vector<uint32_t>& xref) {
    Json primitive = {{"attributes", Json::object()}};
    std::string positions(xref.size() * 12, '\0');
    for (size_t k = 0; k < xref.size(); ++k) std::memcpy(&positions[12 * k], &mesh.positions[xref[k]], 12);
    primitive["attributes"]["POSITION"] =
        o.add_accessor(positions.data(), positions.size(), position_fields(positions, xref.size()), true);
    if (!mesh.normals.empty()) {
      std::vector<rc::Vec3> normals;
      for (uint32_t v : xref) {
        const rc::Vec3 n = mesh.normals[v];
        const float len = glm::length(n);
        normals.push_back(len > 0.0f ? n / len : rc::Vec3(0.0f, 0.0f, 1.0f));
      }
      primitive["attributes"]["NORMAL"] = o.add_accessor(
          normals.data(), normals.size() * 12, {{"componentType", kFloat}, {"count", normals.size()}, {"type", "VEC3"}},
          true);
    }
    if (!mesh.uvs.empty()) {
      std::vector<rc::Vec2> uvs;
      for (uint32_t v : xref) uvs.emplace_back(mesh.uvs[v].x, 1.0f - mesh.uvs[v].y);
      primitive["attributes"]["TEXCOORD_0"] = o.add_accessor(
          uvs.data(), uvs.size() * 8, {{"componentType", kFloat}, {"count", uvs.size()}, {"type", "VEC2"}}, true);
    }
    return primitive;
  }

  /// Adds the primitive with the mesh's material (made on first use, with `extras`).
  void add(Json primitive, const rc::scene::Scene& scene, const rc::scene::TriangleMesh& mesh,
           const Json& extras) {
    Json& j = o.json();
    auto [it, added] = material_index.try_emplace(mesh.material, j["materials"].size());
    if (added) {
      const rc::scene::Material& mat = scene.materials[mesh.material];
      Json material = {{"name", mat.name.empty() ? "material " + std::to_string(mesh.material) : mat.name},
                       {"pbrMetallicRoughness",
                        {{"baseColorFactor", {mat.albedo.r, mat.albedo.g, mat.albedo.b, 1.0f}},
                         {"metallicFactor", 0.0},
                         {"roughnessFactor", 1.0}}}};
      if (!extras.is_null()) material["extras"] = extras;
      const float peak = std::max({mat.emission.r, mat.emission.g, mat.emission.b});
      if (peak > 0.0f) {
        const float scale = peak > 1.0f ? 1.0f / peak : 1.0f;
        material["emissiveFactor"] = {mat.emission.r * scale, mat.emission.g * scale, mat.emission.b * scale};
        if (peak > 1.0f) {
          material["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", peak}};
          emissive_strength = true;
        }
      }
      j["materials"].push_back(std::move(material));
    }
    primitive["material"] = it->second;
    j["meshes"][0]["primitives"].push_back(std::move(primitive));
  }

  void finish(const std::string& output) {
    if (emissive_strength) o.json()["extensionsUsed"] = Json::array({"KHR_materials_emissive_strength"});
    if (o.data.empty())
      throw InputError(input +
                       ": no surface of the model holds a solution (mirrors and glass are not baked)");
    finish_output(o, output);
  }
};

void write_lightmap_converted(const std::string& output, const rc::scene::Scene& scene,
                              const Lightmap& lightmap, const ExportSettings& settings,
                              const std::string& image_uri) {
  ConvertedModel model(scene, lightmap.file, output, "gilt radiosity --lightmap");
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (lightmap.corner_uv[m].empty()) continue;
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    const UvSplit split = split_by_uv(mesh.indices, lightmap.corner_uv[m]);
    Json primitive = model.primitive(mesh, split.xref);
    const int tex_coord = add_lightmap_uvs(model.o, primitive, split);
    const Json extras = {{"gilt_lightmap", lightmap_extras(image_uri, tex_coord, settings)}};
    primitive["extras"] = extras;
    model.add(std::move(primitive), scene, mesh, extras);
  }
  model.finish(output);
}

/// --onto input, OBJ or PLY in, glTF out: the meshes as read, their vertices split into the
/// colours' wedges.
void write_onto_converted(const std::string& output, const rc::scene::Scene& scene,
                          const InputColours& colours, const ExportSettings& settings) {
  ConvertedModel model(scene, colours.file, output, "gilt radiosity --onto input");
  for (size_t m = 0; m < scene.meshes.size(); ++m) {
    if (colours.per_mesh[m].empty()) continue;
    const rc::scene::TriangleMesh& mesh = scene.meshes[m];
    const Wedges& w = colours.wedges[m];
    Json primitive = model.primitive(mesh, w.vertex);
    add_indices(model.o, primitive, w.of_corner);
    add_colour_attributes(model.o, primitive["attributes"], colours.per_mesh[m], settings);
    model.add(std::move(primitive), scene, mesh, Json());
  }
  model.finish(output);
}

}  // namespace

void write_onto_gltf(const std::string& input, const std::string& output, const rc::scene::Scene& scene,
                     const InputColours& colours, const ExportSettings& settings) {
  const std::string in_ext = rc::io::lower_extension(input);
  if (in_ext != ".gltf" && in_ext != ".glb") {
    if (colours.wedges.empty())
      throw std::logic_error("write_onto_gltf: an OBJ or PLY input's colours were not split");
    write_onto_converted(output, scene, colours, settings);
    return;
  }
  std::optional<tinygltf::Model> model;  // read when a primitive's vertices are split
  GltfOutput o = begin_output(input, output);
  Json& j = o.json();
  std::map<int32_t, int32_t> mesh_of_node;
  const auto scene_meshes_of_node = split_instances(
      j, scene, colours.file, [&](size_t m) { return !colours.per_mesh[m].empty(); }, mesh_of_node);
  Json& meshes = array(j, "meshes");
  Json& accessors = array(j, "accessors");
  for (const auto& [node, list] : scene_meshes_of_node) {
    Json& primitives = meshes[size_t(mesh_of_node.at(node))]["primitives"];
    for (size_t m : list) {
      const rc::scene::TriangleMesh& mesh = scene.meshes[m];
      Json& primitive = primitives[size_t(mesh.origin.primitive)];
      const Json& position = accessors[size_t(primitive["attributes"]["POSITION"].get<int64_t>())];
      if (position.value("count", size_t(0)) != mesh.positions.size())
        throw std::logic_error("write_onto_gltf: vertex count of a primitive changed while loading");
      const bool split =
          !colours.wedges.empty() && !is_identity(colours.wedges[m], mesh.indices, mesh.positions.size());
      if (split) {
        if (!model) model = rc::io::read_gltf_file(input);
        const std::string what = input + ": mesh " + std::to_string(mesh.origin.mesh) + " primitive " +
                                 std::to_string(mesh.origin.primitive);
        regather_primitive(o, *model, primitive, colours.wedges[m].vertex, what,
                           "--onto input's vertex split (--keep-vertices turns it off)");
        add_indices(o, primitive, colours.wedges[m].of_corner);
      } else if (colours.per_mesh[m].size() != mesh.positions.size()) {
        throw std::logic_error("write_onto_gltf: colours for some vertices only");
      }
      add_colour_attributes(o, primitive["attributes"], colours.per_mesh[m], settings);
    }
  }
  if (o.data.empty())
    throw InputError(input + ": no surface of the model holds a solution (mirrors and glass are not baked)");
  drop_draco_if_unused(j);
  finish_output(o, output);
}

void check_lightmap_output(const std::string& path, const rc::scene::Scene& scene) {
  const std::string& input = scene.model_files[size_t(onto_input_file(scene))];
  const std::string out_ext = rc::io::lower_extension(path);
  if (out_ext != ".gltf" && out_ext != ".glb")
    throw InputError("-o " + path + ": --lightmap writes glTF (.gltf or .glb), whose second UV set holds the " +
                     "lightmap's; the input is " + input);
  std::error_code ec;
  if (fs::equivalent(input, path, ec))
    throw InputError("-o " + path + ": is the input model; --lightmap never modifies its input");
  if (fs::equivalent(input, lightmap_image_path(path), ec))
    throw InputError("-o " + path + ": its lightmap " + lightmap_image_path(path) + " would overwrite the input");
  const fs::path folder = fs::absolute(path).parent_path();
  if (!fs::is_directory(folder, ec)) throw InputError("-o " + path + ": folder " + folder.string() + " does not exist");
}

void write_lightmap(const std::string& path, const rc::scene::Scene& scene, const Lightmap& lightmap,
                    const ExportSettings& settings) {
  check_lightmap_output(path, scene);
  const std::string& input = scene.model_files[size_t(lightmap.file)];
  const std::string image = lightmap_image_path(path);
  rc::util::write_image(image, lightmap.image, 0.0f, /*half_float=*/true);
  const std::string uri = fs::path(image).filename().string();
  const std::string in_ext = rc::io::lower_extension(input);
  if (in_ext == ".gltf" || in_ext == ".glb")
    write_lightmap_gltf(input, path, scene, lightmap, settings, uri);
  else
    write_lightmap_converted(path, scene, lightmap, settings, uri);
}

}  // namespace gilt::radiosity::bake
