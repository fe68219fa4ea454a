#pragma once
// Evaluation, sampling and density of every material's BSDF.
//
// All directions are unit vectors in the local shading frame (Frame::to_local) whose +z is the
// surface's front normal; wo and wi point away from the surface. Reflective lobes of diffuse,
// glossy and mirror materials work on both sides (wo.z < 0 is mirrored to the front); the
// dielectric distinguishes inside (z < 0) from outside (z > 0); a rough one (rough_dielectric.h)
// has non-delta reflection and refraction, so f and pdf are non-zero across the surface too.
//
// Conventions follow pbrt: f excludes the cosine factor; for a delta lobe f = (weight) / |cos θi|
// and pdf is the discrete probability of choosing that lobe, flagged by `delta`.

#include <optional>

#include "raytrace_core/scene/material.h"
#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::scene {

/// Whether a path carries radiance (camera paths) or importance (light paths, photons). Only
/// refraction differs: radiance is scaled by 1/η² across the interface, importance is not.
enum class TransportMode : uint8_t { radiance, importance };

/// One sampled scattering direction.
struct BsdfSample {
  Vec3 wi{0.0f};
  Rgb f{0.0f};        ///< BSDF value (per steradian; for delta lobes already divided by |cos θi|)
  float pdf = 0.0f;   ///< solid-angle density, or the lobe probability when delta
  bool delta = false; ///< sampled a specular (Dirac) lobe
  bool transmission = false;  ///< wi lies on the other side of the surface from wo
};

/// Non-delta BSDF value f(wo, wi) (zero for mirror and smooth dielectric). Only a rough
/// dielectric's refraction depends on `mode`.
Rgb bsdf_eval(const Material& m, const Vec3& wo, const Vec3& wi, TransportMode mode = TransportMode::radiance);

/// Solid-angle density with which bsdf_sample draws wi given wo (zero for delta-only materials).
/// A rough dielectric's pdf is the same for radiance and importance.
float bsdf_pdf(const Material& m, const Vec3& wo, const Vec3& wi);

/// Draws wi given wo. `u_lobe` picks among lobes, `u` the direction within it. Empty when the
/// sample carries no energy (e.g. below the surface for a glossy lobe).
std::optional<BsdfSample> bsdf_sample(const Material& m, const Vec3& wo, float u_lobe, Vec2 u,
                                      TransportMode mode = TransportMode::radiance);

/// Reflectance of the material's Lambertian part: what radiosity and the photon map's irradiance
/// gather treat as diffuse. The albedo for diffuse and glossy materials; (1 − metallic)(1 − F0)
/// times the base colour for metallic-roughness (F0 the dielectric's normal reflectance, 0.04
/// for η = 1.5: the light the specular layer takes at normal incidence); zero for mirror and
/// glass, smooth or rough.
Rgb diffuse_reflectance(const Material& m);

/// Fresnel reflectance of an unpolarised dielectric interface. cos_i > 0 means arriving from the
/// outside; eta is the inside IOR over the outside IOR.
float fresnel_dielectric(float cos_i, float eta);

}  // namespace gilt::raytrace_core::scene
