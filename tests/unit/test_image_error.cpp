// The shared image error measures against values worked out by hand.

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "raytrace_core/io/image_error.h"

namespace rc = gilt::raytrace_core;

TEST(ImageError, MatchesHandComputedValues) {
  // Differences: 0.1 in every channel of the first pixel, 0 in the second.
  const std::vector<rc::Rgb> reference = {rc::Rgb(0.4f), rc::Rgb(1.0f)};
  const std::vector<rc::Rgb> image = {rc::Rgb(0.5f), rc::Rgb(1.0f)};
  const rc::ImageError e = rc::image_error(image, reference);
  const double d = double(0.5f) - double(0.4f), r = double(0.4f);
  EXPECT_NEAR(e.mae, d / 2, 1e-12);
  EXPECT_NEAR(e.rmse, std::sqrt(d * d / 2), 1e-12);
  EXPECT_NEAR(e.relmse, d * d / (r * r + 0.01) / 2, 1e-12);
  EXPECT_NEAR(e.mean_relative, d / (r + 0.01) / 2, 1e-12);
  EXPECT_EQ(rc::mean_relative_error(image, reference), e.mean_relative);
  EXPECT_EQ(rc::image_error(reference, reference).rmse, 0.0);
  // Brightness: (0.5 + 1) / (0.4 + 1) in every channel; a black reference reads 1.
  EXPECT_NEAR(e.mean_ratio, (double(0.5f) + 1.0) / (r + 1.0), 1e-12);
  EXPECT_EQ(rc::image_error(image, std::vector<rc::Rgb>(2, rc::Rgb(0.0f))).mean_ratio, 1.0);
  EXPECT_THROW(rc::image_error(image, std::vector<rc::Rgb>(1)), std::invalid_argument);
}
