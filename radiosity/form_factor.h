#pragma once
// Form factors between a differential receiving area and a polygonal source (Lambert's
// point-to-polygon formula), as used by receiver-vertex shooting (Wallace, Elmquist & Haines
// 1989, "A Ray Tracing Algorithm for Progressive Radiosity").

#include <span>

#include "raytrace_core/math.h"

namespace gilt::radiosity {

using raytrace_core::DVec3;

/// Unoccluded form factor F(dA → A) from a differential area at `p` with unit normal `n` to the
/// planar polygon `polygon`, for light leaving the polygon's front (the side its
/// counter-clockwise winding faces): (1/2π) Σ γᵢ n·(Rᵢ × Rᵢ₊₁)/|Rᵢ × Rᵢ₊₁|. The polygon is first
/// clipped against the receiver's tangent plane, so parts behind the receiver contribute
/// nothing; a receiver behind the polygon's plane, or a polygon seen from its back, gives 0.
/// In [0, 1]; computed in double precision.
double point_to_polygon_form_factor(const DVec3& p, const DVec3& n, std::span<const DVec3> polygon);

/// The same for a triangle.
double point_to_triangle_form_factor(const DVec3& p, const DVec3& n, const DVec3& a, const DVec3& b, const DVec3& c);

}  // namespace gilt::radiosity
