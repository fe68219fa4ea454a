#pragma once
// A MIP pyramid held in memory in the layout its lookups want (Williams 1983, "Pyramidal
// parametrics"): every level in 4 × 4 tiles, so the 2 × 2 texels a bilinear read takes lie in one
// or two cache lines; 1 to 4 channels, as half floats or as 8-bit codes (TexelFormat). Lookups take no lock
// and allocate nothing. Trilinear filtering after pbrt-v4's MIPMap::Filter (Pharr, Jakob & Humphreys 2023),
// with OpenImageIO's choice of levels for a footprint, so that the two agree (see filter()).
//
// Texture coordinates are OpenImageIO's, as in texture.h: (s, t) = (0, 0) at the image's top-left
// corner, texel (x, y) of a w × h level centred at ((x + ½) / w, (y + ½) / h).

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <vector>

#include "raytrace_core/util/math.h"

namespace gilt::raytrace_core::scene {

/// What happens outside [0, 1] along one texture axis (glTF's sampler wrap modes).
enum class TextureWrap : uint8_t { repeat, clamp, mirror };

/// Texel index i on an axis of n texels, wrapped into [0, n).
int wrap_texel(int i, int n, TextureWrap wrap);

/// How a pyramid stores its texels.
enum class TexelFormat : uint8_t {
  half,    ///< half floats: linear colour decoded from sRGB, and data deeper than 8 bits
  unorm8,  ///< codes 0–255 read as code / 255: 8-bit data images, level 0 exactly as stored
};

/// An image of linear values, rows top to bottom, channels interleaved: what a pyramid is made of.
struct LinearImage {
  int width = 0, height = 0, channels = 0;
  std::vector<float> pixels;  ///< width × height × channels
};

/// An image of 8-bit codes as read from a file (PNG, JPEG), rows top to bottom, channels
/// interleaved, with the linear value each channel's codes stand for (sRGB decoded for colour,
/// code / 255 for data and alpha). A pyramid made from it looks each code up once, rather than
/// going through a float copy of the image.
struct CodeImage {
  int width = 0, height = 0, channels = 0;
  std::vector<uint8_t> codes;                      ///< width × height × channels
  std::array<std::array<float, 256>, 4> values{};  ///< values[c][code], for the first 4 channels
};

/// Zeroed memory for a pyramid's texels. Past 2 MiB it is mapped on its own and, on Linux,
/// advised into transparent huge pages: lookups land anywhere in a large level (a photon's hit,
/// a bounce's), and 2-MiB pages keep their addresses in the TLB. SPPM on the five-texture model
/// of bench/texture_speed.py ran 25 % more rays per second with huge pages than without.
class TexelMemory {
 public:
  TexelMemory() = default;
  explicit TexelMemory(size_t bytes);
  ~TexelMemory();
  TexelMemory(TexelMemory&& other) noexcept;
  TexelMemory& operator=(TexelMemory&& other) noexcept;
  TexelMemory(const TexelMemory&) = delete;
  TexelMemory& operator=(const TexelMemory&) = delete;

  void* data() const { return data_; }
  size_t size() const { return size_; }

 private:
  void release();
  void* data_ = nullptr;
  size_t size_ = 0;
  bool mapped_ = false;  ///< by mmap, else by calloc
};

/// The levels of one image, finest first, held as half floats. Immutable once built; thread-safe.
class MipMap {
 public:
  /// Most channels a pyramid holds; further channels of an image are dropped.
  static constexpr int kMaxChannels = 4;

  /// Builds the pyramid: level 0 is the image, each further level the box-filtered half of the
  /// one below (see the .cpp for odd sizes), down to 1 × 1; each stored in `format`.
  explicit MipMap(const LinearImage& image, TexelFormat format = TexelFormat::half);
  /// The same from an 8-bit image: level 0 holds each code's value (in `format`), the levels
  /// above are filtered from the values as the float constructor filters its pixels.
  MipMap(const CodeImage& image, TexelFormat format);

  /// Writes the pyramid to `out` as this build lays it out in memory: a header naming the
  /// layout's version, the size, channels and format, then the texels. Returns out.good().
  bool write(std::ostream& out) const;
  /// A pyramid written by write(), or nothing when `in` holds something else: another layout's
  /// version, a size out of range, fewer or more bytes than the header implies.
  static std::optional<MipMap> read(std::istream& in);

  /// Bytes the pyramid of a width × height image with `channels` channels takes, tiles padded.
  static size_t bytes_for(int width, int height, int channels, TexelFormat format = TexelFormat::half);

  int levels() const { return int(levels_.size()); }
  int width(int level) const { return levels_[size_t(level)].width; }
  int height(int level) const { return levels_[size_t(level)].height; }
  int channels() const { return channels_; }
  TexelFormat format() const { return format_; }
  /// Bytes the levels take.
  size_t bytes() const { return texels_.size(); }

  /// Channel c of texel (x, y) of a level, as stored (rounded to the format).
  float texel(int level, int x, int y, int c) const;

  /// Bilinear read of one level at (s, t), wrapped per axis; writes channels() values to out.
  void bilerp(int level, Vec2 st, TextureWrap wrap_s, TextureWrap wrap_t, float* out) const;

  /// Trilinear read over the footprint spanned by the (s, t) derivatives dx and dy: bilinear in
  /// the two levels bracketing the footprint's width, blended; zero derivatives read level 0.
  /// Writes channels() values to out.
  void filter(Vec2 st, Vec2 dx, Vec2 dy, TextureWrap wrap_s, TextureWrap wrap_t, float* out) const;

 private:
  struct Level {
    int width = 0, height = 0;
    int tiles_x = 0;    ///< tiles per row
    size_t offset = 0;  ///< first half float of the level in texels_
  };
  MipMap(int width, int height, int channels, TexelFormat format);
  /// Lays out the levels of a width × height image and sizes the texels.
  void allocate(int width, int height);
  /// Stores level l: stored(x, y, c) is channel c of texel (x, y) in the format's type. Rows are
  /// stored in parallel.
  template <typename Stored>
  void store(int l, const Stored& stored);
  /// Stores `image` as level l and every coarser level filtered from it.
  void store_from(int l, LinearImage image);
  /// Index into the texels of channel 0 of texel (x, y) of a level.
  size_t index(const Level& level, int x, int y) const;
  template <typename T>
  void bilerp_in(const T* texels, int level, Vec2 st, TextureWrap wrap_s, TextureWrap wrap_t,
                 float* out) const;

  /// The texels as half floats' bits, or as 8-bit codes: by format_.
  uint16_t* halves() const { return static_cast<uint16_t*>(texels_.data()); }
  uint8_t* codes() const { return static_cast<uint8_t*>(texels_.data()); }

  std::vector<Level> levels_;
  TexelMemory texels_;  ///< level by level, tile by tile
  int channels_ = 0;
  TexelFormat format_ = TexelFormat::half;
};

}  // namespace gilt::raytrace_core::scene
