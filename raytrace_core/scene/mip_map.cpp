#include "raytrace_core/scene/mip_map.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

// Imath's conversions by bit operations (or F16C where the build enables it), not through its
// 256 kB table, which would compete with the texels for the cache.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>

namespace gilt::raytrace_core::scene {

namespace {

/// Texels on a tile's side; a tile of 4 channels is 128 bytes.
constexpr int kTile = 4;

int tiles(int texels) { return (texels + kTile - 1) / kTile; }

/// Texels along an axis at the next level: half, rounded down, at least 1.
int next_size(int n) { return std::max(1, n / 2); }

/// Largest finite half float.
constexpr float kHalfMax = 65504.0f;

/// One source texel's share of a texel of the next level.
struct Tap {
  int source;
  float weight;
};

/// The box filter along one axis from n_in texels to n_out: texel i of the next level is the mean
/// over the interval [i r, (i + 1) r) of the level below, r = n_in / n_out, each texel below
/// weighted by its overlap. For even n_in, r = 2 and every weight is exactly ½ (the 2 × 2 box);
/// for odd n_in (r between 2 and 3) the middle texel is shared between its two neighbours, so
/// each level is still the exact area mean of the one below and every level has the image's
/// mean. An axis of one texel stays one texel (r = 1).
std::vector<std::vector<Tap>> box_taps(int n_in, int n_out) {
  std::vector<std::vector<Tap>> taps(static_cast<size_t>(n_out));
  const double r = double(n_in) / double(n_out);
  for (int i = 0; i < n_out; ++i) {
    const double lo = double(i) * r, hi = i + 1 == n_out ? double(n_in) : double(i + 1) * r;
    for (int j = int(std::floor(lo)); j < n_in && double(j) < hi; ++j) {
      const double overlap = std::min(hi, double(j + 1)) - std::max(lo, double(j));
      if (overlap > 1e-9) taps[size_t(i)].push_back(Tap{j, float(overlap / r)});
    }
  }
  return taps;
}

/// The next level of a w × h image (channels `channels`, pixel stride `stride` floats).
LinearImage reduce(const float* pixels, int w, int h, int stride, int channels) {
  LinearImage out{next_size(w), next_size(h), channels, {}};
  const std::vector<std::vector<Tap>> along_x = box_taps(w, out.width), along_y = box_taps(h, out.height);
  // Along x into `rows` (out.width × h), then along y.
  std::vector<float> rows(size_t(out.width) * size_t(h) * size_t(channels), 0.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < out.width; ++x) {
      float* to = &rows[(size_t(y) * size_t(out.width) + size_t(x)) * size_t(channels)];
      for (const Tap& tap : along_x[size_t(x)]) {
        const float* from = pixels + (size_t(y) * size_t(w) + size_t(tap.source)) * size_t(stride);
        for (int c = 0; c < channels; ++c) to[c] += tap.weight * from[c];
      }
    }
  const size_t row = size_t(out.width) * size_t(channels);
  out.pixels.assign(row * size_t(out.height), 0.0f);
  for (int y = 0; y < out.height; ++y)
    for (const Tap& tap : along_y[size_t(y)]) {
      float* to = &out.pixels[size_t(y) * row];
      const float* from = &rows[size_t(tap.source) * row];
      for (size_t k = 0; k < row; ++k) to[k] += tap.weight * from[k];
    }
  return out;
}

/// A stored texel channel's value.
float value_of(uint16_t half) { return imath_half_to_float(half); }
float value_of(uint8_t code) { return float(code) * (1.0f / 255.0f); }

/// Replaces a coordinate that is not a number, or too large to index with, by 0.
float usable(float x) { return std::fabs(x) < 1e9f ? x : 0.0f; }

}  // namespace

int wrap_texel(int i, int n, TextureWrap wrap) {
  switch (wrap) {
    case TextureWrap::clamp:
      return std::clamp(i, 0, n - 1);
    case TextureWrap::mirror: {
      const int period = 2 * n;
      int p = i % period;
      if (p < 0) p += period;
      return p < n ? p : period - 1 - p;
    }
    case TextureWrap::repeat:
      break;
  }
  const int p = i % n;
  return p < 0 ? p + n : p;
}

size_t MipMap::bytes_for(int width, int height, int channels, TexelFormat format) {
  channels = std::min(channels, kMaxChannels);
  size_t texels = 0;  // channel values
  for (;;) {
    texels += size_t(tiles(width)) * size_t(tiles(height)) * size_t(kTile * kTile) * size_t(channels);
    if (width == 1 && height == 1) break;
    width = next_size(width), height = next_size(height);
  }
  return texels * (format == TexelFormat::half ? sizeof(uint16_t) : sizeof(uint8_t));
}

MipMap::MipMap(const LinearImage& image, TexelFormat format)
    : channels_(std::min(image.channels, kMaxChannels)), format_(format) {
  if (image.width < 1 || image.height < 1 || image.channels < 1 ||
      image.pixels.size() != size_t(image.width) * size_t(image.height) * size_t(image.channels))
    throw std::invalid_argument(
        "MipMap: an image needs a size, channels and width × height × channels values");
  const size_t count = bytes_for(image.width, image.height, image.channels, TexelFormat::unorm8);
  if (format_ == TexelFormat::half)
    halves_.resize(count);
  else
    codes_.resize(count);
  // Each level is made from the one below in full precision, then stored (half floats rounded to
  // nearest, codes to the nearest code), so rounding does not build up from level to level.
  LinearImage below;  // the level just stored, or empty while that is the image itself
  size_t offset = 0;
  for (;;) {
    const bool first = below.pixels.empty();
    const float* pixels = first ? image.pixels.data() : below.pixels.data();
    const int w = first ? image.width : below.width, h = first ? image.height : below.height;
    const int stride = first ? image.channels : channels_;
    Level level{w, h, tiles(w), offset};
    levels_.push_back(level);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const float* from = pixels + (size_t(y) * size_t(w) + size_t(x)) * size_t(stride);
        const size_t to = index(level, x, y);
        for (int c = 0; c < channels_; ++c) {
          if (format_ == TexelFormat::half)
            halves_[to + size_t(c)] = imath_float_to_half(std::clamp(from[c], -kHalfMax, kHalfMax));
          else
            codes_[to + size_t(c)] = uint8_t(std::lround(std::clamp(from[c], 0.0f, 1.0f) * 255.0f));
        }
      }
    offset += size_t(tiles(w)) * size_t(tiles(h)) * size_t(kTile * kTile) * size_t(channels_);
    if (w == 1 && h == 1) break;
    below = reduce(pixels, w, h, stride, channels_);
  }
}

size_t MipMap::index(const Level& level, int x, int y) const {
  const size_t tile = size_t(y / kTile) * size_t(level.tiles_x) + size_t(x / kTile);
  const size_t within = size_t(y % kTile) * kTile + size_t(x % kTile);
  return level.offset + (tile * (kTile * kTile) + within) * size_t(channels_);
}

float MipMap::texel(int level, int x, int y, int c) const {
  const size_t i = index(levels_[size_t(level)], x, y) + size_t(c);
  return format_ == TexelFormat::half ? value_of(halves_[i]) : value_of(codes_[i]);
}

void MipMap::bilerp(int level, Vec2 st, TextureWrap wrap_s, TextureWrap wrap_t, float* out) const {
  if (format_ == TexelFormat::half)
    bilerp_in(halves_.data(), level, st, wrap_s, wrap_t, out);
  else
    bilerp_in(codes_.data(), level, st, wrap_s, wrap_t, out);
}

template <typename T>
void MipMap::bilerp_in(const T* texels, int l, Vec2 st, TextureWrap wrap_s, TextureWrap wrap_t,
                       float* out) const {
  const Level& level = levels_[size_t(l)];
  // Texel centres at integer + ½.
  const float x = usable(st.x * float(level.width) - 0.5f), y = usable(st.y * float(level.height) - 0.5f);
  const float x0 = std::floor(x), y0 = std::floor(y);
  const float fx = x - x0, fy = y - y0;
  const int xa = wrap_texel(int(x0), level.width, wrap_s), xb = wrap_texel(int(x0) + 1, level.width, wrap_s);
  const int ya = wrap_texel(int(y0), level.height, wrap_t),
            yb = wrap_texel(int(y0) + 1, level.height, wrap_t);
  const T* t00 = texels + index(level, xa, ya);
  const T* t10 = texels + index(level, xb, ya);
  const T* t01 = texels + index(level, xa, yb);
  const T* t11 = texels + index(level, xb, yb);
  const float w00 = (1.0f - fx) * (1.0f - fy), w10 = fx * (1.0f - fy), w01 = (1.0f - fx) * fy, w11 = fx * fy;
  for (int c = 0; c < channels_; ++c)
    out[c] =
        w00 * value_of(t00[c]) + w10 * value_of(t10[c]) + w01 * value_of(t01[c]) + w11 * value_of(t11[c]);
}

void MipMap::filter(Vec2 st, Vec2 dx, Vec2 dy, TextureWrap wrap_s, TextureWrap wrap_t, float* out) const {
  // The footprint's width in texels of level 0: its longer axis, as pbrt-v4's trilinear filter
  // takes its largest derivative (so an elongated footprint blurs rather than aliases).
  const Vec2 resolution(float(levels_[0].width), float(levels_[0].height));
  const Vec2 axis_x = dx * resolution, axis_y = dy * resolution;
  const float width = std::sqrt(std::max(glm::dot(axis_x, axis_x), glm::dot(axis_y, axis_y)));
  const int last = levels() - 1;
  // Up to one texel wide (or not a number): level 0, magnified.
  if (!(width > 1.0f) || last == 0) return bilerp(0, st, wrap_s, wrap_t, out);
  if (!(width < std::ldexp(1.0f, last))) return bilerp(last, st, wrap_s, wrap_t, out);
  // Level k's texels are 2^k wide; width = u 2^k with u in [1, 2) lies between levels k and k + 1.
  // The blend is linear in u, as OpenImageIO's (pbrt-v4 blends in log₂ u), so a lookup here and
  // one through OpenImageIO's TextureSystem agree; both read level k alone at width 2^k.
  int exponent = 0;
  std::frexp(width, &exponent);  // width = m 2^exponent, m in [½, 1)
  const int k = exponent - 1;
  const float blend = std::ldexp(width, -k) - 1.0f;
  bilerp(k, st, wrap_s, wrap_t, out);
  if (blend <= 0.0f) return;
  float coarse[kMaxChannels];
  bilerp(k + 1, st, wrap_s, wrap_t, coarse);
  for (int c = 0; c < channels_; ++c) out[c] += blend * (coarse[c] - out[c]);
}

}  // namespace gilt::raytrace_core::scene
