// Tests of the GGX distribution (raytrace_core/scene/microfacet.h) and of the glTF metallic-roughness
// BSDF built on it (raytrace_core/scene/bsdf.cpp), plus the thin-walled and tinted dielectric.
//
//   - D is normalised: ∫ D(h) cos θh dω = 1, by quadrature in cos θ.
//   - Visible normals: sample_visible follows visible_d (chi-square; visible_d integrating to one
//     over the sphere is tested with it, through the chi-square's remainder cell).
//   - The BSDF's sampled directions follow bsdf_pdf (chi-square), and each sample reports f and
//     pdf equal to bsdf_eval and bsdf_pdf.
//   - Closed form: bsdf_eval against the specification's own formula, written independently here
//     in double precision with its own visibility form V_GGX (an algebraically different route).
//   - Reciprocity f(wo, wi) = f(wi, wo) and positivity.
//   - White furnace: with base colour 1, directional albedo never exceeds one; a BSDF-sampled and
//     a uniformly sampled estimate agree; the energy a single-scattering GGX loses at high
//     roughness is measured and printed (it is physical loss of the model, not an error).
//
// Chi-square tests run at α = 0.01 Šidák-corrected over this program's kChi2Tests. Monte Carlo
// comparisons use z = 4 standard errors (two-sided false failure 6.3e-5 per check).

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/scene/microfacet.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "tests/statistical/bsdf_chi2.h"
#include "tests/statistical/bsdf_test_kit.h"
#include "tests/statistical/chi2.h"

namespace gilt::raytrace_core::scene {
namespace {

constexpr int kChi2Tests = 6 + 24;  // visible normals + BSDF lobes
constexpr size_t kChi2Samples = 1000000;
constexpr double kZ = 4.0;
const double kAlpha = test::sidak_alpha(test::kFamilyAlpha, kChi2Tests);

using test::LobeCase;
using test::spherical;

TEST(Ggx, DistributionIsNormalised) {
  // ∫ D cos θ dω = 2π ∫₀¹ D(μ) μ dμ with μ = cos θ. Midpoint rule on a grid graded towards μ = 1
  // (μ = 1 − s², s uniform), where D peaks with width ~α²; 2e6 cells bring the rule's error below
  // 1e-6 for α ≥ 0.05 (checked by halving the grid: the result moves by less than that).
  for (float alpha : {0.05f, 0.2f, 0.5f, 1.0f}) {
    const GgxDistribution ggx(alpha);
    constexpr int kCells = 2000000;
    double sum = 0.0;
    for (int i = 0; i < kCells; ++i) {
      const double s = (i + 0.5) / kCells;
      const double mu = 1.0 - s * s;
      const double sin_theta = std::sqrt(std::max(0.0, 1.0 - mu * mu));
      const Vec3 h{float(sin_theta), 0.0f, float(mu)};
      sum += double(ggx.d(h)) * mu * (2.0 * s / kCells);  // dμ = 2 s ds
    }
    EXPECT_NEAR(2.0 * std::numbers::pi * sum, 1.0, 2e-5) << "alpha " << alpha;
  }
}

TEST(Ggx, ClampsAlpha) {
  EXPECT_EQ(GgxDistribution(0.0f).alpha(), kMinGgxAlpha);
  EXPECT_EQ(GgxDistribution(-1.0f).alpha(), kMinGgxAlpha);
  EXPECT_EQ(GgxDistribution(std::nanf("")).alpha(), 1.0f);
  EXPECT_EQ(GgxDistribution(7.0f).alpha(), 1.0f);
  EXPECT_EQ(GgxDistribution(0.3f).alpha(), 0.3f);
}

struct VisibleCase {
  std::string name;
  float alpha;
  Vec3 wo;
};

class VisibleNormals : public testing::TestWithParam<VisibleCase> {};

TEST_P(VisibleNormals, SamplesFollowVisibleD) {
  const VisibleCase& c = GetParam();
  const GgxDistribution ggx(c.alpha);
  const auto r = test::chi2_directions(
      test::theta_grid(48, 96, 0.5 * std::numbers::pi), kChi2Samples, 0x71 + std::hash<std::string>{}(c.name) % 997,
      [&](util::Rng& rng) -> std::optional<Vec3> { return ggx.sample_visible(c.wo, rng.uniform2()); },
      [&](Vec3 h) { return ggx.visible_d(c.wo, h); }, kAlpha);
  test::expect_chi2_pass(r);
}

INSTANTIATE_TEST_SUITE_P(Ggx, VisibleNormals,
                         testing::Values(VisibleCase{"a03_normal", 0.3f, {0, 0, 1}},
                                         VisibleCase{"a03_oblique", 0.3f, spherical(1.0f, 0.7f)},
                                         VisibleCase{"a03_grazing", 0.3f, spherical(1.5f, 0.7f)},
                                         VisibleCase{"a1_normal", 1.0f, {0, 0, 1}},
                                         VisibleCase{"a1_oblique", 1.0f, spherical(1.0f, 0.7f)},
                                         VisibleCase{"a1_grazing", 1.0f, spherical(1.5f, 0.7f)}),
                         [](const auto& info) { return info.param.name; });

// ---- The metallic-roughness BSDF. ----

const std::vector<std::pair<std::string, Vec3>> kWos{{"normal", {0.0f, 0.0f, 1.0f}},
                                                     {"oblique45", spherical(0.25f * kPi, 0.7f)},
                                                     {"grazing", spherical(std::acos(0.05f), 0.7f)},
                                                     {"below120", spherical(2.0f * kPi / 3.0f, 0.7f)}};

std::vector<LobeCase> lobe_cases() {
  // Roughness 0.35 (α ≈ 0.12) is the narrowest lobe the 48-row θ grid resolves at this sample
  // count; narrower lobes are covered by the sample-consistency and closed-form tests.
  std::vector<LobeCase> cases;
  for (float roughness : {0.35f, 0.6f, 1.0f})
    for (float metallic : {0.0f, 1.0f})
      for (const auto& [wo_name, wo] : kWos) {
        char name[64];
        std::snprintf(name, sizeof name, "r%03d_m%d_%s", int(roughness * 100), int(metallic), wo_name.c_str());
        cases.push_back({name, Material::make_metallic_roughness("mr", Rgb(0.8f, 0.5f, 0.2f), metallic, roughness), wo});
      }
  return cases;
}

class MetallicRoughnessLobe : public testing::TestWithParam<LobeCase> {};

TEST_P(MetallicRoughnessLobe, SampledDirectionsFollowPdf) {
  const LobeCase& c = GetParam();
  test::expect_chi2_pass(
      test::chi2_bsdf(c.material, c.wo, kChi2Samples, 0x3e1 + std::hash<std::string>{}(c.name) % 1000, kAlpha));
}

TEST_P(MetallicRoughnessLobe, SampleMatchesEvalAndPdf) {
  // Same float expressions on both sides: agreement to rounding (relative 1e-5, a few dozen
  // operations of 2^-24 each through the normalised half vector).
  const LobeCase& c = GetParam();
  util::Rng rng(42);
  int taken = 0;
  for (int k = 0; k < 20000; ++k) {
    const float u_lobe = rng.uniform();
    const auto s = bsdf_sample(c.material, c.wo, u_lobe, rng.uniform2());
    if (!s) continue;
    ++taken;
    ASSERT_FALSE(s->delta);
    ASSERT_FALSE(s->transmission);
    ASSERT_GT(s->wi.z * c.wo.z, 0.0f);
    const Rgb f = bsdf_eval(c.material, c.wo, s->wi);
    const float pdf = bsdf_pdf(c.material, c.wo, s->wi);
    ASSERT_NEAR(s->pdf, pdf, 1e-5f * pdf);
    for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(s->f[ch], f[ch], 1e-5f * f[ch]);
  }
  EXPECT_GT(taken, 10000);  // most samples land above the surface, even at grazing wo
}

INSTANTIATE_TEST_SUITE_P(Bsdf, MetallicRoughnessLobe, testing::ValuesIn(lobe_cases()),
                         [](const auto& info) { return info.param.name; });

// The specification's BRDF (glTF 2.0, appendix B.3), written from its text in double precision:
// V_GGX = 1 / ((|N·L| + √(α² + (1 − α²)(N·L)²)) (|N·V| + √(α² + (1 − α²)(N·V)²))) is the
// separable Smith term already divided by 4 |N·L| |N·V|.
double spec_brdf(double base, double metallic, double roughness, const Vec3& v, const Vec3& l) {
  const double a = std::max(double(kMinGgxAlpha), roughness * roughness), a2 = a * a;
  double h[3] = {double(v.x) + l.x, double(v.y) + l.y, double(v.z) + l.z};
  const double hl = std::sqrt(h[0] * h[0] + h[1] * h[1] + h[2] * h[2]);
  for (double& x : h) x /= hl;
  const double nh = h[2], nl = l.z, nv = v.z;
  const double vh = std::fabs(double(v.x) * h[0] + double(v.y) * h[1] + double(v.z) * h[2]);
  const double d = a2 / (std::numbers::pi * std::pow(nh * nh * (a2 - 1.0) + 1.0, 2.0));
  const double vis = 1.0 / ((nl + std::sqrt(a2 + (1 - a2) * nl * nl)) * (nv + std::sqrt(a2 + (1 - a2) * nv * nv)));
  const double specular = d * vis;
  const double f_dielectric = 0.04 + 0.96 * std::pow(1.0 - vh, 5.0);
  const double f_metal = base + (1.0 - base) * std::pow(1.0 - vh, 5.0);
  const double dielectric = (1.0 - f_dielectric) * base / std::numbers::pi + f_dielectric * specular;
  return (1.0 - metallic) * dielectric + metallic * f_metal * specular;
}

TEST(MetallicRoughness, EvalIsTheSpecificationsFormula) {
  // Relative 2e-5: float evaluation (D's denominator squared near the peak, the half vector).
  const Rgb base(0.9f, 0.4f, 0.05f);
  for (float roughness : {0.05f, 0.3f, 0.7f, 1.0f})
    for (float metallic : {0.0f, 0.25f, 1.0f}) {
      const Material m = Material::make_metallic_roughness("mr", base, metallic, roughness);
      for (float to : {0.1f, 0.8f, 1.4f})
        for (float ti : {0.05f, 0.6f, 1.2f, 1.5f})
          for (float dphi : {0.0f, 1.0f, 3.0f}) {
            const Vec3 wo = spherical(to, 0.3f), wi = spherical(ti, 0.3f + kPi + dphi);
            const Rgb f = bsdf_eval(m, wo, wi);
            for (int c = 0; c < 3; ++c) {
              const double expected = spec_brdf(base[c], metallic, roughness, wo, wi);
              EXPECT_NEAR(f[c], expected, 2e-5 * expected + 1e-7)
                  << "r " << roughness << " m " << metallic << " θo " << to << " θi " << ti << " Δφ " << dphi;
            }
          }
    }
}

TEST(MetallicRoughness, IsReciprocalPositiveAndTwoSided) {
  util::Rng rng(5);
  for (int k = 0; k < 20000; ++k) {
    const Material m = Material::make_metallic_roughness("mr", Rgb(rng.uniform(), rng.uniform(), rng.uniform()),
                                                         rng.uniform(), rng.uniform());
    Vec3 wo = util::sample_uniform_sphere(rng.uniform2()), wi = util::sample_uniform_sphere(rng.uniform2());
    if (wo.z < 0.0f) wo.z = -wo.z;
    if (wi.z < 0.0f) wi.z = -wi.z;
    const Rgb a = bsdf_eval(m, wo, wi), b = bsdf_eval(m, wi, wo);
    for (int c = 0; c < 3; ++c) {
      ASSERT_GE(a[c], 0.0f);
      ASSERT_TRUE(std::isfinite(a[c]));
      // Every factor is symmetric in wo and wi (|V·H| = |L·H|); only rounding differs.
      ASSERT_NEAR(a[c], b[c], 1e-5f * a[c] + 1e-12f);
    }
    const Vec3 wo_back{wo.x, wo.y, -wo.z}, wi_back{wi.x, wi.y, -wi.z};
    ASSERT_EQ(bsdf_eval(m, wo_back, wi_back), a);
    ASSERT_TRUE(bsdf_eval(m, wo, wi_back).is_black());
    ASSERT_EQ(bsdf_pdf(m, wo, wi_back), 0.0f);
  }
}

TEST(MetallicRoughness, DegenerateInputsGiveFiniteResults) {
  const float nan = std::nanf("");
  const std::vector<Material> materials{Material::make_metallic_roughness("smooth", Rgb(1.0f), 1.0f, 0.0f),
                                        Material::make_metallic_roughness("black", Rgb(0.0f), 0.0f, 0.5f),
                                        Material::make_metallic_roughness("blackmetal", Rgb(0.0f), 1.0f, 0.5f),
                                        Material::make_metallic_roughness("nan", Rgb(0.5f), nan, nan),
                                        Material::make_metallic_roughness("ior0", Rgb(0.5f), 0.0f, 0.5f, 0.0f)};
  const std::vector<Vec3> wos{{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, spherical(1.5707f, 0.3f), spherical(1.5709f, 0.3f)};
  util::Rng rng(9);
  for (const Material& m : materials)
    for (const Vec3& wo : wos)
      for (int k = 0; k < 500; ++k) {
        const float u_lobe = k == 0 ? 0.0f : (k == 1 ? kOneMinusEpsilon : rng.uniform());
        const Vec2 u = k == 0 ? Vec2(0.0f) : (k == 1 ? Vec2(kOneMinusEpsilon) : rng.uniform2());
        if (const auto s = bsdf_sample(m, wo, u_lobe, u)) {
          ASSERT_TRUE(s->f.is_finite() && is_finite(s->wi) && std::isfinite(s->pdf)) << m.name;
          ASSERT_GT(s->pdf, 0.0f) << m.name;
        }
        const Vec3 wi = util::sample_uniform_sphere(u);
        ASSERT_TRUE(bsdf_eval(m, wo, wi).is_finite()) << m.name;
        ASSERT_TRUE(std::isfinite(bsdf_pdf(m, wo, wi))) << m.name;
      }
}

// ---- White furnace. ----


TEST(MetallicRoughness, WhiteFurnace) {
  // Base colour 1. A metal then reflects all that its microfacets' single scattering reflects:
  // ρ < 1 by the light that would scatter more than once between microfacets, which a
  // single-scattering model drops (Heitz et al. 2016, "Multiple-Scattering Microfacet BSDFs
  // with the Smith Model", show the loss growing with α). Measured here (green channel, 4e5
  // samples): r = 0.5 loses 8–17 %, r = 1 loses 43–69 % (69 % at normal incidence).
  //
  // The dielectric mix is the specification's too: its diffuse base is weighted by 1 − F(V·H),
  // not by what the specular layer actually took, so towards grazing views it returns more than
  // arrives: measured 1.19 at θo = 1.3 and 1.62 at θo = 1.5 for r = 0.1, 1.05 and 1.10 for
  // r = 0.5. That is the model's (glTF 2.0, appendix B.3.5), kept so that gilt renders glTF
  // assets as the specification defines them; at normal incidence it is within 0.4 % of one.
  // So the bound ρ ≤ 1 is asserted for metals at every angle and for the dielectric at normal
  // incidence; everywhere, two independent estimators must agree.
  constexpr int kN = 400000;
  std::printf("    [furnace] roughness metallic θo: directional albedo ± standard error\n");
  for (float roughness : {0.1f, 0.5f, 1.0f})
    for (float metallic : {0.0f, 1.0f})
      for (float theta : {0.0f, 0.8f, 1.3f, 1.5f}) {
        const Material m = Material::make_metallic_roughness("white", Rgb(1.0f), metallic, roughness);
        const Vec3 wo = spherical(theta, 0.4f);
        util::Rng rng(77);
        const test::MeanEstimate by_bsdf = test::estimate_mean(kN, [&] {
          const float u_lobe = rng.uniform();
          const auto s = bsdf_sample(m, wo, u_lobe, rng.uniform2());
          return s ? double(s->f.g) * std::fabs(s->wi.z) / s->pdf : 0.0;
        });
        std::printf("    [furnace] %.1f %.0f %.1f: %.4f ± %.4f\n", roughness, metallic, theta, by_bsdf.mean,
                    by_bsdf.standard_error);
        if (metallic == 1.0f || theta == 0.0f) {
          EXPECT_LE(by_bsdf.mean, 1.0 + kZ * by_bsdf.standard_error) << roughness << " " << metallic << " " << theta;
        }
        // For the rougher lobes, an independent estimate from uniform directions and bsdf_eval
        // alone (too noisy for the narrow r = 0.1 lobe, whose check is the chi-square above).
        if (roughness >= 0.5f) {
          const test::MeanEstimate by_uniform = test::estimate_mean(kN, [&] {
            Vec3 wi = util::sample_uniform_sphere(rng.uniform2());
            if (wi.z < 0.0f) wi.z = -wi.z;
            return double(bsdf_eval(m, wo, wi).g) * wi.z * 2.0 * std::numbers::pi;
          });
          EXPECT_NEAR(by_bsdf.mean, by_uniform.mean, kZ * std::hypot(by_bsdf.standard_error, by_uniform.standard_error))
              << roughness << " " << metallic << " " << theta;
        }
        // A smooth metal at normal incidence loses next to nothing: G2 → 1 as α → 0; at α = 0.01
        // the masking of a normal view is 1 − G1 < 1e-4, so the single-scattering albedo is 1
        // within that and the estimator's error.
        if (roughness == 0.1f && metallic == 1.0f && theta == 0.0f) {
          EXPECT_NEAR(by_bsdf.mean, 1.0, kZ * by_bsdf.standard_error + 2e-4);
        }
      }
}

// ---- Dielectric: tint and thin walls. ----

TEST(Dielectric, ThinWallPassesStraightThroughTinted) {
  Material m = Material::make_dielectric("sheet", 1.5f);
  m.thin_walled = true;
  m.transmission_tint = Rgb(0.1f, 0.5f, 0.9f);
  for (float theta : {0.0f, 0.7f, 1.4f}) {
    const Vec3 wo = spherical(theta, 1.1f);
    const float r = fresnel_dielectric(wo.z, 1.5f);
    const auto s = bsdf_sample(m, wo, r + 0.5f * (1.0f - r), {0.3f, 0.3f});  // the transmission branch
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->transmission && s->delta);
    EXPECT_NEAR(glm::length(s->wi + wo), 0.0f, 1e-6f);  // unbent
    for (int c = 0; c < 3; ++c)  // weight f |cos| / pdf is the tint: no 1/η² across a thin sheet
      EXPECT_NEAR(s->f[c] * std::fabs(s->wi.z) / s->pdf, m.transmission_tint[c], 1e-6f);
    const auto reflected = bsdf_sample(m, wo, 0.5f * r, {0.3f, 0.3f});
    ASSERT_TRUE(reflected);
    EXPECT_FALSE(reflected->transmission);
  }
}

TEST(Dielectric, ThinWallReflectsAlikeFromBothSides) {
  // From the back of a sheet of η = 1.5, 60° is past the critical angle of a solid's inside
  // (41.8°); a sheet has air on both sides, so it must still transmit 1 − F(60°).
  Material m = Material::make_dielectric("sheet", 1.5f);
  m.thin_walled = true;
  const Vec3 wo_back = spherical(kPi - 1.0472f, 0.4f);
  const float r = fresnel_dielectric(std::cos(1.0472f), 1.5f);
  ASSERT_LT(r, 0.2f);
  const auto s = bsdf_sample(m, wo_back, 0.5f * (1.0f + r), {0.3f, 0.3f});
  ASSERT_TRUE(s);
  EXPECT_TRUE(s->transmission);
  EXPECT_NEAR(s->pdf, 1.0f - r, 1e-6f);
}

TEST(Dielectric, TintScalesRefraction) {
  Material clear = Material::make_dielectric("clear", 1.5f), tinted = clear;
  tinted.transmission_tint = Rgb(0.2f, 0.6f, 1.0f);
  const Vec3 wo = spherical(0.5f, 0.2f);
  const auto a = bsdf_sample(clear, wo, 0.99f, {0.1f, 0.1f}), b = bsdf_sample(tinted, wo, 0.99f, {0.1f, 0.1f});
  ASSERT_TRUE(a && b);
  ASSERT_TRUE(a->transmission && b->transmission);
  EXPECT_EQ(a->wi, b->wi);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(b->f[c], a->f[c] * tinted.transmission_tint[c]);
}

TEST(MetallicRoughness, DiffuseReflectanceIsTheLambertianPart) {
  const Material m = Material::make_metallic_roughness("mr", Rgb(0.5f, 0.6f, 0.7f), 0.25f, 0.5f);
  const Rgb d = diffuse_reflectance(m);
  for (int c = 0; c < 3; ++c) EXPECT_FLOAT_EQ(d[c], m.albedo[c] * 0.75f * 0.96f);  // (1 − m)(1 − F0), F0 = 0.04
  EXPECT_EQ(diffuse_reflectance(Material::make_diffuse("d", Rgb(0.3f))), Rgb(0.3f));
  EXPECT_TRUE(diffuse_reflectance(Material::make_mirror("m")).is_black());
}

}  // namespace
}  // namespace gilt::raytrace_core::scene
