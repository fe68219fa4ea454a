#pragma once
// The GGX (Trowbridge–Reitz) microfacet distribution with Smith's masking, isotropic, in the
// local shading frame (+z is the macro-normal), and the sampling of its visible normals.
//
//   D(h)   = α² / (π cos⁴θh (α² + tan²θh)²)                 Walter et al. 2007, eq. 33
//   Λ(w)   = (√(1 + α² tan²θ) − 1) / 2                       Heitz 2014, "Understanding the
//   G1(w)  = 1 / (1 + Λ(w))                                    Masking-Shadowing Function", §5.3
//   G2     = G1(wo) G1(wi)   (separable: the form of glTF 2.0's appendix B.3.2, whose V_GGX is
//            G2 / (4 |N·L| |N·V|); the height-correlated 1 / (1 + Λ(wo) + Λ(wi)) is up to a few
//            per cent brighter at grazing angles)
//   D_wo(h) = G1(wo) max(0, wo·h) D(h) / cos θo              the visible normals seen from wo
//
// Visible normals are drawn with Heitz 2018, "Sampling the GGX Distribution of Visible Normals"
// (JCGT 7(4)): stretch wo to the α = 1 configuration, pick a point on the projected hemisphere,
// and unstretch. Every sample is a normal wo can see, so no sample is wasted on back-facing
// microfacets and the weight f cos/pdf = F·G1(wi) stays ≤ 1, unlike sampling D alone.

#include <algorithm>

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::scene {

/// Smallest α the distribution is evaluated with. Below it D's peak (1/πα²) overflows what a
/// float path weight can carry usefully; a glTF roughness of 0.03 (α = 1e-3) is already a mirror
/// to the eye.
inline constexpr float kMinGgxAlpha = 1e-3f;

class GgxDistribution {
 public:
  /// α = roughness² (glTF's and Disney's perceptual remapping is the caller's), clamped to
  /// [kMinGgxAlpha, 1]; NaN becomes 1.
  explicit GgxDistribution(float alpha);

  float alpha() const { return alpha_; }
  /// Normal distribution D(h); h on the +z side (zero below).
  float d(const Vec3& h) const;
  /// Smith's Λ for direction w (either side: uses |cos θ|).
  float lambda(const Vec3& w) const;
  float g1(const Vec3& w) const { return 1.0f / (1.0f + lambda(w)); }
  float g2(const Vec3& wo, const Vec3& wi) const { return g1(wo) * g1(wi); }
  /// Density of visible normals D_wo(h) for wo on the +z side.
  float visible_d(const Vec3& wo, const Vec3& h) const;
  /// Draws a visible normal for wo on the +z side (Heitz 2018); u in [0, 1)².
  Vec3 sample_visible(const Vec3& wo, Vec2 u) const;

 private:
  float alpha_;
};

/// The distribution of a perceptual roughness r: α = r², r clamped to [0, 1] (glTF's remapping).
inline GgxDistribution ggx_of_roughness(float roughness) {
  return GgxDistribution(sqr(std::clamp(roughness, 0.0f, 1.0f)));
}

/// w mirrored through the local xy-plane: the same direction seen from the other side of the
/// surface (how two-sided lobes bring wo to +z, and how a thin sheet's transmission mirrors its
/// reflection).
inline Vec3 flip_z(const Vec3& w) { return {w.x, w.y, -w.z}; }

/// Mirror direction of w about the unit normal h.
inline Vec3 reflect_about(const Vec3& w, const Vec3& h) { return 2.0f * glm::dot(w, h) * h - w; }

/// Schlick's Fresnel weight (1 − cos θ)⁵: F = F0 + (1 − F0)·weight (Schlick 1994).
inline float schlick_weight(float cos_theta) {
  const float m = std::clamp(1.0f - cos_theta, 0.0f, 1.0f);
  const float m2 = m * m;
  return m2 * m2 * m;
}

}  // namespace gilt::raytrace_core::scene
