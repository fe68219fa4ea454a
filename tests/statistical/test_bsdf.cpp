// Statistical and exact tests of raytrace_core/scene/bsdf.h.
//
// Non-delta lobes (diffuse, glossy): the directions bsdf_sample draws must follow bsdf_pdf
// (chi-square, see chi2.h; α = 0.01 Šidák-corrected over the kChi2Tests tests of this program),
// and every sample must report f and pdf equal to bsdf_eval and bsdf_pdf at its direction.
// Delta lobes (mirror, dielectric): exact geometry (reflection law, Snell's law), the Fresnel
// equations against an independent textbook form, the reflect/refract split frequency, energy
// conservation and total internal reflection. Glossy: white-furnace bound on directional albedo.
//
// Monte Carlo checks use z = 4 standard errors: a two-sided false failure rate of 6.3e-5 per
// check (one-sided 3.2e-5), below 1e-3 for the few dozen such checks here.

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "raytrace_core/scene/bsdf.h"
#include "raytrace_core/util/rng.h"
#include "raytrace_core/util/sampling.h"
#include "tests/statistical/bsdf_chi2.h"
#include "tests/statistical/bsdf_test_kit.h"
#include "tests/statistical/chi2.h"

namespace gilt::raytrace_core::scene {
namespace {

constexpr int kChi2Tests = 17;  // 4 diffuse + 12 glossy (3 exponents × 4 wo) + 1 pure Phong
constexpr size_t kChi2Samples = 1000000;
constexpr double kZ = 4.0;
const double kAlpha = test::sidak_alpha(test::kFamilyAlpha, kChi2Tests);

using test::LobeCase;
using test::spherical;

// Outgoing directions: normal, 45°, grazing (cos θ = 0.02) and below the surface (θ = 120°).
// The azimuth 0.7 keeps lobes off the grid's cell boundaries in φ.
const Vec3 kWoNormal{0.0f, 0.0f, 1.0f};
const std::vector<std::pair<std::string, Vec3>> kWos{{"normal", kWoNormal},
                                                     {"oblique45", spherical(0.25f * kPi, 0.7f)},
                                                     {"grazing", spherical(std::acos(0.02f), 0.7f)},
                                                     {"below120", spherical(2.0f * kPi / 3.0f, 0.7f)}};

// ---- Non-delta lobes: sampled density against bsdf_pdf, and sample consistency. ----

std::vector<LobeCase> lobe_cases() {
  std::vector<LobeCase> cases;
  for (const auto& [wo_name, wo] : kWos)
    cases.push_back({"diffuse_" + wo_name, Material::make_diffuse("d", Rgb(0.7f, 0.5f, 0.3f)), wo});
  for (float n : {1.0f, 10.0f, 100.0f})
    for (const auto& [wo_name, wo] : kWos)
      cases.push_back({"glossy_n" + std::to_string(static_cast<int>(n)) + "_" + wo_name,
                       Material::make_glossy("g", Rgb(0.3f, 0.2f, 0.1f), Rgb(0.4f, 0.6f, 0.8f), n), wo});
  cases.push_back({"phong_only_n10_oblique60", Material::make_glossy("p", Rgb(0.0f), Rgb(0.9f), 10.0f),
                   spherical(kPi / 3.0f, 0.7f)});
  return cases;
}

class LobeTest : public testing::TestWithParam<LobeCase> {};

TEST_P(LobeTest, SampledDirectionsFollowPdf) {
  const LobeCase& c = GetParam();
  // θ rows resolve the n = 100 lobe (angular width ~0.1 rad) at normal incidence; 48 × 96 cells.
  test::expect_chi2_pass(
      test::chi2_bsdf(c.material, c.wo, kChi2Samples, 0xb5df + std::hash<std::string>{}(c.name) % 1000, kAlpha));
}

TEST_P(LobeTest, SampleMatchesEvalAndPdf) {
  // The sample's f and pdf are the same float expressions as bsdf_eval and bsdf_pdf at its wi, so
  // they agree to rounding (relative 1e-6 allows a few operations of 2^-24 each).
  const LobeCase& c = GetParam();
  util::Rng rng(42);
  for (int k = 0; k < 20000; ++k) {
    const float u_lobe = rng.uniform();
    const auto s = bsdf_sample(c.material, c.wo, u_lobe, rng.uniform2());
    if (!s) continue;
    ASSERT_FALSE(s->delta);
    ASSERT_FALSE(s->transmission);
    ASSERT_GT(s->wi.z * c.wo.z, 0.0f) << "sample on the other side of the surface";
    ASSERT_NEAR(glm::length(s->wi), 1.0f, 1e-5f);
    const Rgb f = bsdf_eval(c.material, c.wo, s->wi);
    const float pdf = bsdf_pdf(c.material, c.wo, s->wi);
    ASSERT_GT(s->pdf, 0.0f);
    ASSERT_NEAR(s->pdf, pdf, 1e-6f * pdf);
    for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(s->f[ch], f[ch], 1e-6f * f[ch]);
    if (c.material.kind == MaterialKind::diffuse) {  // f·cos/pdf is exactly the albedo
      for (int ch = 0; ch < 3; ++ch)
        ASSERT_NEAR(s->f[ch] * std::fabs(s->wi.z) / s->pdf, c.material.albedo[ch], 1e-5f);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Bsdf, LobeTest, testing::ValuesIn(lobe_cases()),
                         [](const testing::TestParamInfo<LobeCase>& info) { return info.param.name; });

TEST(Bsdf, ReflectiveLobesVanishAcrossTheSurface) {
  const Material d = Material::make_diffuse("d", Rgb(0.5f));
  const Material g = Material::make_glossy("g", Rgb(0.2f), Rgb(0.7f), 20.0f);
  const Vec3 wo = spherical(0.3f, 0.1f), wi = spherical(2.5f, 2.0f);
  for (const Material* m : {&d, &g}) {
    EXPECT_TRUE(bsdf_eval(*m, wo, wi).is_black());
    EXPECT_EQ(bsdf_pdf(*m, wo, wi), 0.0f);
    // Both sides reflect alike: mirroring z of both directions changes nothing.
    const Vec3 a = spherical(0.4f, 0.2f), b = spherical(0.9f, 3.0f);
    EXPECT_EQ(bsdf_eval(*m, a, b), bsdf_eval(*m, Vec3(a.x, a.y, -a.z), Vec3(b.x, b.y, -b.z)));
    EXPECT_EQ(bsdf_pdf(*m, a, b), bsdf_pdf(*m, Vec3(a.x, a.y, -a.z), Vec3(b.x, b.y, -b.z)));
  }
}

TEST(Bsdf, GlossyIsTheDocumentedPhongMixture) {
  // Closed forms in double: f = albedo/π + specular·(n+2)/2π·cos^n α, and the lobe choice
  // probability ps = avg(specular) / (avg(albedo) + avg(specular)) = 0.6 / 0.8 here, so
  // pdf = ps·(n+1)/2π·cos^n α + (1 − ps)·cos θi/π. Relative 1e-5: float evaluation of cos^n α
  // carries n·2^-24 ≤ 6e-6 relative error for n = 100.
  const double n = 100.0, ps = 0.75;
  const Material m = Material::make_glossy("g", Rgb(0.3f, 0.2f, 0.1f), Rgb(0.4f, 0.6f, 0.8f), 100.0f);
  const Vec3 wo = spherical(0.6f, 1.0f);
  for (float dtheta : {0.0f, 0.02f, 0.1f, 0.3f}) {
    const Vec3 wi = spherical(0.6f + dtheta, 1.0f + kPi + 0.5f * dtheta);
    const double cos_alpha = glm::dot(wi, Vec3(-wo.x, -wo.y, wo.z));
    const double lobe = std::pow(std::max(0.0, cos_alpha), n) / (2.0 * std::numbers::pi);
    const double pdf = ps * (n + 1.0) * lobe + (1.0 - ps) * wi.z / std::numbers::pi;
    EXPECT_NEAR(bsdf_pdf(m, wo, wi), pdf, 1e-5 * pdf);
    for (int c = 0; c < 3; ++c) {
      const double f = m.albedo[c] / std::numbers::pi + m.specular[c] * (n + 2.0) * lobe;
      EXPECT_NEAR(bsdf_eval(m, wo, wi)[c], f, 1e-5 * f);
    }
  }
}

TEST(Bsdf, DegenerateInputsGiveFiniteResults) {
  const float nan = std::nanf("");
  std::vector<Material> materials{Material::make_diffuse("d", Rgb(0.5f)),
                                  Material::make_glossy("g0", Rgb(0.2f), Rgb(0.7f), 0.0f),
                                  Material::make_glossy("g", Rgb(0.0f), Rgb(1.0f), 1e9f),
                                  Material::make_glossy("ginf", Rgb(0.1f), Rgb(0.5f), kInfinity),
                                  Material::make_glossy("gnan", Rgb(0.1f), Rgb(0.5f), nan),
                                  Material::make_glossy("black", Rgb(0.0f), Rgb(0.0f), 5.0f),
                                  Material::make_mirror("m"),
                                  Material::make_dielectric("g15", 1.5f),
                                  Material::make_dielectric("g1", 1.0f),
                                  Material::make_dielectric("bad", 0.0f)};
  const std::vector<Vec3> wos{
      {0, 0, 1}, {0, 0, -1}, {1, 0, 0}, spherical(1.5707f, 0.3f), spherical(1.5709f, 0.3f)};
  util::Rng rng(9);
  for (const Material& m : materials)
    for (const Vec3& wo : wos)
      for (int k = 0; k < 200; ++k) {
        const float u_lobe = k == 0 ? 0.0f : (k == 1 ? kOneMinusEpsilon : rng.uniform());
        const Vec2 u = k == 0 ? Vec2(0.0f) : (k == 1 ? Vec2(kOneMinusEpsilon) : rng.uniform2());
        const auto s = bsdf_sample(m, wo, u_lobe, u);
        if (s) {
          ASSERT_TRUE(s->f.is_finite() && is_finite(s->wi) && std::isfinite(s->pdf)) << m.name;
          ASSERT_GT(s->pdf, 0.0f) << m.name;
        }
        const Vec3 wi = util::sample_uniform_sphere(u);
        ASSERT_TRUE(bsdf_eval(m, wo, wi).is_finite()) << m.name;
        ASSERT_TRUE(std::isfinite(bsdf_pdf(m, wo, wi))) << m.name;
      }
}

// ---- Glossy energy: white furnace. ----

struct AlbedoEstimate {
  Rgb mean, standard_error;
};

// Directional albedo ρ(wo) = ∫ f cos θi dωi, estimated with n samples of `draw`, which returns
// the weight f·|cos|/pdf of one sample (zero when none). Mean and standard error per channel.
template <class Draw>
AlbedoEstimate estimate_albedo(int n, const Draw& draw) {
  double sum[3] = {0, 0, 0}, sum_sq[3] = {0, 0, 0};
  for (int k = 0; k < n; ++k) {
    const Rgb w = draw();
    for (int c = 0; c < 3; ++c) sum[c] += w[c], sum_sq[c] += static_cast<double>(w[c]) * w[c];
  }
  AlbedoEstimate e;
  for (int c = 0; c < 3; ++c) {
    const double mean = sum[c] / n;
    const double variance = std::max(0.0, (sum_sq[c] / n - mean * mean) * n / (n - 1));
    e.mean[c] = static_cast<float>(mean);
    e.standard_error[c] = static_cast<float>(std::sqrt(variance / n));
  }
  return e;
}

class GlossyFurnace : public testing::TestWithParam<float> {};

TEST_P(GlossyFurnace, DirectionalAlbedoIsBoundedAndMatchesUniformSampling) {
  // albedo + specular = 1 in every channel, with different splits per channel.
  const Material m = Material::make_glossy("g", Rgb(0.5f, 0.2f, 0.0f), Rgb(0.5f, 0.8f, 1.0f), GetParam());
  constexpr int kN = 200000;
  for (float theta : {0.0f, 0.5f, 1.0f, 1.3f, 1.55f, 2.2f}) {
    const Vec3 wo = spherical(theta, 0.7f);
    util::Rng rng(1234);
    const AlbedoEstimate by_bsdf = estimate_albedo(kN, [&] {
      const float u_lobe = rng.uniform();
      const auto s = bsdf_sample(m, wo, u_lobe, rng.uniform2());
      return s ? s->f * (std::fabs(s->wi.z) / s->pdf) : Rgb(0.0f);
    });
    // Brute-force twin: uniform directions on wo's hemisphere, pdf 1/2π, using bsdf_eval only.
    const AlbedoEstimate by_uniform = estimate_albedo(kN, [&] {
      Vec3 wi = util::sample_uniform_sphere(rng.uniform2());
      if (wi.z * wo.z < 0.0f) wi.z = -wi.z;
      return bsdf_eval(m, wo, wi) * (std::fabs(wi.z) * 2.0f * kPi);
    });
    for (int c = 0; c < 3; ++c) {
      const float se = by_bsdf.standard_error[c];
      // Energy conservation, one-sided: ρ ≤ albedo + specular = 1.
      EXPECT_LE(by_bsdf.mean[c], 1.0f + kZ * se) << "theta " << theta << " channel " << c;
      // Two estimators of the same integral agree within kZ combined standard errors.
      const float se_diff = std::hypot(se, by_uniform.standard_error[c]);
      EXPECT_NEAR(by_bsdf.mean[c], by_uniform.mean[c], kZ * se_diff) << "theta " << theta << " channel " << c;
      // Closed form at normal incidence: ∫ (n+2)/2π cos^(n+1) θ dω = 1 and ∫ cos θ/π dω = 1, so ρ = 1.
      if (theta == 0.0f) {  // 1e-5: float rounding of the weights, far below se
        EXPECT_NEAR(by_bsdf.mean[c], 1.0f, kZ * se + 1e-5f) << "channel " << c;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Bsdf, GlossyFurnace, testing::Values(0.0f, 1.0f, 10.0f, 100.0f, 1000.0f));

// ---- Delta lobes. ----

TEST(Mirror, ReflectsAboutTheNormalOnBothSides) {
  const Material m = Material::make_mirror("m", Rgb(0.9f, 0.5f, 0.2f));
  for (float theta : {0.0f, 0.6f, 1.4f, 1.57f, 1.8f, 3.0f}) {
    const Vec3 wo = spherical(theta, 2.1f);
    const auto s = bsdf_sample(m, wo, 0.37f, {0.2f, 0.8f});
    ASSERT_TRUE(s);
    EXPECT_TRUE(s->delta);
    EXPECT_FALSE(s->transmission);
    EXPECT_EQ(s->pdf, 1.0f);
    EXPECT_EQ(s->wi, Vec3(-wo.x, -wo.y, wo.z));
    // Throughput f·|cos θi|/pdf is the reflectance (relative 1e-6: one division and one product).
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(s->f[c] * std::fabs(s->wi.z), m.specular[c], 1e-6f);
    EXPECT_TRUE(bsdf_eval(m, wo, s->wi).is_black());
    EXPECT_EQ(bsdf_pdf(m, wo, s->wi), 0.0f);
  }
  EXPECT_FALSE(bsdf_sample(m, {1.0f, 0.0f, 0.0f}, 0.5f, {0.5f, 0.5f}));  // grazing: no finite f
}

// Textbook Fresnel reflectance in double from the angles (Born & Wolf): independent of the
// cos-based form in bsdf.cpp. n_i, n_t: refractive indices of the incident and the other side.
double fresnel_reference(double theta_i, double n_i, double n_t) {
  const double sin_t = n_i / n_t * std::sin(theta_i);
  if (sin_t >= 1.0) return 1.0;
  const double theta_t = std::asin(sin_t);
  const double s = std::sin(theta_i - theta_t) / std::sin(theta_i + theta_t);
  const double t = std::tan(theta_i - theta_t) / std::tan(theta_i + theta_t);
  return 0.5 * (s * s + t * t);
}

TEST(Fresnel, MatchesTheTextbookFormulaFromBothSides) {
  // Float evaluation: inputs and a dozen operations each carry relative error ≤ 2^-24; away from
  // the critical angle (cos θt ≥ 0.1 below) |dF/dcos| is at most ~10, so the error is ≲ 1e-6.
  // The tolerance 1e-5 leaves a factor 10 of margin.
  for (float eta : {1.33f, 1.5f, 2.4f})
    for (int k = 1; k < 90; ++k) {
      const double theta = k * std::numbers::pi / 180.0;
      const double out = fresnel_reference(theta, 1.0, eta);
      EXPECT_NEAR(fresnel_dielectric(static_cast<float>(std::cos(theta)), eta), out, 1e-5) << k;
      const double sin_t = std::sin(theta) * eta;
      if (sin_t < std::sqrt(0.99)) {  // inside, cos θt ≥ 0.1
        EXPECT_NEAR(fresnel_dielectric(-static_cast<float>(std::cos(theta)), eta),
                    fresnel_reference(theta, eta, 1.0), 1e-5)
            << k;
      }
    }
  // Normal incidence: ((η − 1)/(η + 1))² from either side; index-matched interface: 0.
  EXPECT_NEAR(fresnel_dielectric(1.0f, 1.5f), 0.04f, 1e-7f);
  EXPECT_NEAR(fresnel_dielectric(-1.0f, 1.5f), 0.04f, 1e-7f);
  // Index-matched: cos θt equals cos θi up to a rounding of 2^-23, and F is its square: ≲ 1e-13.
  EXPECT_NEAR(fresnel_dielectric(0.3f, 1.0f), 0.0f, 1e-12f);
  // Grazing from outside reflects everything; beyond the critical angle from inside likewise.
  EXPECT_NEAR(fresnel_dielectric(0.0f, 1.5f), 1.0f, 1e-6f);
  EXPECT_EQ(fresnel_dielectric(-0.5f, 1.5f), 1.0f);  // sin θ = 0.866 > 1/1.5
}

TEST(Fresnel, ReflectanceIsTheSameSeenFromEitherSide) {
  // Stokes relations: F(θi, outside) = F(θt, inside) for the refracted angle θt (tolerance as above).
  const float eta = 1.5f;
  for (float cos_i : {0.05f, 0.2f, 0.5f, 0.8f, 0.99f}) {
    const float cos_t = std::sqrt(1.0f - (1.0f - cos_i * cos_i) / (eta * eta));
    EXPECT_NEAR(fresnel_dielectric(cos_i, eta), fresnel_dielectric(-cos_t, eta), 1e-5f);
  }
}

TEST(Dielectric, RefractionObeysSnellsLaw) {
  const float eta = 1.5f;
  const Material glass = Material::make_dielectric("glass", eta);
  for (float theta : {0.0f, 0.3f, 0.9f, 1.4f, 1.56f, 2.6f, 2.9f, 3.1f}) {  // ≥ 2.6: inside, below critical
    const Vec3 wo = spherical(theta, 1.1f);
    const auto s = bsdf_sample(glass, wo, kOneMinusEpsilon, {0.5f, 0.5f});  // u_lobe ≥ F: refract
    ASSERT_TRUE(s) << theta;
    EXPECT_TRUE(s->delta && s->transmission);
    EXPECT_LT(s->wi.z * wo.z, 0.0f);
    EXPECT_NEAR(glm::length(s->wi), 1.0f, 1e-6f);
    // Tangential components antiparallel (in the plane of incidence), sines in ratio 1/η.
    const float n_o = wo.z > 0.0f ? 1.0f : eta, n_i = wo.z > 0.0f ? eta : 1.0f;
    EXPECT_NEAR(wo.x * s->wi.y - wo.y * s->wi.x, 0.0f, 1e-6f);
    EXPECT_LE(wo.x * s->wi.x + wo.y * s->wi.y, 0.0f);
    const float sin_o = std::hypot(wo.x, wo.y), sin_i = std::hypot(s->wi.x, s->wi.y);
    EXPECT_NEAR(n_o * sin_o, n_i * sin_i, 1e-6f);  // both ≤ 1.5 with float rounding 2^-24 each
    // Throughput: T in importance mode; radiance additionally scaled by (n_o / n_i)².
    const float transmittance = 1.0f - fresnel_dielectric(wo.z, eta);
    EXPECT_NEAR(s->pdf, transmittance, 1e-6f);
    const auto imp = bsdf_sample(glass, wo, kOneMinusEpsilon, {0.5f, 0.5f}, TransportMode::importance);
    ASSERT_TRUE(imp);
    EXPECT_NEAR(imp->f.r * std::fabs(imp->wi.z), transmittance, 1e-6f);
    EXPECT_NEAR(s->f.r * std::fabs(s->wi.z), transmittance * sqr(n_o / n_i), 1e-6f);
  }
  // Index-matched: straight through.
  const auto s =
      bsdf_sample(Material::make_dielectric("water-in-water", 1.0f), spherical(0.7f, 0.3f), 0.0f, {});
  ASSERT_TRUE(s);
  EXPECT_NEAR(glm::length(s->wi + spherical(0.7f, 0.3f)), 0.0f, 1e-6f);
}

TEST(Dielectric, ReflectionBranchAndEnergyBalance) {
  // Importance mode: reflectance R = f_r|cos|, transmittance T = f_t|cos|, R + T = 1 exactly up to
  // rounding (1e-6: a handful of float operations on values ≤ 1); every sample's weight is 1.
  const Material glass = Material::make_dielectric("glass", 1.5f);
  util::Rng rng(77);
  for (float theta : {0.0f, 0.5f, 1.2f, 1.5f, 2.0f, 2.5f, 2.9f}) {
    const Vec3 wo = spherical(theta, 0.4f);
    const auto r = bsdf_sample(glass, wo, 0.0f, {}, TransportMode::importance);
    const auto t = bsdf_sample(glass, wo, kOneMinusEpsilon, {}, TransportMode::importance);
    ASSERT_TRUE(r && t) << theta;
    const float reflectance = r->transmission ? 0.0f : r->f.r * std::fabs(r->wi.z);
    const float transmittance = t->transmission ? t->f.r * std::fabs(t->wi.z) : 0.0f;
    EXPECT_EQ(r->wi, Vec3(-wo.x, -wo.y, wo.z)) << theta;
    EXPECT_NEAR(reflectance + transmittance, 1.0f, 1e-6f) << theta;
    for (int k = 0; k < 1000; ++k) {
      const auto s = bsdf_sample(glass, wo, rng.uniform(), rng.uniform2(), TransportMode::importance);
      ASSERT_TRUE(s);
      ASSERT_NEAR(s->f.g * std::fabs(s->wi.z) / s->pdf, 1.0f, 1e-6f);
    }
  }
}

TEST(Dielectric, SplitFrequencyIsFresnel) {
  // The fraction of reflected samples is Binomial(N, F)/N: standard deviation sqrt(F(1−F)/N).
  // N = 1e5 and F ≥ 0.04 give N·F ≥ 4000, so the normal approximation holds; tolerance kZ = 4 σ.
  const float eta = 1.5f;
  const Material glass = Material::make_dielectric("glass", eta);
  constexpr int kN = 100000;
  for (float theta : {0.0f, 0.8f, 1.4f, 2.7f}) {
    const Vec3 wo = spherical(theta, 0.2f);
    const double reflectance = fresnel_dielectric(wo.z, eta);
    util::Rng rng(31337);
    int reflected = 0;
    for (int k = 0; k < kN; ++k) {
      const float u_lobe = rng.uniform();
      const auto s = bsdf_sample(glass, wo, u_lobe, rng.uniform2());
      ASSERT_TRUE(s);
      reflected += s->transmission ? 0 : 1;
      ASSERT_NEAR(s->pdf, s->transmission ? 1.0 - reflectance : reflectance, 1e-6);
    }
    const double sigma = std::sqrt(reflectance * (1.0 - reflectance) / kN);
    EXPECT_NEAR(static_cast<double>(reflected) / kN, reflectance, kZ * sigma) << "theta " << theta;
  }
}

TEST(Dielectric, TotalInternalReflectionBeyondTheCriticalAngle) {
  const float eta = 1.5f;
  const Material glass = Material::make_dielectric("glass", eta);
  const float critical = std::asin(1.0f / eta);  // measured from the inward normal −z
  for (float past : {1e-3f, 0.1f, 0.5f, 0.8f}) {
    const Vec3 wo = spherical(kPi - (critical + past), 0.9f);  // inside, z < 0
    EXPECT_EQ(fresnel_dielectric(wo.z, eta), 1.0f);
    for (float u_lobe : {0.0f, 0.5f, kOneMinusEpsilon}) {
      const auto s = bsdf_sample(glass, wo, u_lobe, {0.3f, 0.3f});
      ASSERT_TRUE(s);
      EXPECT_FALSE(s->transmission);
      EXPECT_EQ(s->pdf, 1.0f);
      EXPECT_EQ(s->wi, Vec3(-wo.x, -wo.y, wo.z));
      EXPECT_NEAR(s->f.r * std::fabs(s->wi.z), 1.0f, 1e-6f);
    }
  }
  EXPECT_TRUE(bsdf_eval(glass, kWoNormal, kWoNormal).is_black());
  EXPECT_EQ(bsdf_pdf(glass, kWoNormal, kWoNormal), 0.0f);
}

}  // namespace
}  // namespace gilt::raytrace_core::scene
