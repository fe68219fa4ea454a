#include "raytrace_core/io/image_error.h"

#include <cmath>
#include <stdexcept>

namespace gilt::raytrace_core {

ImageError image_error(std::span<const Rgb> image, std::span<const Rgb> reference) {
  if (image.size() != reference.size()) throw std::invalid_argument("image_error: the images differ in size");
  if (image.empty()) return {};
  double se = 0.0, rel = 0.0, ae = 0.0, mre = 0.0, sum_image = 0.0, sum_reference = 0.0;
  for (size_t i = 0; i < image.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      const double r = reference[i][c], d = double(image[i][c]) - r;
      se += d * d;
      rel += d * d / (r * r + 0.01);
      ae += std::abs(d);
      mre += std::abs(d) / (r + 0.01);
      sum_image += image[i][c];
      sum_reference += r;
    }
  const double n = 3.0 * double(image.size());
  return {std::sqrt(se / n), rel / n, ae / n, mre / n, sum_reference > 0.0 ? sum_image / sum_reference : 1.0};
}

}  // namespace gilt::raytrace_core
