#pragma once
// The radiosity mesh: the scene's diffuse surfaces as a conforming triangle mesh of elements.
// Vertices are shared within a smooth surface of one material and split where the material or
// the surface normal changes sharply; light is received at vertices, shot from elements.

#include <array>
#include <chrono>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "raytrace_core/scene/scene.h"

// Every room of radiosity (mesh, solver, bake) builds on the ray core and names its vectors and
// colours alike.
namespace gilt::radiosity {
namespace rc = gilt::raytrace_core;
using rc::DVec3;
using rc::Rgb;
using rc::Vec3;
}  // namespace gilt::radiosity

namespace gilt::radiosity::mesh {

using rc::Vec3;

/// How to mesh. With both sizes zero the default is used.
struct MeshSettings {
  float max_edge = 0.0f;        ///< target edge length in scene units (0: derive from `elements` or the default)
  int elements = 0;             ///< approximate total element count (0: use max_edge or the default)
  float sharp_angle_degrees = 30.0f;  ///< dihedral angle above which an edge is sharp (vertices split)
  int remesh_iterations = 3;    ///< isotropic remeshing passes
  /// Give each smooth piece of surface an element on every side that light reaches (turning over
  /// those lit on the back alone, doubling those lit on both: see sides.h); off, elements face
  /// as the input's faces are wound.
  bool two_sided = true;
  bool progress = false;        ///< report each stage that runs longer than a second or two on stderr
  /// When meshing must end (a solve under --time). Imprinting goes piece by piece, those with the
  /// most contact faces first; pieces not begun by then keep their input triangles, without
  /// contact lines (MeshReport::pieces_not_imprinted). Remeshing then goes on until the same
  /// time; pieces not begun by then keep their imprinted triangles (pieces_not_remeshed).
  std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max();
};

/// Default element count when neither size is given: accurate on the built-in scenes.
inline constexpr int kDefaultElements = 4000;

/// One mesh of elements. Element e has vertices elements[e], material element_material[e].
struct RadiosityMesh {
  std::vector<Vec3> positions;                   ///< per vertex
  std::vector<Vec3> normals;                     ///< per vertex: unit normal of its surface side
  std::vector<uint32_t> vertex_material;         ///< per vertex (vertices never span materials)
  std::vector<std::array<uint32_t, 3>> elements; ///< counter-clockwise seen from the front
  std::vector<uint32_t> element_material;        ///< index into the scene's materials
  std::vector<uint32_t> element_surface;         ///< which input mesh (or sphere) it came from
  std::vector<Vec3> element_normal;              ///< unit geometric normal (front)
  std::vector<float> element_area;               ///< scene units²
  /// Per element, 1 for an element given a twin lying on it facing the other way, and 2 for the
  /// twin (a surface lit on both sides has an element, and a radiosity, per side: sides.h); empty
  /// when no element has one.
  std::vector<uint8_t> element_two_sided;

  bool two_sided(size_t e) const { return !element_two_sided.empty() && element_two_sided[e] != 0; }
  /// Whether element e is a twin (made behind another by orient_sides: element_two_sided 2).
  bool twin(size_t e) const { return !element_two_sided.empty() && element_two_sided[e] == 2; }

  size_t vertex_count() const { return positions.size(); }
  size_t element_count() const { return elements.size(); }
};

/// What meshing did: counts of repairs and the edge length used.
struct MeshReport {
  float max_edge = 0.0f;
  size_t elements = 0;         ///< elements as meshed (adaptive subdivision adds more later)
  size_t merged_vertices = 0, removed_degenerate = 0, reoriented = 0, self_intersecting = 0;
  size_t contact_edges = 0;    ///< input edges imprinted where surfaces touch (before remeshing)
  size_t buried_faces = 0;     ///< imprinted input faces removed: they lie inside or under other surfaces
  size_t buried_elements = 0;  ///< flat elements removed after remeshing for the same reason (where no contact was imprinted)
  double buried_area = 0.0;    ///< area of both, scene units²
  double meshed_area = 0.0;    ///< area of the input surfaces that are meshed, scene units²
  size_t pieces_not_imprinted = 0;  ///< pieces that touch others but kept no contact lines: the deadline had passed
  size_t turned_elements = 0;       ///< elements turned over: light reaches only their back (sides.h)
  size_t two_sided_elements = 0;    ///< elements given a twin facing the other way: light reaches both sides
  size_t pieces_not_remeshed = 0;  ///< pieces that kept their imprinted triangles: the deadline had passed
  /// Seconds each stage took, in order: repair, contacts (which faces meet), imprint, buried
  /// faces (the imprinted input's test), remesh (with the flat elements' test), assemble, sides.
  std::vector<std::pair<std::string, double>> stage_seconds;
  std::vector<std::string> warnings;
};

/// Meshes every diffuse or glossy surface of the committed scene (mirrors and dielectrics are
/// left to ray tracing). Input meshes are checked and mended first (duplicate vertices merged,
/// degenerate faces removed, orientation made consistent where possible, self-intersections
/// reported). Where another surface touches or crosses one (a block standing on the floor),
/// the contact line is imprinted; the surface is then remeshed isotropically with boundaries,
/// sharp edges and contact lines protected. Spheres are tessellated to the same edge length.
/// The parts of the input buried inside or under other surfaces (the floor under a block) are
/// removed before remeshing, and flat elements found buried after it; those tests cast rays, so
/// they run only when the scene is committed.
RadiosityMesh build_mesh(const rc::scene::Scene& scene, const MeshSettings& settings,
                         MeshReport* report = nullptr);

/// Splits the longest edge of each listed element at its midpoint (at most once per element per
/// call; elements whose longest edge is shorter than `min_edge` are left alone). Every element on
/// that edge is split with it, on both sides of a sharp or material border too (each side gets
/// its own vertex), so the mesh stays conforming: no T-junctions. Existing vertex and element
/// indices keep their meaning (a split element keeps its index for one half); new vertices and
/// elements are appended. Returns the number of vertices added.
size_t split_longest_edges(RadiosityMesh& mesh, const std::vector<uint32_t>& elements, float min_edge);

/// Whether the triangle (a, b, c) of the committed scene, seen from its front (counter-clockwise),
/// is buried as build_mesh removes input faces: from its centroid and three points near its
/// corners, every test ray over the front hemisphere first hits the back of an opaque surface (it
/// lies inside a closed solid or under an object standing on it), and the camera does not see it.
bool input_triangle_buried(const rc::scene::Scene& scene, const Vec3& a, const Vec3& b, const Vec3& c);

/// The same test at one point p of a surface whose front faces n: for a face that is only partly
/// inside a solid (a wall running down under a roof), the part no one can see.
bool input_point_buried(const rc::scene::Scene& scene, const Vec3& p, const Vec3& n);

/// The edge length `settings` asks for on this scene (resolving `elements` and the default).
float target_edge_length(const rc::scene::Scene& scene, const MeshSettings& settings);

}  // namespace gilt::radiosity::mesh
