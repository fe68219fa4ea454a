#pragma once
// The image being rendered: linear RGB float pixels and the pixel reconstruction filter.
//
// Anti-aliasing is stochastic: each sample's position is drawn from the filter itself, so every
// sample carries weight one and lands in exactly one pixel (no splatting, no races between tiles).

#include <cstdint>
#include <string>
#include <vector>

#include "raytrace_core/util/math.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core::render {

/// Pixel reconstruction filter.
enum class FilterKind : uint8_t { box, tent, gaussian };

/// A filter and its radius in pixels (gaussian: σ = radius / 3, truncated at the radius).
struct Filter {
  FilterKind kind = FilterKind::gaussian;
  float radius = 1.5f;

  /// Offset from the pixel centre, in pixels, distributed as the filter; u ∈ [0,1)².
  Vec2 sample(Vec2 u) const;
  /// Filter kind from its name ("box", "tent", "gaussian"); throws InputError otherwise.
  static FilterKind parse(const std::string& name);
};

/// Linear float RGB image accumulated from samples.
class Film {
 public:
  Film() = default;
  Film(int width, int height);

  int width() const { return width_; }
  int height() const { return height_; }
  /// Adds one unit-weight sample to pixel (x, y).
  void add_sample(int x, int y, const Rgb& radiance) {
    const size_t i = static_cast<size_t>(y) * width_ + x;
    sum_[i] += radiance;
    count_[i] += 1;
  }
  /// A pixel's sum of samples and their count (pixel = y · width + x), for joining the films of
  /// several processes.
  struct Accumulated {
    Rgb sum;
    uint32_t count = 0;
  };
  Accumulated accumulated(size_t pixel) const { return {sum_[pixel], count_[pixel]}; }
  void set_accumulated(size_t pixel, const Accumulated& a) { sum_[pixel] = a.sum, count_[pixel] = a.count; }
  /// Mean of the samples of pixel (x, y); black with no samples.
  Rgb pixel(int x, int y) const;
  /// The whole image, row-major from the top-left.
  std::vector<Rgb> pixels() const;
  /// Number of pixels whose value is NaN or infinite.
  size_t non_finite_count() const;

 private:
  int width_ = 0, height_ = 0;
  std::vector<Rgb> sum_;
  std::vector<uint32_t> count_;
};

}  // namespace gilt::raytrace_core::render
