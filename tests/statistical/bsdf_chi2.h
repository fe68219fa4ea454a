#pragma once
// The chi-square test of a BSDF's sampling routine, shared by the BSDF test programs: directions
// drawn by bsdf_sample (both random numbers uniform) against bsdf_pdf, on a θ × φ grid of the
// whole sphere (see chi2.h; samples that bsdf_sample declines count in the remainder cell).
// `adaptive_depth` > 0 refines the expected counts' integration where the density jumps inside
// a cell.

#include <optional>

#include "raytrace_core/scene/bsdf.h"
#include "tests/statistical/chi2.h"

namespace gilt::test {

inline Chi2Result chi2_bsdf(const raytrace_core::scene::Material& material, const raytrace_core::Vec3& wo, size_t samples,
                            uint64_t seed, double alpha, int theta_rows = 48, int phi_columns = 96,
                            int adaptive_depth = 0) {
  using raytrace_core::util::Rng;
  using raytrace_core::scene::bsdf_pdf;
  using raytrace_core::scene::bsdf_sample;
  using raytrace_core::Vec3;
  return chi2_directions(
      theta_grid(theta_rows, phi_columns), samples, seed,
      [&](Rng& rng) -> std::optional<Vec3> {
        const float u_lobe = rng.uniform();
        const auto s = bsdf_sample(material, wo, u_lobe, rng.uniform2());
        if (!s) return std::nullopt;
        return s->wi;
      },
      [&](Vec3 wi) { return bsdf_pdf(material, wo, wi); }, alpha, 3, adaptive_depth);
}

}  // namespace gilt::test
