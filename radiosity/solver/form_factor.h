#pragma once
// Form factors between a differential receiving area and a polygonal source (Lambert's
// point-to-polygon formula), as used by receiver-vertex shooting (Wallace, Elmquist & Haines
// 1989, "A Ray Tracing Algorithm for Progressive Radiosity").

#include <algorithm>
#include <span>
#include <vector>

#include "raytrace_core/util/math.h"

namespace gilt::radiosity::solver {

using raytrace_core::DVec3;
using raytrace_core::Vec3;

/// Unoccluded form factor F(dA → A) from a differential area at `p` with unit normal `n` to the
/// planar polygon `polygon`, for light leaving the polygon's front (the side its
/// counter-clockwise winding faces): (1/2π) Σ γᵢ n·(Rᵢ × Rᵢ₊₁)/|Rᵢ × Rᵢ₊₁|. The polygon is first
/// clipped against the receiver's tangent plane, so parts behind the receiver contribute
/// nothing; a receiver behind the polygon's plane, or a polygon seen from its back, gives 0.
/// In [0, 1]; computed in double precision.
double point_to_polygon_form_factor(const DVec3& p, const DVec3& n, std::span<const DVec3> polygon);

/// The same for a triangle.
double point_to_triangle_form_factor(const DVec3& p, const DVec3& n, const DVec3& a, const DVec3& b, const DVec3& c);

/// How far a receiver must be from a source triangle, in circumradii (distance from the
/// triangle's centroid over the largest centroid–vertex distance), for the far-field rule below.
/// At 6 the rule is within 0.3 % of Lambert's formula over random configurations (worst case,
/// grazing; the mean is 0.014 %), see tests/unit/test_form_factor.cpp.
inline constexpr float kFarFieldRatio = 6.0f;

/// A source point at offset d from a receiver with unit normal n counts as in or behind the
/// receiver's tangent plane when n·d ≤ kTangentSlope·|d|: a source within 10⁻⁴ rad of the plane
/// sends at most cos θ ≤ 10⁻⁴ of its light there, so its factor is below 2·10⁻⁴ (the whole
/// hemisphere at that slope) and in practice zero: it is a source coplanar with the receiver,
/// where rounding decides the sign of n·d and Lambert's formula would spend three arctangents
/// to add up nothing.
inline constexpr float kTangentSlope = 1e-4f;

inline bool in_or_behind_tangent_plane(const Vec3& d, const Vec3& n) {
  const float s = glm::dot(n, d);
  return s <= 0.0f || s * s <= kTangentSlope * kTangentSlope * glm::dot(d, d);
}

/// A source triangle prepared for form factors to many receivers: Lambert's formula near it,
/// and beyond kFarFieldRatio circumradii (with the triangle wholly in front of the receiver's
/// tangent plane) the cos·cos/(π r²) kernel integrated by the symmetric three-point rule,
/// exact for quadratics (Strang & Fix 1973), so its error falls as (circumradius / distance)⁴.
/// The far rule costs about a tenth of the exact formula.
class SourceTriangle {
 public:
  SourceTriangle() = default;
  SourceTriangle(const Vec3& a, const Vec3& b, const Vec3& c);

  /// F(dA → triangle) for a receiver at p with unit normal n; 0 behind the triangle's plane,
  /// and 0 when the triangle lies behind the receiver's tangent plane or in it (see
  /// kTangentSlope): a receiver on the same wall as the source, the commonest case.
  double form_factor(const Vec3& p, const Vec3& n) const {
    if (glm::dot(normal_, p) <= plane_offset_) return 0.0;
    if (in_or_behind_tangent_plane(a_ - p, n) && in_or_behind_tangent_plane(b_ - p, n) &&
        in_or_behind_tangent_plane(c_ - p, n))
      return 0.0;
    const Vec3 to_centroid = centroid_ - p;
    if (glm::dot(to_centroid, to_centroid) >= far_distance2_ && glm::dot(n, to_centroid) > radius_)
      return far_form_factor(p, n);
    return point_to_triangle_form_factor(DVec3(p), DVec3(n), DVec3(a_), DVec3(b_), DVec3(c_));
  }

  /// F(A_r → triangle), the mean of form_factor over a receiving triangle with unit normal n,
  /// by the symmetric six-point rule of degree 4 over the receiver (Dunavant 1985). Next to the
  /// source, where F varies steeply across the receiver, its value at the receiver's centroid
  /// is far off: 10 % low across a shared edge where the two meet at 90°, 18 % high where they
  /// close to 20°; the rule is within 2 % (tests/unit/test_form_factor.cpp). The rule is used at
  /// any distance, so that one receiver's factors to all its sources are read at the same
  /// points: in a closed room they then still sum to 1. Read at the centroid for far sources
  /// only, they summed to more where a near source gained, and the white furnace's worst
  /// vertex at ρ = 0.9 went from 0.19 % to 0.48 % off.
  double form_factor_from(const SourceTriangle& receiver, const Vec3& n) const;

  /// The far-field rule alone, whatever the distance (for tests).
  float far_form_factor(const Vec3& p, const Vec3& n) const {
    float sum = 0.0f;
    for (const Vec3& x : rule_points_) {
      const Vec3 d = x - p;
      const float r2 = glm::dot(d, d);
      const float cos_receiver = glm::dot(n, d), cos_source_scaled = -glm::dot(twice_area_normal_, d);
      if (cos_receiver > 0.0f && cos_source_scaled > 0.0f) sum += cos_receiver * cos_source_scaled / (r2 * r2);
    }
    // Σ (cos_r cos_s / π r²) · A/3 with cos_s · 2A folded in: sum / (6π).
    return std::clamp(sum * float(1.0 / (6.0 * 3.14159265358979323846)), 0.0f, 1.0f);
  }

 private:
  friend class SourceBatch;
  Vec3 a_{0.0f}, b_{0.0f}, c_{0.0f};
  Vec3 normal_{0.0f};             ///< unit
  float plane_offset_ = 0.0f;     ///< normal · a
  Vec3 centroid_{0.0f};
  float radius_ = 0.0f;           ///< largest centroid–vertex distance
  float far_distance2_ = 0.0f;    ///< (kFarFieldRatio · radius)²
  Vec3 twice_area_normal_{0.0f};  ///< (b − a) × (c − a)
  Vec3 rule_points_[3];           ///< barycentric (2/3, 1/6, 1/6) and permutations
};

/// Source triangles laid out to be evaluated together for one receiver at a time: the far-field
/// rule runs branch-free over all of them (the compiler vectorises it), and only the triangles
/// near the receiver or behind its tangent plane go through SourceTriangle::form_factor. The
/// results equal SourceTriangle::form_factor's up to float rounding of the far rule.
class SourceBatch {
 public:
  /// Prepares the triangles; at most kMaxBatch.
  void assign(std::span<const SourceTriangle> triangles);
  size_t size() const { return triangles_.size(); }
  /// F(dA → triangle k) for every k into out[k], for a receiver at p with unit normal n.
  void form_factors(const Vec3& p, const Vec3& n, float* out) const;

  static constexpr size_t kMaxBatch = 64;

 private:
  std::vector<SourceTriangle> triangles_;
  // One array per coordinate, each of size() floats: rule points, the doubled-area normal,
  // centroid, far-field distance², radius, unit normal and plane offset, corners.
  std::vector<float> qx_[3], qy_[3], qz_[3], tx_, ty_, tz_, cx_, cy_, cz_, far2_, radius_, nx_, ny_, nz_, offset_;
  std::vector<float> vx_[3], vy_[3], vz_[3];  ///< the corners

};

}  // namespace gilt::radiosity::solver
