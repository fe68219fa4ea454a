// Sun direction and Preetham's clear sky; see sun_sky.h.
//
// The sky's luminance Y and chromaticity (x, y) in a direction at zenith angle θ and angle γ
// from the sun follow Perez et al.'s five-parameter distribution,
//     F(θ, γ) = (1 + A e^(B / cos θ)) (1 + C e^(D γ) + E cos² γ),
// scaled to the zenith value: Y(θ, γ) = Y_z F(θ, γ) / F(0, θ_s), θ_s the sun's zenith angle.
// The coefficients A–E of Y, x and y are linear in the turbidity T, and the zenith values Y_z
// (kcd/m²), x_z and y_z are polynomials in T and θ_s: the paper's appendix A.2. (x, y, Y) are
// turned into XYZ and then linear Rec.709 RGB (D65).

#include "raytrace_core/scene/sun_sky.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "raytrace_core/util/error.h"

namespace gilt::raytrace_core::scene {
namespace {

struct Perez {
  double a, b, c, d, e;
  double operator()(double cos_theta, double gamma) const {
    const double cos_gamma = std::cos(gamma);
    return (1.0 + a * std::exp(b / cos_theta)) * (1.0 + c * std::exp(d * gamma) + e * cos_gamma * cos_gamma);
  }
};

}  // namespace

Vec3 sky_direction(float elevation_degrees, float azimuth_degrees) {
  const float e = elevation_degrees * (kPi / 180.0f), a = azimuth_degrees * (kPi / 180.0f);
  return {std::cos(e) * std::sin(a), std::sin(e), -std::cos(e) * std::cos(a)};
}

std::shared_ptr<const EnvironmentMap> preetham_sky(const Vec3& to_sun, float turbidity, int width) {
  if (!(turbidity >= 1.7f && turbidity <= 10.0f))
    throw InputError("sky: turbidity " + std::to_string(turbidity) + " is outside the model's range [1.7, 10]");
  const double t = turbidity;
  const Perez luminance{0.1787 * t - 1.4630, -0.3554 * t + 0.4275, -0.0227 * t + 5.3251, 0.1206 * t - 2.5771,
                        -0.0670 * t + 0.3703};
  const Perez chroma_x{-0.0193 * t - 0.2592, -0.0665 * t + 0.0008, -0.0004 * t + 0.2125, -0.0641 * t - 0.8989,
                       -0.0033 * t + 0.0452};
  const Perez chroma_y{-0.0167 * t - 0.2608, -0.0950 * t + 0.0092, -0.0079 * t + 0.2102, -0.0441 * t - 1.6537,
                       -0.0109 * t + 0.0529};
  const Vec3 sun = glm::normalize(to_sun);
  // The model is fitted for a sun above the horizon; one below it lights a sky of its twilight
  // value at the horizon, which Y_z (→ 0 as the sun sets) keeps dim.
  const double theta_s = std::min(double(std::acos(std::clamp(sun.y, -1.0f, 1.0f))), 0.5 * std::numbers::pi);
  const double chi = (4.0 / 9.0 - t / 120.0) * (std::numbers::pi - 2.0 * theta_s);
  const double zenith_y = std::max(0.0, (4.0453 * t - 4.9710) * std::tan(chi) - 0.2155 * t + 2.4192);  // kcd/m²
  const double s1 = theta_s, s2 = s1 * s1, s3 = s2 * s1;
  const double zenith_x = t * t * (0.00166 * s3 - 0.00375 * s2 + 0.00209 * s1) +
                          t * (-0.02903 * s3 + 0.06377 * s2 - 0.03202 * s1 + 0.00394) +
                          (0.11693 * s3 - 0.21196 * s2 + 0.06052 * s1 + 0.25886);
  const double zenith_yc = t * t * (0.00275 * s3 - 0.00610 * s2 + 0.00317 * s1) +
                           t * (-0.04214 * s3 + 0.08970 * s2 - 0.04153 * s1 + 0.00516) +
                           (0.15346 * s3 - 0.26756 * s2 + 0.06670 * s1 + 0.26688);
  // Radiance in the units of sun_sky.h: luminance (cd/m²) over 100 klx, i.e. kcd/m² / 100.
  constexpr double kUnit = 1000.0 / 100000.0;

  const int height = std::max(1, width / 2);
  std::vector<Rgb> texels(size_t(width) * size_t(height), Rgb(0.0f));
  for (int row = 0; row < height; ++row) {
    const double theta = std::numbers::pi * (row + 0.5) / height;
    if (theta >= 0.5 * std::numbers::pi) break;  // below the horizon: black
    const double cos_theta = std::max(std::cos(theta), 1e-3);
    for (int col = 0; col < width; ++col) {
      const double phi = 2.0 * std::numbers::pi * ((col + 0.5) / width - 0.5);
      const Vec3 w(float(std::sin(theta) * std::sin(phi)), float(std::cos(theta)), float(-std::sin(theta) * std::cos(phi)));
      const double gamma = std::acos(std::clamp(double(glm::dot(w, sun)), -1.0, 1.0));
      const double big_y = zenith_y * luminance(cos_theta, gamma) / luminance(1.0, theta_s) * kUnit;
      const double x = zenith_x * chroma_x(cos_theta, gamma) / chroma_x(1.0, theta_s);
      const double y = zenith_yc * chroma_y(cos_theta, gamma) / chroma_y(1.0, theta_s);
      if (!(y > 0.0) || !(big_y > 0.0)) continue;
      const double big_x = x * big_y / y, big_z = (1.0 - x - y) * big_y / y;
      const Rgb rgb(float(3.2406 * big_x - 1.5372 * big_y - 0.4986 * big_z),
                    float(-0.9689 * big_x + 1.8758 * big_y + 0.0415 * big_z),
                    float(0.0557 * big_x - 0.2040 * big_y + 1.0570 * big_z));
      texels[size_t(row) * size_t(width) + size_t(col)] = clamp(rgb, 0.0f, kInfinity);
    }
  }
  return std::make_shared<const EnvironmentMap>(width, height, std::move(texels));
}

}  // namespace gilt::raytrace_core::scene
