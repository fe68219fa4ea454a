#pragma once
// How far an image is from a reference: the error measures every benchmark, test and report of
// gilt uses, in one place so that they all mean the same thing.

#include <span>

#include "raytrace_core/rgb.h"

namespace gilt::raytrace_core {

/// Errors of an image against a reference of the same size, over pixels and channels.
struct ImageError {
  double rmse = 0.0;           ///< √mean (I − R)²
  double relmse = 0.0;         ///< mean (I − R)² / (R² + 0.01)
  double mae = 0.0;            ///< mean |I − R|
  double mean_relative = 0.0;  ///< mean |I − R| / (R + 0.01); ε keeps black pixels from dominating
  /// Σ I / Σ R over pixels and channels: a method's bias in overall brightness, which the
  /// measures above mix with its noise (1 when the reference is black).
  double mean_ratio = 1.0;
};

/// All the measures; throws std::invalid_argument when the sizes differ.
ImageError image_error(std::span<const Rgb> image, std::span<const Rgb> reference);

/// mean |I − R| / (R + 0.01) over pixels and channels.
inline double mean_relative_error(std::span<const Rgb> image, std::span<const Rgb> reference) {
  return image_error(image, reference).mean_relative;
}

}  // namespace gilt::raytrace_core
