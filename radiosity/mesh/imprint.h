#pragma once
// Private to the radiosity mesher: gilt's own imprinting of contact lines, which replaced CGAL's
// corefinement for this job (see imprint.cpp).

#include <array>
#include <cstddef>
#include <span>
#include <utility>
#include <vector>

#include "radiosity/mesh/mesh_detail.h"

namespace gilt::radiosity::mesh::detail {

/// What imprint() did.
struct ImprintCounts {
  size_t face_pairs = 0;     ///< pairs of a surface face and a tool triangle tested (whose boxes meet)
  size_t segments = 0;       ///< pieces of contact line found (one per crossing face pair)
  size_t faces_cut = 0;      ///< faces of the surface retriangulated
  size_t segments_lost = 0;  ///< segments left out: an end outside its face by rounding
};

/// Imprints on `surface` (a triangle surface, counter-clockwise about each face's front) the lines
/// where the triangles `tools` cross or touch it: each face is cut along its intersection with
/// every tool triangle that crosses its plane, and retriangulated as a constrained Delaunay
/// triangulation of its corners, the points where lines meet its edges, and the lines. Points on
/// an edge are computed from the edge alone (its endpoints in lexicographic order), so the two
/// faces of an edge are cut at bit-identical points and the surface stays conforming. Tool
/// triangles lying in a face's plane leave no line: a solid standing on the face leaves its
/// outline through its sides.
///
/// The result keeps the input's points first, in order, then the new ones; `cuts` are the
/// imprinted edges, each once, the lower index first. Everything depends on the input's values
/// and order alone (no memory addresses, no thread count), and the cost is O((n + k) log n) for n
/// faces and k meeting pairs. The tools may intersect themselves.
TriangleSoup imprint(const TriangleSoup& surface, std::span<const std::array<DVec3, 3>> tools,
                     ImprintCounts* counts = nullptr);

/// The same, given which faces may meet which tool triangles: `pairs` of (face, tool triangle),
/// ascending and unique, holding at least every pair whose closed triangles meet (a caller that
/// has found them already, as the mesher's contact search has, saves imprint() its own search).
TriangleSoup imprint(const TriangleSoup& surface, std::span<const std::array<DVec3, 3>> tools,
                     const std::vector<std::pair<uint32_t, uint32_t>>& pairs, ImprintCounts* counts = nullptr);

}  // namespace gilt::radiosity::mesh::detail
