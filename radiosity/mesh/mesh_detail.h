#pragma once
// Private to the radiosity mesher: the passes build_mesh() chains, declared here so that the
// CGAL pass lives in its own translation unit (mesh_repair.cpp) and the rest (mesh.cpp) compiles
// without CGAL's headers.

#include <array>
#include <chrono>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "radiosity/mesh/mesh.h"
#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::util {
class Progress;
}

namespace gilt::radiosity::mesh::detail {

using rc::DVec3;

/// An indexed triangle surface in double precision, counter-clockwise seen from its front.
struct TriangleSoup {
  std::vector<DVec3> points;
  std::vector<std::array<uint32_t, 3>> triangles;
  /// Edges (pairs of points) that vertices are not shared across: the lines imprinted where other
  /// surfaces touch or cross this one, and creases (see split_sharp_vertices).
  std::vector<std::array<uint32_t, 2>> cuts;
};

/// What repairing one input mesh found; each count names one kind of repair.
struct RepairCounts {
  size_t merged_vertices = 0;      ///< points equal to an earlier point, merged into it
  size_t removed_degenerate = 0;   ///< faces with a repeated vertex or collinear vertices, removed
  size_t removed_duplicates = 0;   ///< faces repeating another face's vertices, removed
  size_t reoriented = 0;           ///< faces whose winding was reversed to agree with their neighbours
  size_t duplicated_vertices = 0;  ///< vertices copied to make the surface manifold
  size_t self_intersecting = 0;    ///< pairs of faces that intersect away from a shared vertex or edge
  size_t self_intersections_uncounted = 0;  ///< pieces not (wholly) searched for them: the deadline had passed
  size_t contact_edges = 0;        ///< edges imprinted where another surface touches or crosses this one
  size_t contacts_failed = 0;      ///< other surfaces whose contact could not be imprinted
  size_t contact_segments_lost = 0;  ///< pieces of contact line left out: an end outside its face by rounding
  size_t remesh_failed = 0;        ///< pieces CGAL could not remesh, kept as they were
  size_t not_imprinted = 0;        ///< pieces with contacts not all imprinted: the deadline had passed
  size_t not_remeshed = 0;         ///< pieces left as imprinted: the deadline had passed
};

/// Remeshing parameters for one surface.
struct RemeshParams {
  double edge_length = 1.0;           ///< the remesher's target edge length, scene units (see build_mesh)
  double sharp_angle_degrees = 30.0;  ///< dihedral angle above which an edge is kept as a crease
  int iterations = 3;                 ///< isotropic remeshing passes
};

/// The scene's input meshes, each mended once with CGAL Polygon Mesh Processing (merge duplicate
/// points and faces, drop degenerate faces, orient consistently while keeping the input's front
/// where the input agreed) and split into connected pieces; then each is imprinted by the meshes
/// it touches, which it reads as tools, and remeshed. The CGAL types stay in mesh_repair.cpp.
class RepairedMeshes {
 public:
  explicit RepairedMeshes(size_t mesh_count);
  ~RepairedMeshes();
  RepairedMeshes(const RepairedMeshes&) = delete;
  RepairedMeshes& operator=(const RepairedMeshes&) = delete;

  /// Mends mesh m; calls for different m may run in parallel. Counting each piece's
  /// self-intersections, a warning only, stops at `deadline` (counts->self_intersections_uncounted).
  void repair(size_t m, const rc::scene::TriangleMesh& mesh,
              std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());

  /// Finds which faces of which pieces meet, over every repaired mesh, so call it after every
  /// repair(); imprint() calls it on first use. `progress`, when given, counts pairs of pieces
  /// searched; pairs not begun by `deadline` are left out, and their pieces counted as not
  /// imprinted (they keep the contacts that were found).
  void find_contacts(rc::util::Progress* progress = nullptr,
                     std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());

  /// Imprints on mesh m the lines where the `touching` meshes (repaired too) and its own pieces
  /// meet it, and keeps the result for remesh(). Returns the imprinted surface, which lies on the
  /// input's, and fills `counts` with the repairs and what imprinting found. Each piece is cut by
  /// the faces that meet it alone (imprint.h), in parallel over pieces. Reads the other meshes
  /// only: calls for different m may run in parallel.
  /// `progress`, when given, advances by each piece's faces as it is done. Pieces are begun in
  /// order of their contact faces, most first; those not begun by `deadline` are left as they
  /// were (counts->not_imprinted).
  TriangleSoup imprint(size_t m, std::span<const size_t> touching, RepairCounts* counts,
                       rc::util::Progress* progress = nullptr,
                       std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());

  /// Mesh m as imprinted, without the triangles of the imprinted surface that `remove` marks,
  /// remeshed isotropically to `params.edge_length` with its border, sharp and contact edges
  /// protected. Returns the remeshed surface (empty when nothing is left) and adds to `counts`
  /// what remeshing mended. Calls for different m may run in parallel.
  /// `progress`, when given, advances by each piece's faces as it is done.
  /// Pieces not begun by `deadline` keep their imprinted triangles (counts->not_remeshed).
  TriangleSoup remesh(size_t m, const std::vector<char>& remove, const RemeshParams& params, RepairCounts* counts,
                      rc::util::Progress* progress = nullptr,
                      std::chrono::steady_clock::time_point deadline = std::chrono::steady_clock::time_point::max());

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Geodesic sphere: an icosahedron whose edges are cut into `frequency` parts, projected onto the
/// sphere; 20·frequency² triangles, counter-clockwise seen from outside.
TriangleSoup tessellate_sphere(const DVec3& center, double radius, int frequency);

/// A surface whose vertices are split along creases: `corners[t]` are the output vertices of
/// triangle t of the input soup, `normals[v]` the area-weighted normal of vertex v's smooth fan.
struct SplitSurface {
  std::vector<DVec3> positions;
  std::vector<DVec3> normals;
  std::vector<std::array<uint32_t, 3>> corners;
};

/// Splits the soup's vertices where the dihedral angle between neighbouring triangles exceeds
/// `sharp_angle_degrees`, along the soup's cuts, and where the surface is not manifold (an edge of three triangles, two
/// triangles wound against each other, fans meeting at a point): each smooth fan of triangles
/// around a vertex gets its own copy of the vertex, with the fan's area-weighted normal.
SplitSurface split_sharp_vertices(const TriangleSoup& soup, double sharp_angle_degrees);

}  // namespace gilt::radiosity::mesh::detail
