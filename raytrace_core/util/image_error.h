#pragma once
// How far an image is from a reference: the error measures every benchmark, test and report of
// gilt uses, in one place so that they all mean the same thing.

#include <span>
#include <vector>

#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core::util {

/// Errors of an image against a reference of the same size, over pixels and channels.
///
/// A reference rendered by a Monte Carlo method carries noise of its own, and an image's squared
/// error against it is, in expectation, the image's own squared error plus the reference's
/// variance (the two are independent). Given that variance per pixel (reference_variance), the
/// squared measures have it subtracted, so that they estimate the error against the exact image:
/// a method whose error is below the reference's noise is then still told apart from one above
/// it. Without it, they are the error against the reference as it is.
struct ImageError {
  double rmse = 0.0;           ///< √mean (I − R)², less the reference's variance when known (≥ 0)
  double relmse = 0.0;         ///< mean (I − R)² / (R² + 0.01), less the same share of its variance
  double mae = 0.0;            ///< mean |I − R|
  double mean_relative = 0.0;  ///< mean |I − R| / (R + 0.01); ε keeps black pixels from dominating
  /// Σ I / Σ R over pixels and channels: a method's bias in overall brightness, which the
  /// measures above mix with its noise (1 when the reference is black).
  double mean_ratio = 1.0;
  /// The measures against the reference as it is, its noise included (equal to rmse and relmse
  /// when no variance is given).
  double rmse_measured = 0.0, relmse_measured = 0.0;
  /// The reference's own noise floor: mean variance, and mean variance / (R² + 0.01). A perfect
  /// image would measure these. 0 when unknown.
  double mse_floor = 0.0, relmse_floor = 0.0;
  /// Standard error of relmse, from the spread of its per-pixel terms: the corrected relmse of
  /// an image at the floor may come out below 0 by about this much.
  double relmse_stderr = 0.0;
  bool noise_corrected = false;  ///< whether a variance was given
};

/// All the measures against the reference as it is; throws std::invalid_argument when the sizes
/// differ.
ImageError image_error(std::span<const Rgb> image, std::span<const Rgb> reference);

/// All the measures, the squared ones less the reference's variance per pixel and channel
/// (`reference_variance`, the size of the images; empty: unknown, as above).
ImageError image_error(std::span<const Rgb> image, std::span<const Rgb> reference,
                       std::span<const Rgb> reference_variance);

/// Per pixel and channel, an unbiased estimate of the variance of the reference
/// w·A + (1 − w)·B made of two independent renders A and B of the same scene, whose sample counts
/// are in the ratio w : (1 − w): (A − B)²·w·(1 − w). (Each render's variance is s²/n for its n
/// samples, so E[(A − B)²] = s²(1/n_A + 1/n_B), and the mix's variance s²/(n_A + n_B) is that
/// times n_A·n_B/(n_A + n_B)² = w(1 − w).)
std::vector<Rgb> reference_variance(std::span<const Rgb> a, std::span<const Rgb> b, double w);

/// mean |I − R| / (R + 0.01) over pixels and channels.
inline double mean_relative_error(std::span<const Rgb> image, std::span<const Rgb> reference) {
  return image_error(image, reference).mean_relative;
}

}  // namespace gilt::raytrace_core::util
