#pragma once
// Sampling a triangle by the solid angle it subtends (Arvo 1995, "Stratified Sampling of
// Spherical Triangles"). Sampling a triangle light by area gives each direction a density
// proportional to distance² / cos θ on the light, which spikes where a point sees the light
// near edge-on or close by (the ceiling beside a Cornell box's lamp); uniform over the solid
// angle, every direction towards the light has the same density 1/Ω.

#include <optional>

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::util {

/// The triangle (a, b, c) as seen from a point: its corners as unit directions, and what Arvo's
/// construction needs of the spherical triangle they span. Computed in double: the construction
/// subtracts nearly equal angles when the triangle is small.
class SphericalTriangle {
 public:
  /// Nothing when the point lies in the triangle's plane or on it (no solid angle).
  static std::optional<SphericalTriangle> from(const DVec3& p, const DVec3& a, const DVec3& b, const DVec3& c);

  /// Solid angle Ω (triangle_solid_angle of the corner directions).
  double solid_angle() const { return area_; }
  /// A unit direction from the point, uniform over the solid angle (density 1/Ω), for u ∈ [0,1)².
  /// u.x sweeps the area from the edge through a (sub-triangles of area u.x·Ω), u.y runs along
  /// the arc towards b, so strata of u stay strata of directions.
  DVec3 sample(Vec2 u) const;

 private:
  DVec3 a_{0.0}, b_{0.0}, c_{0.0};
  double area_ = 0.0;
  double cos_alpha_ = 1.0, sin_alpha_ = 0.0;  ///< of the angle at a
  double cos_c_ = 0.0;                        ///< cosine of the arc from a to b
};

/// Solid angle of the spherical triangle with unit corners a, b, c (Van Oosterom & Strackee 1983).
double triangle_solid_angle(const DVec3& a, const DVec3& b, const DVec3& c);

/// Whether a triangle light seen under solid angle `omega` is sampled by solid angle rather than
/// by area: not when it is tiny, where the two densities agree to within rounding and Arvo's
/// construction loses digits, nor when it fills nearly a hemisphere (a point almost on the light).
/// The same test decides for sampling and for the MIS density, so the two always match.
inline bool samples_by_solid_angle(double omega) { return omega > 1e-4 && omega < 6.2; }

}  // namespace gilt::raytrace_core::util
