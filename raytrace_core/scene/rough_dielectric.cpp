// The rough dielectric BSDF; see rough_dielectric.h for the formulas and their sources.
//
// Written after pbrt-v4's DielectricBxDF (Pharr, Jakob & Humphreys, 4th ed., §9.7) in its
// conventions (η' relative to wo's side, back-facing microfacets rejected), with two choices of
// gilt's own: the separable Smith G2 of the glTF specification, as the metallic-roughness BRDF
// uses, and one routine that gives f and pdf together, so that a sample's f and pdf are by
// construction what bsdf_eval and bsdf_pdf report for the same pair.

#include "raytrace_core/scene/rough_dielectric.h"

#include <algorithm>
#include <cmath>

#include "raytrace_core/scene/microfacet.h"

namespace gilt::raytrace_core::scene {
namespace {

bool valid_ior(float eta) { return eta > 0.0f && std::isfinite(eta); }

struct Value {
  Rgb f{0.0f};
  float pdf = 0.0f;
};

// A thin sheet, with wo and wi in the frame where wo.z > 0.
Value thin_sheet(const Material& m, const GgxDistribution& ggx, const Vec3& wo, const Vec3& wi) {
  const bool transmitted = wi.z < 0.0f;
  const Vec3 wr = transmitted ? flip_z(wi) : wi;  // the transmitted lobe is the reflected one, mirrored
  const Vec3 sum = wo + wr;
  const float len2 = glm::dot(sum, sum);
  if (!(len2 > 0.0f)) return {};
  const Vec3 h = sum / std::sqrt(len2);
  const float cos_oh = glm::dot(wo, h);
  if (!(cos_oh > 0.0f) || !(glm::dot(wr, h) > 0.0f)) return {};
  const float reflectance = fresnel_dielectric(cos_oh, m.ior);
  const float weight = transmitted ? 1.0f - reflectance : reflectance;
  const float lobe = weight * ggx.d(h) * ggx.g2(wo, wr) / (4.0f * wo.z * wr.z);
  Value v;
  v.f = transmitted ? m.transmission_tint * lobe : Rgb(lobe);
  v.pdf = weight * ggx.visible_d(wo, h) / (4.0f * cos_oh);
  return v;
}

Value evaluate(const Material& m, Vec3 wo, Vec3 wi, TransportMode mode) {
  if (wo.z == 0.0f || wi.z == 0.0f || !valid_ior(m.ior)) return {};
  const GgxDistribution ggx = ggx_of_roughness(m.roughness);
  if (m.thin_walled) return wo.z > 0.0f ? thin_sheet(m, ggx, wo, wi) : thin_sheet(m, ggx, flip_z(wo), flip_z(wi));

  const bool reflected = wo.z * wi.z > 0.0f;
  const float eta_rel = reflected ? 1.0f : (wo.z > 0.0f ? m.ior : 1.0f / m.ior);
  Vec3 h = eta_rel * wi + wo;  // reflection: wo + wi
  const float len2 = glm::dot(h, h);
  if (!(len2 > 0.0f)) return {};
  h /= std::sqrt(len2);
  if (h.z < 0.0f) h = -h;
  const float cos_oh = glm::dot(wo, h), cos_ih = glm::dot(wi, h);
  // Back-facing microfacets: each direction must lie on its own side of h as of the macro-surface.
  if (!(cos_oh * wo.z > 0.0f) || !(cos_ih * wi.z > 0.0f)) return {};

  const float reflectance = fresnel_dielectric(cos_oh, m.ior);
  const float visible = ggx.visible_d(wo.z > 0.0f ? wo : -wo, h);
  const float dg = ggx.d(h) * ggx.g2(wo, wi);
  const float cos_o = std::fabs(wo.z), cos_i = std::fabs(wi.z);
  Value v;
  if (reflected) {
    v.f = Rgb(reflectance * dg / (4.0f * cos_o * cos_i));
    v.pdf = reflectance * visible / (4.0f * std::fabs(cos_oh));
    return v;
  }
  const float denom = sqr(cos_ih + cos_oh / eta_rel);
  if (!(denom > 0.0f)) return {};
  const float transmittance = 1.0f - reflectance;
  float scale = transmittance * dg * std::fabs(cos_oh * cos_ih) / (cos_o * cos_i * denom);
  if (mode == TransportMode::radiance) scale /= eta_rel * eta_rel;
  v.f = m.transmission_tint * scale;
  v.pdf = transmittance * visible * std::fabs(cos_ih) / denom;
  return v;
}

}  // namespace

Rgb rough_dielectric_eval(const Material& m, const Vec3& wo, const Vec3& wi, TransportMode mode) {
  return evaluate(m, wo, wi, mode).f;
}

float rough_dielectric_pdf(const Material& m, const Vec3& wo, const Vec3& wi) {
  return evaluate(m, wo, wi, TransportMode::radiance).pdf;
}

std::optional<BsdfSample> rough_dielectric_sample(const Material& m, const Vec3& wo, float u_lobe, Vec2 u,
                                                  TransportMode mode) {
  if (wo.z == 0.0f || !valid_ior(m.ior)) return std::nullopt;
  const GgxDistribution ggx = ggx_of_roughness(m.roughness);
  Vec3 wi;
  if (m.thin_walled) {
    const bool flipped = wo.z < 0.0f;
    const Vec3 w = flipped ? flip_z(wo) : wo;
    const Vec3 h = ggx.sample_visible(w, u);
    const Vec3 wr = reflect_about(w, h);
    if (!(wr.z > 0.0f)) return std::nullopt;
    wi = u_lobe < fresnel_dielectric(glm::dot(w, h), m.ior) ? wr : flip_z(wr);
    if (flipped) wi = flip_z(wi);
  } else {
    const Vec3 h = ggx.sample_visible(wo.z > 0.0f ? wo : -wo, u);
    const float cos_oh = glm::dot(wo, h);
    const bool reflect = u_lobe < fresnel_dielectric(cos_oh, m.ior);
    if (reflect) {
      wi = reflect_about(wo, h);
    } else {
      // Refraction through the microfacet h: Snell's law about the normal on wo's side.
      const float eta_rel = cos_oh > 0.0f ? m.ior : 1.0f / m.ior;
      const Vec3 n = cos_oh > 0.0f ? h : -h;
      const float cos_i = std::fabs(cos_oh);
      const float sin2_t = (1.0f - cos_i) * (1.0f + cos_i) / (eta_rel * eta_rel);
      if (!(sin2_t < 1.0f)) return std::nullopt;  // total internal reflection (F = 1: not reached)
      wi = -wo / eta_rel + (cos_i / eta_rel - std::sqrt(1.0f - sin2_t)) * n;
    }
    // A microfacet may send light to the wrong side of the macro-surface: reflected below it,
    // refracted back above it. The BSDF is zero there; such a sample carries nothing.
    if ((wi.z * wo.z > 0.0f) != reflect) return std::nullopt;
  }
  const Value v = evaluate(m, wo, wi, mode);
  if (!(v.pdf > 0.0f) || !std::isfinite(v.pdf) || !v.f.is_finite() || v.f.is_black()) return std::nullopt;
  BsdfSample s;
  s.wi = wi;
  s.f = v.f;
  s.pdf = v.pdf;
  s.transmission = wo.z * wi.z < 0.0f;
  return s;
}

}  // namespace gilt::raytrace_core::scene
