#pragma once
// Which sides of the meshed surfaces take light. A diffuse surface reflects on whichever side
// light reaches, whatever its winding (pbrt-v4, Cycles and gilt's own path tracer all treat it
// so), while a radiosity element receives and sends on its front alone. Downloaded models are
// wound any way: a room whose walls face out, a floor that is a single sheet lit from above and
// below. So after meshing, each smooth piece of surface (elements joined by shared vertices) is
// asked which of its sides light can reach, by following rays between the pieces' sides from
// those that see a light: a piece lit on its back alone is turned over, one lit on both sides
// gets a second element behind each of its elements, facing the other way, with its own
// vertices (its own radiosity). A closed solid's inside, or the outside of a room under a black
// sky, reaches no light and gets nothing.

#include <cstddef>

#include "radiosity/mesh/mesh.h"

namespace gilt::radiosity::mesh {

/// What orient_sides did.
struct SidesReport {
  size_t pieces = 0;              ///< smooth pieces of surface asked
  size_t turned_elements = 0;     ///< elements turned over: only their back takes light
  size_t two_sided_elements = 0;  ///< elements given a twin behind them: both sides take light
  size_t rays = 0;                ///< rays traced to decide
};

/// Rays each piece sends from each side, spread over its elements (at least one per element).
inline constexpr int kSideRaysPerPiece = 64;

/// Turns over or doubles the pieces of `mesh` as above. `scene` is the committed input (its
/// lights); rays are traced against the elements. Deterministic for a given mesh.
SidesReport orient_sides(const rc::scene::Scene& scene, RadiosityMesh& mesh);

}  // namespace gilt::radiosity::mesh
