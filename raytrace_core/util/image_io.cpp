// Image files through OpenImageIO.
//
// A write encodes the image in memory, then writes it to a hidden temporary file next to the
// destination that keeps its extension, e.g. ".out.exr.tmp-1234-0.exr". Only a complete file,
// flushed to disk, is renamed over the destination; on any failure the temporary is removed and
// the destination is left as it was.
//
// Non-finite pixel values (NaN, ±inf) are written as 0: no file ever holds them. Callers that want
// to warn about them check Film::non_finite_count() before writing.

#include "raytrace_core/util/image_io.h"

#include <fcntl.h>
#include <unistd.h>

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/strutil.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <system_error>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/staged_file.h"

namespace gilt::raytrace_core::util {

namespace fs = std::filesystem;

namespace {

enum class Format { exr, hdr, png, unsupported };

std::string lower_extension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

Format format_of(const std::string& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".exr") return Format::exr;
  if (ext == ".hdr") return Format::hdr;
  if (ext == ".png") return Format::png;
  return Format::unsupported;
}

float finite_or_zero(float v) { return std::isfinite(v) ? v : 0.0f; }

/// The sRGB opto-electronic transfer function (IEC 61966-2-1), linear [0,1] to encoded [0,1].
float srgb_encode(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

/// Inverse of srgb_encode.
float srgb_decode(float encoded) {
  return encoded <= 0.04045f ? encoded / 12.92f : std::pow((encoded + 0.055f) / 1.055f, 2.4f);
}

/// Linear radiance to an 8-bit sRGB code value: exposure scale, transfer function, clamp, round.
uint8_t to_srgb8(float linear, float scale) {
  const float encoded = std::clamp(srgb_encode(finite_or_zero(linear * scale)), 0.0f, 1.0f);
  return static_cast<uint8_t>(std::lround(encoded * 255.0f));
}

/// Encodes `pixels` (laid out as `spec` says) in the format named by `path`'s extension into
/// `bytes`; returns OIIO's error message, empty on success. Encoding in memory lets us check every
/// write to disk ourselves: OIIO's PNG writer, for one, ignores a short write (disk full).
std::string encode_with_oiio(const fs::path& path, const OIIO::ImageSpec& spec, const void* pixels,
                             std::vector<unsigned char>& bytes) {
  OIIO::Filesystem::IOVecOutput memory(bytes);  // declared first: it must outlive `out`
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) return OIIO::geterror();
  if (!out->set_ioproxy(&memory)) return "this format cannot be encoded in memory";
  if (!out->open(path.string(), spec)) return out->geterror();
  if (!out->write_image(spec.format == OIIO::TypeDesc::HALF ? OIIO::TypeDesc(OIIO::TypeDesc::FLOAT) : spec.format, pixels)) {
    std::string message = out->geterror();
    out->close();
    return message;
  }
  if (!out->close()) return out->geterror();
  return {};
}

}  // namespace

bool is_supported_image_path(const std::string& path) { return format_of(path) != Format::unsupported; }

void write_image(const std::string& path, const Image& image, float exposure, bool half_float) {
  const Format format = format_of(path);
  if (format == Format::unsupported) {
    throw InputError("cannot write '" + path + "': unsupported image format '" +
                     fs::path(path).extension().string() + "' (expected .exr, .hdr or .png)");
  }
  const size_t count = static_cast<size_t>(std::max(image.width, 0)) * std::max(image.height, 0);
  if (image.pixels.size() != count) {
    throw std::invalid_argument("write_image: pixel count does not match " + std::to_string(image.width) +
                                "x" + std::to_string(image.height));
  }
  const fs::path destination(path);
  const fs::path folder = destination.parent_path().empty() ? fs::path(".") : destination.parent_path();
  std::error_code ec;
  if (!fs::is_directory(folder, ec)) {
    throw InputError("cannot write '" + path + "': '" + folder.string() + "' is not an existing directory");
  }

  OIIO::ImageSpec spec(image.width, image.height, 3, OIIO::TypeDesc::FLOAT);
  std::vector<float> linear;
  std::vector<uint8_t> encoded;
  const void* data = nullptr;
  if (format == Format::png) {
    const float scale = std::exp2(exposure);
    encoded.reserve(3 * count);
    for (const Rgb& p : image.pixels) {
      for (int c = 0; c < 3; ++c) encoded.push_back(to_srgb8(p[c], scale));
    }
    spec.set_format(OIIO::TypeDesc::UINT8);
    spec.attribute("oiio:ColorSpace", "sRGB");
    data = encoded.data();
  } else {
    // Full 32-bit float in EXR keeps every value bit-exact; .hdr quantises to RGBE regardless,
    // and RGBE has no sign, so negative values are written to it as 0.
    const float lowest = format == Format::hdr ? 0.0f : -std::numeric_limits<float>::max();
    linear.reserve(3 * count);
    for (const Rgb& p : image.pixels) {
      for (int c = 0; c < 3; ++c) linear.push_back(std::max(finite_or_zero(p[c]), lowest));
    }
    if (format == Format::exr) spec.attribute("compression", "zip");
    data = linear.data();
    if (format == Format::exr && half_float) {
      // OIIO converts the float pixels as it writes; values past half's range become infinite.
      for (float& x : linear) x = std::clamp(x, -65504.0f, 65504.0f);
      spec.set_format(OIIO::TypeDesc::HALF);
    }
  }
  // OpenImageIO stamps EXR files with the current time (capDate) unless told a DateTime; a fixed
  // one keeps files bit-identical across runs, so equal images give equal files.
  spec.attribute("DateTime", "1970:01:01 00:00:00");

  // The path only tells OIIO the format: the bytes go to memory, then through a StagedFile.
  std::vector<unsigned char> bytes;
  const std::string error = encode_with_oiio(destination, spec, data, bytes);
  if (!error.empty()) throw InputError("cannot write '" + path + "': " + error);
  StagedFile(destination, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size())).commit();
}

Image read_image(const std::string& path) {
  // Colour channels exactly as stored: without this, OIIO multiplies the colour of files with
  // unassociated alpha (PNG, TGA) by alpha, in encoded space.
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);
  auto in = OIIO::ImageInput::open(path, &config);
  if (!in) throw InputError("cannot read image '" + path + "': " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  // One or two channels (grey, grey + alpha) read as grey; otherwise the first three are RGB.
  const int channels = spec.nchannels >= 3 ? 3 : 1;
  if (spec.nchannels < 1 || spec.width < 1 || spec.height < 1) {
    throw InputError("cannot read image '" + path + "': it has no pixels or no channels");
  }

  Image image;
  image.width = spec.width;
  image.height = spec.height;
  const size_t count = static_cast<size_t>(spec.width) * spec.height;
  std::vector<float> buffer(count * channels);
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, buffer.data())) {
    throw InputError("cannot read image '" + path + "': " + in->geterror());
  }

  // Decide how the stored values map to linear ones: an explicit "linear", "sRGB" or "GammaX"
  // tag wins; otherwise integer data is taken as sRGB-encoded (the convention for 8-bit and
  // 16-bit files) and float data as linear.
  const std::string space = spec.get_string_attribute("oiio:ColorSpace");
  const bool is_float = spec.format.basetype == OIIO::TypeDesc::FLOAT ||
                        spec.format.basetype == OIIO::TypeDesc::HALF ||
                        spec.format.basetype == OIIO::TypeDesc::DOUBLE;
  float gamma = is_float ? 1.0f : 0.0f;  // 0 = sRGB curve, 1 = linear, otherwise a power law
  if (OIIO::Strutil::iequals(space, "linear")) {
    gamma = 1.0f;
  } else if (OIIO::Strutil::iequals(space, "sRGB")) {
    gamma = 0.0f;
  } else if (OIIO::Strutil::istarts_with(space, "gamma")) {
    const float g = OIIO::Strutil::stof(space.substr(5));
    if (g > 0.0f) gamma = g;
  }
  auto decode = [gamma](float v) {
    if (gamma == 1.0f) return v;
    if (gamma == 0.0f) return srgb_decode(v);
    return std::pow(std::max(v, 0.0f), gamma);
  };

  image.pixels.resize(count);
  for (size_t i = 0; i < count; ++i) {
    const float* p = &buffer[i * channels];
    image.pixels[i] = channels == 1 ? Rgb(decode(p[0])) : Rgb(decode(p[0]), decode(p[1]), decode(p[2]));
  }
  return image;
}

}  // namespace gilt::raytrace_core::util
