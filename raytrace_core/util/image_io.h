#pragma once
// Image files through OpenImageIO. Writes are atomic: the image goes to a temporary file in the
// destination folder, which is renamed over the destination only when complete.

#include <string>
#include <vector>

#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core::util {

/// A linear RGB float image, row-major from the top-left.
struct Image {
  int width = 0, height = 0;
  std::vector<Rgb> pixels;
};

/// True when `path` ends in an extension write_image supports (.exr, .hdr, .png).
bool is_supported_image_path(const std::string& path);

/// Writes linear RGB: .exr (half or float, lossless) and .hdr as linear radiance; .png as 8-bit
/// sRGB after scaling by 2^exposure and clamping. Throws InputError for an unsupported extension
/// or an unwritable destination; an existing file is replaced only after a complete write.
/// `half_float` writes .exr as 16-bit half (values clamped to its range, ±65504).
void write_image(const std::string& path, const Image& image, float exposure = 0.0f, bool half_float = false);

/// Reads any image OpenImageIO understands as linear RGB float (sRGB PNGs are linearised).
/// Throws InputError naming the file when it cannot be read.
Image read_image(const std::string& path);

}  // namespace gilt::raytrace_core::util
