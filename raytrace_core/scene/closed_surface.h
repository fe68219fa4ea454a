#pragma once
// Which triangles of a mesh lie on a closed surface: one that bounds a solid, every edge of its
// connected piece shared by exactly two of its triangles (positions equal bit for bit count as
// one vertex, so a model whose faces each have their own corners is read as it is meant). The
// inside of a closed surface is a region light cannot enter; the back of an open sheet (a slab
// modelled as one quad, a leaf) may face a room.

#include <vector>

#include "raytrace_core/scene/scene.h"

namespace gilt::raytrace_core::scene {

/// Per triangle of `mesh` (its indices, in order), 1 where its connected piece is closed.
std::vector<char> triangles_on_closed_surfaces(const TriangleMesh& mesh);

}  // namespace gilt::raytrace_core::scene
