// BSDFs of gilt's four materials, in the local shading frame (cos θ = w.z).
//   Lambertian diffuse, sampled with Malley's cosine-weighted hemisphere.
//   Glossy: Lambertian + energy-normalised modified Phong, Lafortune & Willems 1994, "Using the
//     Modified Phong Reflectance Model for Physically Based Rendering" (CW report 197).
//   Rough dielectric: GGX reflection and refraction, Walter et al. 2007 (rough_dielectric.h).
//   Mirror and smooth dielectric: delta lobes with the exact unpolarised Fresnel equations
//     (Born & Wolf, "Principles of Optics", §1.5), 1/η² radiance scaling across a refractive
//     interface as in Veach 1997, "Robust Monte Carlo Methods for Light Transport Simulation", §5.2.
//   Metallic-roughness: glTF 2.0's appendix B, term by term (V = wo, L = wi, H their half vector):
//       f = (1 − m)·[(1 − F_d)·c/π + F_d·S] + m·F_c·S,   S = D(H)·G2(V, L) / (4 |N·V| |N·L|),
//       F_d = F0 + (1 − F0)(1 − |V·H|)⁵ with F0 = ((η − 1)/(η + 1))²,  F_c = c + (1 − c)(1 − |V·H|)⁵,
//     with c the base colour, m the metalness, GGX D and separable Smith G2 of α = r²
//     (microfacet.h). It is sampled by a one-sample mixture of visible-normal sampling (Heitz
//     2018) and the cosine-weighted hemisphere, the lobe chosen by its Fresnel weight at wo.

#include "raytrace_core/scene/bsdf.h"

#include <algorithm>

#include "raytrace_core/scene/microfacet.h"
#include "raytrace_core/scene/rough_dielectric.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::raytrace_core::scene {
namespace {

// Above this the Phong lobe is narrower than float directions can resolve (width ~ sqrt(2/n)
// radians vs. ~3e-4 rad between neighbouring unit floats near the lobe axis); capping it also
// keeps (n + 2) / 2π and the sampling exponent finite for absurd inputs.
constexpr float kMaxPhongExponent = 1e6f;

float phong_exponent(const Material& m) {
  return m.exponent > 0.0f ? std::min(m.exponent, kMaxPhongExponent) : 0.0f;  // NaN → 0
}

// Mirror direction of wo about the normal +z.
Vec3 mirror_direction(const Vec3& wo) { return {-wo.x, -wo.y, wo.z}; }

// Probability of choosing the Phong lobe rather than the Lambertian one (glossy); < 0 when the
// material reflects nothing.
float specular_lobe_probability(const Material& m) {
  const float d = std::max(0.0f, m.albedo.average());
  const float s = std::max(0.0f, m.specular.average());
  return d + s > 0.0f ? s / (d + s) : -1.0f;
}

// cos α between wi and the mirror direction of wo, raised to n; zero outside the lobe.
float phong_cos_power(const Vec3& wo, const Vec3& wi, float n) {
  const float cos_alpha = glm::dot(wi, mirror_direction(wo));
  return cos_alpha > 0.0f ? std::pow(std::min(cos_alpha, 1.0f), n) : 0.0f;
}

// The following take wo and wi on the +z side.
Rgb glossy_eval_front(const Material& m, const Vec3& wo, const Vec3& wi) {
  const float n = phong_exponent(m);
  const float lobe = (n + 2.0f) * kInv2Pi * phong_cos_power(wo, wi, n);
  return m.albedo * kInvPi + m.specular * lobe;
}

float glossy_pdf_front(const Material& m, const Vec3& wo, const Vec3& wi) {
  const float ps = specular_lobe_probability(m);
  if (ps < 0.0f) return 0.0f;
  const float n = phong_exponent(m);
  const float lobe_pdf = (n + 1.0f) * kInv2Pi * phong_cos_power(wo, wi, n);
  return ps * lobe_pdf + (1.0f - ps) * util::cosine_hemisphere_pdf(wi.z);
}

// Direction with density (n + 1)/2π cos^n α around the mirror direction of wo, α ≤ π/2.
Vec3 sample_phong_lobe(const Vec3& wo, float n, Vec2 u) {
  // cos α = u^(1/(n+1)); 1 − cos α via expm1 keeps sin α accurate for narrow lobes.
  const float t = std::log(u.x) / (n + 1.0f);  // −∞ when u.x = 0: cos α = 0
  const float cos_alpha = std::exp(t);
  const float one_minus_cos = -std::expm1(t);
  const float sin_alpha = safe_sqrt(one_minus_cos * (1.0f + cos_alpha));
  const float phi = 2.0f * kPi * u.y;
  const Vec3 local{sin_alpha * std::cos(phi), sin_alpha * std::sin(phi), cos_alpha};
  return Frame::from_normal(glm::normalize(mirror_direction(wo))).to_world(local);
}

// ---- Metallic-roughness (wo, wi on the +z side). ----

float dielectric_f0(float ior) {
  const float eta = ior > 0.0f && std::isfinite(ior) ? ior : 1.5f;
  return sqr((eta - 1.0f) / (eta + 1.0f));
}

float clamped_metallic(const Material& m) { return m.metallic > 0.0f ? std::min(m.metallic, 1.0f) : 0.0f; }  // NaN → 0

Rgb metallic_roughness_eval_front(const Material& m, const Vec3& wo, const Vec3& wi) {
  const Vec3 sum = wo + wi;
  const float len2 = glm::dot(sum, sum);
  if (!(len2 > 0.0f)) return Rgb(0.0f);
  const Vec3 h = sum / std::sqrt(len2);
  const GgxDistribution ggx = ggx_of_roughness(m.roughness);
  const float metal = clamped_metallic(m);
  const float weight = schlick_weight(std::fabs(glm::dot(wo, h)));
  const float f0 = dielectric_f0(m.ior);
  const float f_dielectric = f0 + (1.0f - f0) * weight;
  const Rgb f_conductor = m.albedo + (Rgb(1.0f) - m.albedo) * weight;
  const float specular = ggx.d(h) * ggx.g2(wo, wi) / (4.0f * wo.z * wi.z);
  const Rgb dielectric = m.albedo * ((1.0f - f_dielectric) * kInvPi) + Rgb(f_dielectric * specular);
  return dielectric * (1.0f - metal) + f_conductor * (metal * specular);
}

// Probability of drawing from the specular lobe rather than the diffuse one: the two lobes'
// weights at wo, with the normal standing in for the half vector; < 0 when nothing reflects.
float metallic_roughness_specular_probability(const Material& m, const Vec3& wo) {
  const float metal = clamped_metallic(m);
  const float weight = schlick_weight(wo.z);
  const float f0 = dielectric_f0(m.ior);
  const float f_dielectric = f0 + (1.0f - f0) * weight;
  const float base = std::clamp(m.albedo.average(), 0.0f, 1.0f);
  const float specular = (1.0f - metal) * f_dielectric + metal * (base + (1.0f - base) * weight);
  const float diffuse = (1.0f - metal) * (1.0f - f_dielectric) * base;
  return specular + diffuse > 0.0f ? specular / (specular + diffuse) : -1.0f;
}

float metallic_roughness_pdf_front(const Material& m, const Vec3& wo, const Vec3& wi) {
  const float ps = metallic_roughness_specular_probability(m, wo);
  if (ps < 0.0f) return 0.0f;
  float specular_pdf = 0.0f;
  const Vec3 sum = wo + wi;
  const float len2 = glm::dot(sum, sum);
  if (len2 > 0.0f) {
    const Vec3 h = sum / std::sqrt(len2);
    const float cos_oh = glm::dot(wo, h);
    // Reflection maps h to wi with Jacobian 1 / (4 wo·h).
    if (cos_oh > 0.0f) specular_pdf = ggx_of_roughness(m.roughness).visible_d(wo, h) / (4.0f * cos_oh);
  }
  return ps * specular_pdf + (1.0f - ps) * util::cosine_hemisphere_pdf(wi.z);
}

std::optional<BsdfSample> sample_reflective(const Material& m, Vec3 wo, float u_lobe, Vec2 u) {
  if (wo.z == 0.0f) return std::nullopt;
  const bool flipped = wo.z < 0.0f;
  if (flipped) wo = flip_z(wo);

  Vec3 wi;
  if (m.kind == MaterialKind::diffuse) {
    wi = util::sample_cosine_hemisphere(u);
  } else if (m.kind == MaterialKind::metallic_roughness) {
    const float ps = metallic_roughness_specular_probability(m, wo);
    if (ps < 0.0f) return std::nullopt;
    wi = u_lobe < ps ? reflect_about(wo, ggx_of_roughness(m.roughness).sample_visible(wo, u)) : util::sample_cosine_hemisphere(u);
  } else {
    const float ps = specular_lobe_probability(m);
    if (ps < 0.0f) return std::nullopt;
    wi = u_lobe < ps ? sample_phong_lobe(wo, phong_exponent(m), u) : util::sample_cosine_hemisphere(u);
  }
  if (!(wi.z > 0.0f)) return std::nullopt;  // under the surface, or on the horizon (pdf 0)

  BsdfSample s;
  if (m.kind == MaterialKind::diffuse) {
    s.f = m.albedo * kInvPi;
    s.pdf = util::cosine_hemisphere_pdf(wi.z);
  } else if (m.kind == MaterialKind::metallic_roughness) {
    s.f = metallic_roughness_eval_front(m, wo, wi);
    s.pdf = metallic_roughness_pdf_front(m, wo, wi);
  } else {
    s.f = glossy_eval_front(m, wo, wi);
    s.pdf = glossy_pdf_front(m, wo, wi);
  }
  if (!(s.pdf > 0.0f) || !std::isfinite(s.pdf) || !s.f.is_finite() || s.f.is_black()) return std::nullopt;
  s.wi = flipped ? flip_z(wi) : wi;
  return s;
}

std::optional<BsdfSample> sample_mirror(const Material& m, const Vec3& wo) {
  const float cos_i = std::fabs(wo.z);
  if (cos_i == 0.0f) return std::nullopt;
  BsdfSample s;
  s.wi = mirror_direction(wo);
  s.f = m.specular / cos_i;
  s.pdf = 1.0f;
  s.delta = true;
  if (!s.f.is_finite() || s.f.is_black()) return std::nullopt;
  return s;
}

std::optional<BsdfSample> sample_dielectric(const Material& m, const Vec3& wo, float u_lobe,
                                            TransportMode mode) {
  const float eta = m.ior;  // inside over outside
  const float cos_o = wo.z;
  if (!(eta > 0.0f) || !std::isfinite(eta) || cos_o == 0.0f) return std::nullopt;
  // A thin sheet has the same medium on both sides: either face reflects as the front one does
  // (no total internal reflection, which would trap rays inside a closed thin shell forever).
  const float reflectance = fresnel_dielectric(m.thin_walled ? std::fabs(cos_o) : cos_o, eta);

  BsdfSample s;
  s.delta = true;
  if (u_lobe < reflectance) {
    s.wi = mirror_direction(wo);
    s.f = Rgb(reflectance / std::fabs(cos_o));
    s.pdf = reflectance;
  } else {
    if (m.thin_walled) {  // an infinitely thin sheet: through, unbent, the same medium behind
      const float cos_i = std::fabs(cos_o);
      s.wi = -wo;
      s.f = m.transmission_tint * ((1.0f - reflectance) / cos_i);
      s.pdf = 1.0f - reflectance;
      s.transmission = true;
      if (!(s.pdf > 0.0f) || !s.f.is_finite() || s.f.is_black()) return std::nullopt;
      return s;
    }
    // eta_rel = IOR on wi's side / IOR on wo's side. Entering (wo outside, z > 0): eta;
    // leaving (wo inside): 1/eta. Snell: sin θi = sin θo / eta_rel.
    const bool entering = cos_o > 0.0f;
    const float eta_rel = entering ? eta : 1.0f / eta;
    const float abs_cos_o = std::fabs(cos_o);
    const float sin2_t = (1.0f - abs_cos_o) * (1.0f + abs_cos_o) / (eta_rel * eta_rel);
    if (!(sin2_t < 1.0f)) return std::nullopt;  // total internal reflection: reflectance is 1
    const float cos_t = std::sqrt(1.0f - sin2_t);
    if (cos_t == 0.0f) return std::nullopt;
    s.wi = {-wo.x / eta_rel, -wo.y / eta_rel, entering ? -cos_t : cos_t};
    const float transmittance = 1.0f - reflectance;
    // Radiance is compressed into the smaller solid angle on the denser side: a camera path
    // carries L(wi) · (n_wo / n_wi)², i.e. f is scaled by 1/eta_rel². Importance is not scaled
    // (Veach 1997, §5.2), so that f·|cos θi|/pdf sums to R + T = 1 over the two branches.
    float scale = transmittance / cos_t;
    if (mode == TransportMode::radiance) scale /= eta_rel * eta_rel;
    s.f = m.transmission_tint * scale;
    s.pdf = transmittance;
    s.transmission = true;
  }
  if (!(s.pdf > 0.0f) || !s.f.is_finite()) return std::nullopt;
  return s;
}

}  // namespace

Rgb bsdf_eval(const Material& m, const Vec3& wo, const Vec3& wi, TransportMode mode) {
  if (m.is_rough_dielectric()) return rough_dielectric_eval(m, wo, wi, mode);
  if (!(wo.z * wi.z > 0.0f)) return Rgb(0.0f);  // opposite sides, or grazing
  switch (m.kind) {
    case MaterialKind::diffuse:
      return m.albedo * kInvPi;
    case MaterialKind::glossy:
      return wo.z > 0.0f ? glossy_eval_front(m, wo, wi) : glossy_eval_front(m, flip_z(wo), flip_z(wi));
    case MaterialKind::metallic_roughness:
      return wo.z > 0.0f ? metallic_roughness_eval_front(m, wo, wi)
                         : metallic_roughness_eval_front(m, flip_z(wo), flip_z(wi));
    case MaterialKind::mirror:
    case MaterialKind::dielectric:
      return Rgb(0.0f);
  }
  return Rgb(0.0f);
}

float bsdf_pdf(const Material& m, const Vec3& wo, const Vec3& wi) {
  if (m.is_rough_dielectric()) return rough_dielectric_pdf(m, wo, wi);
  if (!(wo.z * wi.z > 0.0f)) return 0.0f;
  switch (m.kind) {
    case MaterialKind::diffuse:
      return util::cosine_hemisphere_pdf(std::fabs(wi.z));
    case MaterialKind::glossy:
      return wo.z > 0.0f ? glossy_pdf_front(m, wo, wi) : glossy_pdf_front(m, flip_z(wo), flip_z(wi));
    case MaterialKind::metallic_roughness:
      return wo.z > 0.0f ? metallic_roughness_pdf_front(m, wo, wi)
                         : metallic_roughness_pdf_front(m, flip_z(wo), flip_z(wi));
    case MaterialKind::mirror:
    case MaterialKind::dielectric:
      return 0.0f;
  }
  return 0.0f;
}

std::optional<BsdfSample> bsdf_sample(const Material& m, const Vec3& wo, float u_lobe, Vec2 u,
                                      TransportMode mode) {
  switch (m.kind) {
    case MaterialKind::diffuse:
    case MaterialKind::glossy:
    case MaterialKind::metallic_roughness:
      return sample_reflective(m, wo, u_lobe, u);
    case MaterialKind::mirror:
      return sample_mirror(m, wo);
    case MaterialKind::dielectric:
      return m.is_rough_dielectric() ? rough_dielectric_sample(m, wo, u_lobe, u, mode)
                                     : sample_dielectric(m, wo, u_lobe, mode);
  }
  return std::nullopt;
}

Rgb diffuse_reflectance(const Material& m) {
  switch (m.kind) {
    case MaterialKind::diffuse:
    case MaterialKind::glossy:
      return m.albedo;
    case MaterialKind::metallic_roughness:
      return m.albedo * ((1.0f - clamped_metallic(m)) * (1.0f - dielectric_f0(m.ior)));
    case MaterialKind::mirror:
    case MaterialKind::dielectric:
      return Rgb(0.0f);
  }
  return Rgb(0.0f);
}

float fresnel_dielectric(float cos_i, float eta) {
  if (!(eta > 0.0f) || !std::isfinite(eta)) return 1.0f;  // no valid interface: reflect all
  cos_i = std::clamp(cos_i, -1.0f, 1.0f);
  if (cos_i < 0.0f) {  // arriving from inside: the roles of the two media swap
    eta = 1.0f / eta;
    cos_i = -cos_i;
  }
  const float sin2_t = (1.0f - cos_i) * (1.0f + cos_i) / (eta * eta);
  if (!(sin2_t < 1.0f)) return 1.0f;  // total internal reflection
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const float parallel_den = eta * cos_i + cos_t;
  const float perpendicular_den = cos_i + eta * cos_t;
  if (!(parallel_den > 0.0f) || !(perpendicular_den > 0.0f)) return 1.0f;
  const float r_parallel = (eta * cos_i - cos_t) / parallel_den;
  const float r_perpendicular = (cos_i - eta * cos_t) / perpendicular_den;
  return std::clamp(0.5f * (r_parallel * r_parallel + r_perpendicular * r_perpendicular), 0.0f, 1.0f);
}

}  // namespace gilt::raytrace_core::scene
