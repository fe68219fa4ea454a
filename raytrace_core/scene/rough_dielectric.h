#pragma once
// A rough dielectric interface: GGX microfacets that reflect and refract (Walter, Marschner, Li
// & Torrance 2007, "Microfacet Models for Refraction through Rough Surfaces", EGSR), the model of
// glTF's KHR_materials_transmission when its roughness is above zero, and of MTL glass with `Pr`.
//
// In the local shading frame (+z the outside), η = ior (inside over outside), D, G1 and the
// separable G2 of α = roughness² as in microfacet.h, F the exact unpolarised Fresnel reflectance
// (fresnel_dielectric, as the smooth interface uses, so that the rough interface tends to it):
//
//   wo, wi on one side:  f_r = F(wo·h) D(h) G2 / (4 |cos θo| |cos θi|),   h ∥ wo + wi
//   on opposite sides:   f_t = tint (1 − F(wo·h)) D(h) G2 |wo·h| |wi·h| / (|cos θo| |cos θi| (wi·h + wo·h/η')²),
//                        h ∥ η' wi + wo,  η' = IOR of wi's side over IOR of wo's side,
//
// with h turned to the +z side (Walter 2007, eqs. 16 and 21). For radiance f_t is further
// divided by η'² (Veach 1997, §5.2), for importance it is not: so f_radiance(wo, wi) =
// f_importance(wi, wo), the adjoint relation of a refracting BSDF.
//
// Sampling draws a normal h visible from wo (Heitz 2018; from −wo when wo is inside), then
// reflects with probability F(wo·h) and refracts otherwise. Density of wi: D_wo(h) times F / (4 |wo·h|)
// or (1 − F) |wi·h| / (wi·h + wo·h/η')², the Jacobians of reflection and refraction.
//
// A thin-walled sheet (glTF transmission without a volume) has air on both sides: each face
// reflects as the front one does, and its transmitted lobe is the reflected lobe mirrored
// through the sheet's plane, weighted by (1 − F) and the tint. As α → 0 it passes light unbent,
// as the smooth sheet does.

#include "raytrace_core/scene/bsdf.h"

namespace gilt::raytrace_core::scene {

/// f(wo, wi) of a rough dielectric (m.kind == dielectric, roughness above the smooth limit).
Rgb rough_dielectric_eval(const Material& m, const Vec3& wo, const Vec3& wi, TransportMode mode);

/// Density with which rough_dielectric_sample draws wi.
float rough_dielectric_pdf(const Material& m, const Vec3& wo, const Vec3& wi);

/// One direction: u picks the visible normal, u_lobe reflection or refraction.
std::optional<BsdfSample> rough_dielectric_sample(const Material& m, const Vec3& wo, float u_lobe, Vec2 u,
                                                  TransportMode mode);

}  // namespace gilt::raytrace_core::scene
