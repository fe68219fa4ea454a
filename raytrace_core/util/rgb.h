#pragma once
// Linear RGB colour, kept distinct from the vector type so radiance never mixes with directions.

#include <algorithm>
#include <cmath>

namespace gilt::raytrace_core::util {

/// Linear Rec.709 RGB triple: radiance (W·sr⁻¹·m⁻²), reflectance, power (W) or any other
/// spectral quantity. Never a position or direction.
struct Rgb {
  float r = 0.0f, g = 0.0f, b = 0.0f;

  constexpr Rgb() = default;
  constexpr explicit Rgb(float v) : r(v), g(v), b(v) {}
  constexpr Rgb(float red, float green, float blue) : r(red), g(green), b(blue) {}

  constexpr float operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  constexpr float& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }

  constexpr Rgb& operator+=(const Rgb& o) { r += o.r; g += o.g; b += o.b; return *this; }
  constexpr Rgb& operator-=(const Rgb& o) { r -= o.r; g -= o.g; b -= o.b; return *this; }
  constexpr Rgb& operator*=(const Rgb& o) { r *= o.r; g *= o.g; b *= o.b; return *this; }
  constexpr Rgb& operator*=(float s) { r *= s; g *= s; b *= s; return *this; }
  constexpr Rgb& operator/=(float s) { return *this *= 1.0f / s; }

  /// True when every channel is exactly zero.
  constexpr bool is_black() const { return r == 0.0f && g == 0.0f && b == 0.0f; }
  /// True when no channel is NaN or infinite.
  bool is_finite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
  /// Largest channel.
  constexpr float max_component() const { return std::max(r, std::max(g, b)); }
  constexpr float min_component() const { return std::min(r, std::min(g, b)); }
  /// Mean of the three channels: the scalar used for power and Russian roulette.
  constexpr float average() const { return (r + g + b) * (1.0f / 3.0f); }
  /// Rec.709 luminance Y.
  constexpr float luminance() const { return 0.2126f * r + 0.7152f * g + 0.0722f * b; }
};

constexpr Rgb operator+(Rgb a, const Rgb& b) { return a += b; }
constexpr Rgb operator-(Rgb a, const Rgb& b) { return a -= b; }
constexpr Rgb operator*(Rgb a, const Rgb& b) { return a *= b; }
constexpr Rgb operator*(Rgb a, float s) { return a *= s; }
constexpr Rgb operator*(float s, Rgb a) { return a *= s; }
constexpr Rgb operator/(Rgb a, float s) { return a /= s; }
constexpr Rgb operator/(const Rgb& a, const Rgb& b) { return {a.r / b.r, a.g / b.g, a.b / b.b}; }
constexpr bool operator==(const Rgb& a, const Rgb& b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

/// Channel-wise e^x (Beer–Lambert transmittance from an optical depth).
inline Rgb exp(const Rgb& c) { return {std::exp(c.r), std::exp(c.g), std::exp(c.b)}; }
/// Channel-wise clamp to [lo, hi].
inline Rgb clamp(const Rgb& c, float lo, float hi) {
  return {std::clamp(c.r, lo, hi), std::clamp(c.g, lo, hi), std::clamp(c.b, lo, hi)};
}

}  // namespace gilt::raytrace_core::util

// The parent namespace re-exports these names (rc::Vec3, rc::Rgb, rc::InputError ...).
#include "raytrace_core/util/vocabulary.h"
