#pragma once
// KHR_draco_mesh_compression: gilt's checked decoding of Draco-compressed glTF primitives.
//
// tinygltf 2.7.0 calls its own Draco decoder while it parses each primitive, and that decoder
// trusts the file: it indexes buffer views and accessors unchecked, dereferences the attribute
// of an unknown Draco id, overwrites the accessors' counts with the decoded ones and ignores a
// failed decode. gilt compiles tinygltf's implementation from a copy of tiny_gltf.h in which that
// function only calls decode_draco_primitive (see cmake/TinyGltfDraco.cmake and
// io/tinygltf_impl.cpp), so every tinygltf load in gilt goes through the checks below.
//
// A decoded primitive's attribute and index accessors point at new, tightly packed buffer views
// holding the decoded data in the accessors' own component types; their counts are left as the
// file gives them, which must equal the decoded mesh's (vertices for attributes, 3 per triangle
// for indices). Anything else is a problem, reported without changing the model.

#include <cstddef>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
class Value;
struct Primitive;
}  // namespace tinygltf

namespace gilt::raytrace_core::io {

/// Decodes one primitive's KHR_draco_mesh_compression `extension` into `model` (see above).
/// Called by tinygltf while it parses the mesh holding `primitive`, which is therefore not yet in
/// model.meshes. When a DracoLog is alive on this thread the outcome is recorded there; without
/// one a problem throws std::runtime_error.
void decode_draco_primitive(tinygltf::Primitive& primitive, tinygltf::Model& model,
                            const tinygltf::Value& extension);

/// Collects what decode_draco_primitive finds on this thread while it is alive, so that a problem
/// can be named by its mesh and primitive once tinygltf has finished (tinygltf's decoding hook
/// sees neither). Logs nest; the innermost one collects.
class DracoLog {
 public:
  DracoLog();
  ~DracoLog();
  DracoLog(const DracoLog&) = delete;
  DracoLog& operator=(const DracoLog&) = delete;

  /// The first problem met, as "mesh 'NAME' primitive P: KHR_draco_mesh_compression: ...", with
  /// the mesh and primitive looked up in `model` as tinygltf left it; empty when there was none.
  std::string first_problem(const tinygltf::Model& model) const;

 private:
  friend void decode_draco_primitive(tinygltf::Primitive&, tinygltf::Model&, const tinygltf::Value&);
  struct Entry {
    size_t mesh;          // the index of the mesh being parsed (model.meshes.size() at the time)
    std::string problem;  // empty when the primitive decoded
  };
  std::vector<Entry> entries_;
  DracoLog* outer_;
};

}  // namespace gilt::raytrace_core::io
