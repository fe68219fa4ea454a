#pragma once
// Internal to raytrace_core: one loader per file format, each appending what it reads to a scene
// (meshes, materials, punctual lights, camera), plus the geometry helpers they share.
// load_scene / load_scene_file in scene_io.h are the public entry points.

#include <filesystem>
#include <string>

#include <glm/mat4x4.hpp>

#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::io {

/// Appends a Wavefront OBJ (with its MTL) as one mesh per material; throws InputError naming the line.
void load_obj(const std::filesystem::path& path, scene::Scene& scene);
/// Appends a glTF 2.0 file (.gltf or .glb): meshes, materials, first camera, KHR_lights_punctual.
void load_gltf(const std::filesystem::path& path, scene::Scene& scene);
/// Appends a PLY mesh (ascii or binary) with one default diffuse material.
void load_ply(const std::filesystem::path& path, scene::Scene& scene);
/// The warning load_ply gives about the material it makes (a PLY holds geometry only). A JSON
/// scene that gives the file's mesh a material of its own drops it.
std::string ply_default_material_note(const std::string& file);
/// Appends gilt's own JSON scene, loading the mesh files it names relative to itself.
void load_json(const std::filesystem::path& path, scene::Scene& scene);

/// Applies the affine transform to a mesh: positions, normals (inverse transpose, renormalised)
/// and, when the transform mirrors (negative determinant), the winding so the front stays in front.
void transform_mesh(scene::TriangleMesh& mesh, const glm::mat4& transform);

/// Lower-case extension of the path including the dot, e.g. ".obj".
std::string lower_extension(const std::filesystem::path& path);

}  // namespace gilt::raytrace_core::io
