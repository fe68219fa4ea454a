#include "raytrace_core/util/image_error.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace gilt::raytrace_core::util {

ImageError image_error(std::span<const Rgb> image, std::span<const Rgb> reference) {
  return image_error(image, reference, {});
}

ImageError image_error(std::span<const Rgb> image, std::span<const Rgb> reference,
                       std::span<const Rgb> reference_variance) {
  if (image.size() != reference.size()) throw std::invalid_argument("image_error: the images differ in size");
  const bool corrected = !reference_variance.empty();
  if (corrected && reference_variance.size() != reference.size())
    throw std::invalid_argument("image_error: the reference's variance differs in size from the images");
  if (image.empty()) return {};
  double se = 0.0, rel = 0.0, ae = 0.0, mre = 0.0, sum_image = 0.0, sum_reference = 0.0;
  double floor = 0.0, rel_floor = 0.0, term_sum = 0.0, term_sq = 0.0;
  for (size_t i = 0; i < image.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = reference[i][c], d = double(image[i][c]) - r, weight = 1.0 / (r * r + 0.01);
      const double v = corrected ? double(reference_variance[i][c]) : 0.0;
      se += d * d;
      rel += d * d * weight;
      floor += v;
      rel_floor += v * weight;
      const double term = (d * d - v) * weight;  // this pixel's share of the corrected relMSE
      term_sum += term;
      term_sq += term * term;
      ae += std::abs(d);
      mre += std::abs(d) / (r + 0.01);
      sum_image += image[i][c];
      sum_reference += r;
    }
  const double n = 3.0 * double(image.size());
  ImageError e;
  e.rmse_measured = std::sqrt(se / n);
  e.relmse_measured = rel / n;
  e.mse_floor = floor / n;
  e.relmse_floor = rel_floor / n;
  e.rmse = std::sqrt(std::max(0.0, se / n - e.mse_floor));
  e.relmse = e.relmse_measured - e.relmse_floor;
  const double mean_term = term_sum / n;
  e.relmse_stderr = n > 1.0 ? std::sqrt(std::max(0.0, term_sq / n - mean_term * mean_term) / (n - 1.0)) : 0.0;
  e.mae = ae / n;
  e.mean_relative = mre / n;
  e.mean_ratio = sum_reference > 0.0 ? sum_image / sum_reference : 1.0;
  e.noise_corrected = corrected;
  return e;
}

std::vector<Rgb> reference_variance(std::span<const Rgb> a, std::span<const Rgb> b, double w) {
  if (a.size() != b.size()) throw std::invalid_argument("reference_variance: the halves differ in size");
  if (!(w > 0.0 && w < 1.0)) throw std::invalid_argument("reference_variance: the weight must lie in (0, 1)");
  std::vector<Rgb> v(a.size());
  const float scale = float(w * (1.0 - w));
  for (size_t i = 0; i < a.size(); ++i) {
    const Rgb d = a[i] - b[i];
    v[i] = d * d * scale;
  }
  return v;
}

}  // namespace gilt::raytrace_core::util
