#include "raytrace_core/scene/mip_map.h"

#ifdef __linux__
#include <sys/mman.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <istream>
#include <new>
#include <ostream>
#include <stdexcept>
#include <string>
#include <utility>

#include "raytrace_core/util/parallel.h"

// Imath's conversions by bit operations (or F16C where the build enables it), not through its
// 256 kB table, which would compete with the texels for the cache.
#define IMATH_HALF_NO_LOOKUP_TABLE
#include <Imath/half.h>

namespace gilt::raytrace_core::scene {

namespace {

/// A transparent huge page: allocations of at least this size get their own mapping.
constexpr size_t kHugePage = size_t(2) << 20;

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

/// Texel rows handed to one work item when a level is filtered or stored in parallel.
constexpr size_t kRowsPerItem = 32;

/// Calls body(first, last) over blocks of rows [first, last) of `rows` rows, in parallel.
template <typename Body>
void for_row_blocks(int rows, const Body& body) {
  const size_t blocks = (size_t(rows) + kRowsPerItem - 1) / kRowsPerItem;
  util::parallel_for(blocks, [&](size_t b) {
    const int first = int(b * kRowsPerItem);
    body(first, std::min(rows, first + int(kRowsPerItem)));
  });
}

/// The next level of a w × h image with `channels` channels, whose channel c of texel (x, y) is
/// value(x, y, c): the image's own floats, or an 8-bit image's codes through their tables.
template <typename Value>
LinearImage reduce(const Value& value, int w, int h, int channels) {
  LinearImage out{next_size(w), next_size(h), channels, {}};
  const size_t row = size_t(out.width) * size_t(channels);
  if (w % 2 == 0 && h % 2 == 0) {
    // Even sizes (every level of a power-of-two image): each texel the mean of its 2 × 2 block,
    // in one pass. The same sums, in the same order, as the two passes below.
    out.pixels.resize(row * size_t(out.height));
    for_row_blocks(out.height, [&](int first, int last) {
      for (int y = first; y < last; ++y)
        for (int x = 0; x < out.width; ++x)
          for (int c = 0; c < channels; ++c) {
            const float upper = 0.5f * value(2 * x, 2 * y, c) + 0.5f * value(2 * x + 1, 2 * y, c);
            const float lower = 0.5f * value(2 * x, 2 * y + 1, c) + 0.5f * value(2 * x + 1, 2 * y + 1, c);
            out.pixels[size_t(y) * row + size_t(x) * size_t(channels) + size_t(c)] =
                0.5f * upper + 0.5f * lower;
          }
    });
    return out;
  }
  const std::vector<std::vector<Tap>> along_x = box_taps(w, out.width), along_y = box_taps(h, out.height);
  // Along x into `rows` (out.width × h), then along y; each in blocks of rows, in parallel.
  std::vector<float> rows(row * size_t(h), 0.0f);
  for_row_blocks(h, [&](int first, int last) {
    for (int y = first; y < last; ++y)
      for (int x = 0; x < out.width; ++x) {
        float* to = &rows[size_t(y) * row + size_t(x) * size_t(channels)];
        for (const Tap& tap : along_x[size_t(x)])
          for (int c = 0; c < channels; ++c) to[c] += tap.weight * value(tap.source, y, c);
      }
  });
  out.pixels.assign(row * size_t(out.height), 0.0f);
  for_row_blocks(out.height, [&](int first, int last) {
    for (int y = first; y < last; ++y)
      for (const Tap& tap : along_y[size_t(y)]) {
        float* to = &out.pixels[size_t(y) * row];
        const float* from = &rows[size_t(tap.source) * row];
        for (size_t k = 0; k < row; ++k) to[k] += tap.weight * from[k];
      }
  });
  return out;
}

/// Throws std::invalid_argument unless an image has a size, channels, and `count` (of `what`:
/// values, codes) = width × height × channels.
void check_shape(int width, int height, int channels, size_t count, const char* what) {
  if (width < 1 || height < 1 || channels < 1 || count != size_t(width) * size_t(height) * size_t(channels))
    throw std::invalid_argument(
        std::string("MipMap: an image needs a size, channels and width × height × channels ") + what);
}

/// A value stored as a half float's bits, clamped to the finite halves.
uint16_t to_half(float x) { return imath_float_to_half(std::clamp(x, -kHalfMax, kHalfMax)); }

/// A value in [0, 1] stored as the nearest 8-bit code.
uint8_t to_code(float x) { return uint8_t(std::clamp(x, 0.0f, 1.0f) * 255.0f + 0.5f); }

/// A stored texel channel's value.
float value_of(uint16_t half) { return imath_half_to_float(half); }
float value_of(uint8_t code) { return float(code) * (1.0f / 255.0f); }

/// Replaces a coordinate that is not a number, or too large to index with, by 0.
float usable(float x) { return std::fabs(x) < 1e9f ? x : 0.0f; }

}  // namespace

int wrap_texel(int i, int n, TextureWrap wrap) {
  if (unsigned(i) < unsigned(n)) return i;  // inside: every mode leaves it
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

TexelMemory::TexelMemory(size_t bytes) : size_(bytes) {
  if (bytes == 0) return;
#ifdef __linux__
  if (bytes >= kHugePage) {
    data_ = mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (data_ == MAP_FAILED) {
      data_ = nullptr;
      throw std::bad_alloc();
    }
    mapped_ = true;
    madvise(data_, bytes, MADV_HUGEPAGE);  // advice: where the kernel has none to give, it is ignored
    return;
  }
#endif
  data_ = std::calloc(bytes, 1);
  if (!data_) throw std::bad_alloc();
}

TexelMemory::~TexelMemory() { release(); }

TexelMemory::TexelMemory(TexelMemory&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      mapped_(other.mapped_) {}

TexelMemory& TexelMemory::operator=(TexelMemory&& other) noexcept {
  if (this != &other) {
    release();
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapped_ = other.mapped_;
  }
  return *this;
}

void TexelMemory::release() {
  if (!data_) return;
#ifdef __linux__
  if (mapped_) {
    munmap(data_, size_);
    data_ = nullptr;
    return;
  }
#endif
  std::free(data_);
  data_ = nullptr;
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
  check_shape(image.width, image.height, image.channels, image.pixels.size(), "values");
  const size_t stride = size_t(image.channels);
  const float* pixels = image.pixels.data();
  const auto at = [&](int x, int y, int c) {
    return pixels[(size_t(y) * size_t(image.width) + size_t(x)) * stride + size_t(c)];
  };
  allocate(image.width, image.height);
  if (format_ == TexelFormat::half)
    store(0, [&](int x, int y, int c) { return to_half(at(x, y, c)); });
  else
    store(0, [&](int x, int y, int c) { return to_code(at(x, y, c)); });
  if (levels() > 1) store_from(1, reduce(at, image.width, image.height, channels_));
}

MipMap::MipMap(const CodeImage& image, TexelFormat format)
    : channels_(std::min(image.channels, kMaxChannels)), format_(format) {
  check_shape(image.width, image.height, image.channels, image.codes.size(), "codes");
  const size_t stride = size_t(image.channels);
  const uint8_t* codes = image.codes.data();
  const auto code = [&](int x, int y, int c) {
    return codes[(size_t(y) * size_t(image.width) + size_t(x)) * stride + size_t(c)];
  };
  allocate(image.width, image.height);
  // Level 0 through each channel's table of what its 256 codes store as: one look-up per value.
  if (format_ == TexelFormat::half) {
    std::array<std::array<uint16_t, 256>, kMaxChannels> stored{};
    for (int c = 0; c < channels_; ++c)
      for (int k = 0; k < 256; ++k)
        stored[size_t(c)][size_t(k)] = to_half(image.values[size_t(c)][size_t(k)]);
    store(0, [&](int x, int y, int c) { return stored[size_t(c)][code(x, y, c)]; });
  } else {
    std::array<std::array<uint8_t, 256>, kMaxChannels> stored{};
    for (int c = 0; c < channels_; ++c)
      for (int k = 0; k < 256; ++k)
        stored[size_t(c)][size_t(k)] = to_code(image.values[size_t(c)][size_t(k)]);
    store(0, [&](int x, int y, int c) { return stored[size_t(c)][code(x, y, c)]; });
  }
  if (levels() > 1)
    store_from(1, reduce([&](int x, int y, int c) { return image.values[size_t(c)][code(x, y, c)]; },
                         image.width, image.height, channels_));
}

void MipMap::allocate(int width, int height) {
  size_t offset = 0;
  for (;;) {
    levels_.push_back(Level{width, height, tiles(width), offset});
    offset += size_t(tiles(width)) * size_t(tiles(height)) * size_t(kTile * kTile) * size_t(channels_);
    if (width == 1 && height == 1) break;
    width = next_size(width), height = next_size(height);
  }
  texels_ = TexelMemory(offset * (format_ == TexelFormat::half ? sizeof(uint16_t) : sizeof(uint8_t)));
}

template <typename Stored>
void MipMap::store(int l, const Stored& stored) {
  const Level& level = levels_[size_t(l)];
  for_row_blocks(level.height, [&](int first, int last) {
    for (int y = first; y < last; ++y)
      for (int x = 0; x < level.width; ++x) {
        const size_t to = index(level, x, y);
        for (int c = 0; c < channels_; ++c) {
          if constexpr (sizeof(stored(x, y, c)) == sizeof(uint16_t))
            halves()[to + size_t(c)] = stored(x, y, c);
          else
            codes()[to + size_t(c)] = stored(x, y, c);
        }
      }
  });
}

void MipMap::store_from(int l, LinearImage image) {
  // Each level is made from the one below in full precision, then stored (half floats rounded to
  // nearest, codes to the nearest code), so rounding does not build up from level to level.
  for (; l < levels(); ++l) {
    const size_t stride = size_t(channels_);
    const auto at = [&](int x, int y, int c) {
      return image.pixels[(size_t(y) * size_t(image.width) + size_t(x)) * stride + size_t(c)];
    };
    if (format_ == TexelFormat::half)
      store(l, [&](int x, int y, int c) { return to_half(at(x, y, c)); });
    else
      store(l, [&](int x, int y, int c) { return to_code(at(x, y, c)); });
    if (l + 1 < levels()) image = reduce(at, image.width, image.height, channels_);
  }
}

MipMap::MipMap(int width, int height, int channels, TexelFormat format)
    : channels_(channels), format_(format) {
  allocate(width, height);
}

namespace {

/// The first bytes of a written pyramid: names this layout (4 × 4 tiles, channels interleaved,
/// levels finest first), so that a file of another layout is not taken for one.
constexpr char kPyramidMagic[16] = "gilt-mip-4x4-v1";

}  // namespace

bool MipMap::write(std::ostream& out) const {
  const int32_t header[4] = {levels_[0].width, levels_[0].height, channels_, int32_t(format_)};
  out.write(kPyramidMagic, sizeof kPyramidMagic);
  out.write(reinterpret_cast<const char*>(header), sizeof header);
  out.write(static_cast<const char*>(texels_.data()), std::streamsize(texels_.size()));
  return out.good();
}

std::optional<MipMap> MipMap::read(std::istream& in) {
  char magic[sizeof kPyramidMagic];
  int32_t header[4];
  if (!in.read(magic, sizeof magic) || std::memcmp(magic, kPyramidMagic, sizeof magic) != 0)
    return std::nullopt;
  if (!in.read(reinterpret_cast<char*>(header), sizeof header)) return std::nullopt;
  const auto [width, height, channels, format] = header;
  if (width < 1 || height < 1 || width > (1 << 20) || height > (1 << 20) || channels < 1 ||
      channels > kMaxChannels ||
      (format != int32_t(TexelFormat::half) && format != int32_t(TexelFormat::unorm8)))
    return std::nullopt;
  MipMap pyramid(width, height, channels, TexelFormat(format));
  const auto bytes = std::streamsize(pyramid.texels_.size());
  if (in.read(static_cast<char*>(pyramid.texels_.data()), bytes).gcount() != bytes) return std::nullopt;
  if (in.peek() != std::char_traits<char>::eof()) return std::nullopt;  // more than the header implies
  return pyramid;
}

inline size_t MipMap::index(const Level& level, int x, int y) const {
  // x, y ≥ 0, so the divisions and remainders by the tile's side are shifts and masks.
  const unsigned ux = unsigned(x), uy = unsigned(y);
  const size_t tile = size_t(uy / kTile) * size_t(level.tiles_x) + size_t(ux / kTile);
  const size_t within = size_t(uy % kTile) * kTile + size_t(ux % kTile);
  return level.offset + (tile * (kTile * kTile) + within) * size_t(channels_);
}

float MipMap::texel(int level, int x, int y, int c) const {
  const size_t i = index(levels_[size_t(level)], x, y) + size_t(c);
  return format_ == TexelFormat::half ? value_of(halves()[i]) : value_of(codes()[i]);
}

void MipMap::bilerp(int level, Vec2 st, TextureWrap wrap_s, TextureWrap wrap_t, float* out) const {
  if (format_ == TexelFormat::half)
    bilerp_in(halves(), level, st, wrap_s, wrap_t, out);
  else
    bilerp_in(codes(), level, st, wrap_s, wrap_t, out);
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
