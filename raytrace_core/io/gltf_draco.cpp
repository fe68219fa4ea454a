#include "raytrace_core/io/gltf_draco.h"

#include <cstdint>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <utility>

#include <draco/compression/decode.h>
#include <draco/core/decoder_buffer.h>
#include <draco/core/draco_types.h>
#include <tiny_gltf.h>

namespace gilt::raytrace_core::io {

namespace {

constexpr const char* kExtension = "KHR_draco_mesh_compression";

thread_local DracoLog* current_log = nullptr;

/// A problem with one primitive's Draco data (caught in decode_draco_primitive).
class Problem : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

[[noreturn]] void problem(const std::string& why) { throw Problem(why); }

std::string accessor_name(int index) { return "accessor " + std::to_string(index); }

/// One decoded attribute or index array, ready to replace an accessor's data.
struct Decoded {
  int accessor;
  std::vector<unsigned char> bytes;
  int target;
};

/// The decoded values of `attribute` for every point of `mesh`, converted to T.
template <typename T>
std::vector<unsigned char> convert(const draco::Mesh& mesh, const draco::PointAttribute& attribute,
                                   const std::string& name) {
  const size_t components = attribute.num_components();
  std::vector<unsigned char> out(size_t(mesh.num_points()) * components * sizeof(T));
  T values[4] = {};
  unsigned char* at = out.data();
  for (draco::PointIndex i(0); i < mesh.num_points(); ++i) {
    const draco::AttributeValueIndex value = attribute.mapped_index(i);
    if (value.value() >= attribute.size())
      problem(name + ": decoded vertex " + std::to_string(i.value()) + " has no value");
    if (!attribute.ConvertValue<T>(value, int8_t(components), values))
      problem(name + ": a decoded value does not fit the accessor's component type");
    std::memcpy(at, values, components * sizeof(T));
    at += components * sizeof(T);
  }
  return out;
}

/// `attribute`'s values for accessor `a` (of a type with as many components).
std::vector<unsigned char> convert(const tinygltf::Accessor& a, const draco::Mesh& mesh,
                                   const draco::PointAttribute& attribute, const std::string& name) {
  // A normalized integer accessor spans its type's whole range; draco scales floats to it only
  // for attributes it marked normalized, and would otherwise truncate them.
  const bool floats =
      attribute.data_type() == draco::DT_FLOAT32 || attribute.data_type() == draco::DT_FLOAT64;
  if (a.normalized && floats && !attribute.normalized())
    problem(name + ": floating-point Draco data for a normalized integer accessor is not supported");
  switch (a.componentType) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
      return convert<int8_t>(mesh, attribute, name);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
      return convert<uint8_t>(mesh, attribute, name);
    case TINYGLTF_COMPONENT_TYPE_SHORT:
      return convert<int16_t>(mesh, attribute, name);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
      return convert<uint16_t>(mesh, attribute, name);
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
      return convert<uint32_t>(mesh, attribute, name);
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
      return convert<float>(mesh, attribute, name);
    default:
      problem(name + ": component type " + std::to_string(a.componentType) + " is not one glTF allows");
  }
}

/// True when every value of `attribute` lies inside its storage (draco reads them unchecked).
bool values_in_storage(const draco::PointAttribute& attribute) {
  if (attribute.size() == 0) return true;
  const draco::DataBuffer* storage = attribute.buffer();
  const int64_t component = draco::DataTypeLength(attribute.data_type());
  const int64_t element = component * attribute.num_components();
  if (!storage || component <= 0 || attribute.byte_offset() < 0 || attribute.byte_stride() < element)
    return false;
  // Sizes below 2^32 values of under 2^31 bytes each: no overflow in 64 bits.
  const uint64_t last =
      uint64_t(attribute.byte_offset()) + uint64_t(attribute.size() - 1) * uint64_t(attribute.byte_stride());
  return last + uint64_t(element) <= storage->data_size();
}

/// The accessor `index` of `model`, checked to be one the decoded data can fill.
const tinygltf::Accessor& accessor(const tinygltf::Model& model, int index, const std::string& name) {
  if (index < 0 || size_t(index) >= model.accessors.size())
    problem(name + ": " + accessor_name(index) + " does not exist");
  const tinygltf::Accessor& a = model.accessors[size_t(index)];
  if (a.sparse.isSparse)
    problem(name + ": " + accessor_name(index) + " is sparse, which Draco data cannot be");
  return a;
}

/// Pass 1. Reads the primitive's mode and the extension object's shape; writes nothing.
void check_extension(const tinygltf::Primitive& primitive, const tinygltf::Value& extension) {
  if (primitive.mode != TINYGLTF_MODE_TRIANGLES)
    problem("primitive mode " + std::to_string(primitive.mode) +
            " is not supported with Draco compression (only TRIANGLES, 4)");
  if (!extension.IsObject()) problem("expected an object");
  const tinygltf::Value& view_value = extension.Get("bufferView");
  const tinygltf::Value& attributes_value = extension.Get("attributes");
  if (!view_value.IsInt()) problem("bufferView: expected an integer");
  if (!attributes_value.IsObject()) problem("attributes: expected an object");
}

/// Pass 2. Reads the compressed bytes of buffer view `view_index` (`view_name`); returns the
/// mesh Draco decodes from them, its triangles checked to refer to its vertices.
std::unique_ptr<draco::Mesh> decode_mesh(const tinygltf::Model& model, int view_index, const std::string& view_name) {
  if (view_index < 0 || size_t(view_index) >= model.bufferViews.size())
    problem(view_name + " does not exist");
  const tinygltf::BufferView& view = model.bufferViews[size_t(view_index)];
  if (view.buffer < 0 || size_t(view.buffer) >= model.buffers.size())
    problem(view_name + ": buffer " + std::to_string(view.buffer) + " does not exist");
  const std::vector<unsigned char>& source = model.buffers[size_t(view.buffer)].data;
  if (view.byteOffset > source.size() || view.byteLength > source.size() - view.byteOffset)
    problem(view_name + " reaches past the end of its buffer");
  if (view.byteLength == 0) problem(view_name + " is empty");

  draco::DecoderBuffer buffer;
  buffer.Init(reinterpret_cast<const char*>(source.data() + view.byteOffset), view.byteLength);
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&buffer);
  if (!decoded.ok()) problem(view_name + " cannot be decoded: " + decoded.status().error_msg_string());
  std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
  if (!mesh) problem(view_name + " holds no mesh");
  const size_t points = mesh->num_points();
  for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh->face(f)[k].value() >= points)
        problem(view_name + ": a decoded triangle refers past the " + std::to_string(points) + " vertices");
  return mesh;
}

/// Pass 3a, for a primitive with indices. Reads its index accessor and the mesh's triangles;
/// returns 3 indices per triangle in the accessor's component type, once checked to fit it.
Decoded decode_indices(const tinygltf::Primitive& primitive, const tinygltf::Model& model, const draco::Mesh& mesh) {
  const size_t points = mesh.num_points();
  const size_t faces = mesh.num_faces();
  const std::string name = "indices";
  const tinygltf::Accessor& a = accessor(model, primitive.indices, name);
  if (a.type != TINYGLTF_TYPE_SCALAR)
    problem(name + ": " + accessor_name(primitive.indices) + " is not SCALAR");
  if (a.count != 3 * faces)
    problem(name + ": " + accessor_name(primitive.indices) + " has count " + std::to_string(a.count) +
            ", but the Draco data decodes to " + std::to_string(faces) + " triangles (" +
            std::to_string(3 * faces) + " indices)");
  const int size = tinygltf::GetComponentSizeInBytes(uint32_t(a.componentType));
  if (a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
      a.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
    problem(name + ": must be unsigned byte, short or int, not component type " + std::to_string(a.componentType));
  if (points > 0 && size < 4 && points - 1 > (size_t(1) << (8 * size)) - 1)
    problem(name + ": the " + std::to_string(points) + " decoded vertices cannot be indexed with " +
            std::to_string(size) + "-byte indices");
  std::vector<unsigned char> bytes(3 * faces * size_t(size));
  unsigned char* at = bytes.data();
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k, at += size) {
      const uint32_t v = mesh.face(f)[k].value();
      if (size == 1) {
        *at = uint8_t(v);
      } else if (size == 2) {
        const uint16_t v16 = uint16_t(v);
        std::memcpy(at, &v16, 2);
      } else {
        std::memcpy(at, &v, 4);
      }
    }
  return {primitive.indices, std::move(bytes), TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER};
}

/// Pass 3b, for a primitive without indices, whose vertices are read three by three. Reads the
/// mesh's triangles; writes nothing. Problem unless they are so.
void check_unindexed(const draco::Mesh& mesh) {
  const size_t points = mesh.num_points();
  const size_t faces = mesh.num_faces();
  for (draco::FaceIndex f(0); f < mesh.num_faces(); ++f)
    for (int k = 0; k < 3; ++k)
      if (mesh.face(f)[k].value() != 3 * f.value() + uint32_t(k))
        problem("the primitive has no indices, but its Draco data is an indexed mesh");
  if (points != 3 * faces) problem("the primitive has no indices, but its Draco data has unused vertices");
}

/// Pass 4, for the primitive's attribute `name`, Draco attribute `id_value`. Reads its accessor
/// and the mesh's attribute; returns one value per decoded vertex in the accessor's component
/// type, once checked to match the accessor.
Decoded decode_attribute(const std::string& name, const tinygltf::Value& id_value,
                         const tinygltf::Primitive& primitive, const tinygltf::Model& model,
                         const draco::Mesh& mesh) {
  const size_t points = mesh.num_points();
  if (!id_value.IsInt() || id_value.Get<int>() < 0)
    problem("attributes." + name + ": expected a Draco attribute id (a non-negative integer)");
  const int id = id_value.Get<int>();
  const auto found = primitive.attributes.find(name);
  if (found == primitive.attributes.end()) problem(name + ": not among the primitive's attributes");
  const tinygltf::Accessor& a = accessor(model, found->second, name);
  const draco::PointAttribute* attribute = mesh.GetAttributeByUniqueId(uint32_t(id));
  if (!attribute) problem(name + ": the Draco data has no attribute with id " + std::to_string(id));
  const int components = attribute->num_components();
  if (components < 1 || components > 4 || components != tinygltf::GetNumComponentsInType(uint32_t(a.type)))
    problem(name + ": the Draco attribute has " + std::to_string(components) + " components, " +
            accessor_name(found->second) + " " +
            std::to_string(tinygltf::GetNumComponentsInType(uint32_t(a.type))));
  if (!values_in_storage(*attribute)) problem(name + ": the decoded attribute is inconsistent");
  if (a.count != points)
    problem(name + ": " + accessor_name(found->second) + " has count " + std::to_string(a.count) +
            ", but the Draco data decodes to " + std::to_string(points) + " vertices");
  return {found->second, convert(a, mesh, *attribute, name), TINYGLTF_TARGET_ARRAY_BUFFER};
}

/// Pass 5, once all is checked. Reads the decoded arrays (moving their bytes out); writes each
/// as a buffer and a buffer view of its own to `model`, and points its accessor at it.
void replace_accessor_data(tinygltf::Model& model, std::vector<Decoded>& out) {
  for (Decoded& d : out) {
    tinygltf::Buffer decoded_buffer;
    decoded_buffer.data = std::move(d.bytes);
    tinygltf::BufferView decoded_view;
    decoded_view.buffer = int(model.buffers.size());
    decoded_view.byteOffset = 0;
    decoded_view.byteLength = decoded_buffer.data.size();
    decoded_view.byteStride = 0;
    decoded_view.target = d.target;
    decoded_view.dracoDecoded = true;
    model.buffers.push_back(std::move(decoded_buffer));
    model.bufferViews.push_back(std::move(decoded_view));
    tinygltf::Accessor& a = model.accessors[size_t(d.accessor)];
    a.bufferView = int(model.bufferViews.size() - 1);
    a.byteOffset = 0;
  }
}

/// Decodes and checks everything first, then changes the model: a problem leaves it as it was.
/// A driver over the named passes above.
void decode(tinygltf::Primitive& primitive, tinygltf::Model& model, const tinygltf::Value& extension) {
  check_extension(primitive, extension);
  const int view_index = extension.Get("bufferView").Get<int>();
  const std::string view_name = "buffer view " + std::to_string(view_index);
  const std::unique_ptr<draco::Mesh> mesh = decode_mesh(model, view_index, view_name);

  std::vector<Decoded> out;
  // Indices: 3 per decoded triangle, in the accessor's component type.
  if (primitive.indices >= 0) {
    out.push_back(decode_indices(primitive, model, *mesh));
  } else {
    check_unindexed(*mesh);
  }
  // Attributes: one value per decoded vertex, in the accessor's component type.
  const tinygltf::Value& attributes_value = extension.Get("attributes");
  for (const std::string& name : attributes_value.Keys())
    out.push_back(decode_attribute(name, attributes_value.Get(name), primitive, model, *mesh));

  // All checked: each decoded array becomes a buffer and a buffer view of its own.
  replace_accessor_data(model, out);
}

}  // namespace

void decode_draco_primitive(tinygltf::Primitive& primitive, tinygltf::Model& model,
                            const tinygltf::Value& extension) {
  std::string why;
  try {
    decode(primitive, model, extension);
  } catch (const Problem& p) {
    why = std::string(kExtension) + ": " + p.what();
  }
  if (current_log) {
    current_log->entries_.push_back({model.meshes.size(), std::move(why)});
  } else if (!why.empty()) {
    throw std::runtime_error(why);
  }
}

DracoLog::DracoLog() : outer_(current_log) { current_log = this; }

DracoLog::~DracoLog() { current_log = outer_; }

std::string DracoLog::first_problem(const tinygltf::Model& model) const {
  for (size_t e = 0; e < entries_.size(); ++e) {
    if (entries_[e].problem.empty()) continue;
    // The entry is the k-th Draco primitive of its mesh: tinygltf calls the decoder once for
    // every primitive that has the extension, in order, and keeps all of them.
    const size_t m = entries_[e].mesh;
    size_t k = 0;
    for (size_t before = 0; before < e; ++before) k += entries_[before].mesh == m ? 1 : 0;
    std::string where = "mesh " + std::to_string(m);
    if (m < model.meshes.size()) {
      const tinygltf::Mesh& mesh = model.meshes[m];
      where = "mesh '" + (mesh.name.empty() ? "mesh" + std::to_string(m) : mesh.name) + "'";
      for (size_t p = 0, seen = 0; p < mesh.primitives.size(); ++p) {
        if (mesh.primitives[p].extensions.count(kExtension) == 0) continue;
        if (seen++ == k) {
          where += " primitive " + std::to_string(p);
          break;
        }
      }
    }
    return where + ": " + entries_[e].problem;
  }
  return {};
}

}  // namespace gilt::raytrace_core::io
