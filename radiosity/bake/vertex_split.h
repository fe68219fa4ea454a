#pragma once
// Vertices split into wedges: the corners around one vertex that are to share a colour. A vertex
// colour format with an index list (glTF) can give one position several colours, one per wedge;
// OBJ and PLY vertex colours cannot, and keep one wedge per vertex. A vertex bake splits where
// the light itself is discontinuous across an edge: at creases (a floor meeting a wall), between
// materials (a radiance jumps with the albedo), and along shadow lines that follow an edge
// (radiosity/bake/vertex_fit.h decides those). Elsewhere a split only shows the fit's noise.

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace gilt::radiosity::bake {

/// Corners grouped into wedges.
struct Wedges {
  std::vector<uint32_t> of_corner;  ///< per corner of the index list (three per face): its wedge
  std::vector<uint32_t> vertex;     ///< per wedge: the vertex it is a copy of

  size_t count() const { return vertex.size(); }
};

/// An edge two faces share: faces f and g (positions in the face list), its vertices u and v.
struct SharedEdge {
  uint32_t f = 0, g = 0;
  uint32_t u = 0, v = 0;
};

/// The edges exactly two faces share, in order of their first face. An edge of three or more faces
/// (a fin on a wall) joins none of them, and neither does a degenerate face's.
std::vector<SharedEdge> shared_edges(std::span<const uint32_t> indices);

/// One wedge per vertex that a face uses, in the order of first use.
Wedges one_wedge_per_vertex(std::span<const uint32_t> indices);

/// The corners around each vertex joined across each shared edge that `joined` accepts; corners
/// not joined to any other are wedges of their own. Wedges are numbered in order of first corner.
Wedges wedges_across(std::span<const uint32_t> indices, std::span<const SharedEdge> edges,
                     const std::function<bool(const SharedEdge&)>& joined);

}  // namespace gilt::radiosity::bake
