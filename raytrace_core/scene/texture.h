#pragma once
// Image textures: what a scene's materials read and how, and the filtered lookups. OpenImageIO
// reads the files (every format it reads). A scene whose pyramids fit the memory budget (see
// texture_memory_budget()) holds them in memory (mip_map.h): every distinct file decoded once, in
// parallel, at load, and lookups without locks. A scene whose textures would not fit is read
// through OpenImageIO's TextureSystem instead (tiled, MIP-mapped, cached), which pages tiles in
// and out as lookups need them.
//
// Texture coordinates reach the lookup in OpenImageIO's convention, (s, t) = (0, 0) at the
// image's top-left corner. Each format's loader folds its own convention into the reference's
// affine map: glTF's UVs already are (s, t); OBJ's v runs up the image, so its map is t = 1 − v.
//
// Colour textures are stored sRGB-encoded, but light adds up in linear values, and a filtered
// (or averaged) texel must be the mean of linear values, not of codes. So an sRGB image is
// decoded to linear once: into its in-memory pyramid, or, for OpenImageIO's cache, into a linear,
// half-float, MIP-mapped copy (OpenImageIO's make_texture, as `maketx --colorconvert sRGB linear`
// does) kept in a cache folder keyed by the source file's path, size and time (see
// texture_cache_folder()). Data textures (normal, metallic-roughness) are read as they are.
// Alpha stays as stored (unassociated) in both.

#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "raytrace_core/scene/mip_map.h"
#include "raytrace_core/util/math.h"
#include "raytrace_core/util/rgb.h"

namespace gilt::raytrace_core::scene {

/// An image file a material reads.
struct TextureImage {
  std::string file;   ///< path as the loader resolved it
  bool srgb = true;   ///< colour (sRGB-encoded) or data (read linear)
  TextureWrap wrap_s = TextureWrap::repeat, wrap_t = TextureWrap::repeat;
};

/// Where a material reads an image: which one, and the affine map from the mesh's UVs to (s, t).
struct TextureRef {
  int32_t image = -1;  ///< index into Scene::textures, or −1 for none
  /// s = m[0] u + m[1] v + m[2],  t = m[3] u + m[4] v + m[5].
  std::array<float, 6> map{1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f};

  bool valid() const { return image >= 0; }
  Vec2 st(Vec2 uv) const { return {map[0] * uv.x + map[1] * uv.y + map[2], map[3] * uv.x + map[4] * uv.y + map[5]}; }
  /// The map's linear part applied to a UV difference (a footprint's axis).
  Vec2 st_delta(Vec2 duv) const { return {map[0] * duv.x + map[1] * duv.y, map[3] * duv.x + map[4] * duv.y}; }
  /// Composes `then` after this map (then ∘ this).
  TextureRef then(const std::array<float, 6>& next) const;
};

/// A filtered texel: linear RGB and coverage.
struct Texel {
  Rgb rgb{1.0f};
  float alpha = 1.0f;
};

/// How a TextureSet holds its images.
enum class TexturePlan : uint8_t {
  in_memory,   ///< MIP pyramids in memory, built at load (mip_map.h)
  oiio_cache,  ///< OpenImageIO's TextureSystem, paging tiles through its cache
};

/// Bytes of in-memory pyramids a scene may hold: $GILT_TEXTURE_MEMORY_MB mebibytes, else 4 GiB.
size_t texture_memory_budget();

/// Bytes the pyramids kept in the texture cache folder may take together: GILT_TEXTURE_CACHE_MB
/// (mebibytes; InputError if it is not a whole number), else 4 GiB. Past it, the pyramids least
/// recently used are removed to make room.
size_t texture_cache_budget();

/// The images of one scene, opened for filtered lookups. Thread-safe.
class TextureSet {
 public:
  /// Opens every image: reads the files' headers, then, if their pyramids take at most
  /// memory_budget bytes, decodes each distinct file once, in parallel, into a pyramid; else
  /// opens them through OpenImageIO's cache (converting sRGB ones into linear copies first).
  /// Throws InputError naming a file that cannot be read.
  explicit TextureSet(const std::vector<TextureImage>& images,
                      size_t memory_budget = texture_memory_budget());
  ~TextureSet();
  TextureSet(const TextureSet&) = delete;
  TextureSet& operator=(const TextureSet&) = delete;

  /// The image filtered over the parallelogram footprint spanned by the (s, t) derivatives
  /// dx and dy at (s, t); zero derivatives read the finest level bilinearly.
  Texel lookup(int32_t image, Vec2 st, Vec2 dx = Vec2(0.0f), Vec2 dy = Vec2(0.0f)) const;

  /// Mean of the image over the triangle with corners (s, t) = a, b, c: 64 stratified points,
  /// each filtered over its own share of the triangle.
  Texel triangle_mean(int32_t image, Vec2 a, Vec2 b, Vec2 c) const;

  /// Width × height × channels of each image's finest level, summed.
  size_t texel_count() const { return texels_; }
  /// Which plan the images were opened with.
  TexturePlan plan() const { return plan_; }
  /// Bytes the in-memory pyramids take (or, under oiio_cache, would have taken), each distinct
  /// file counted once.
  size_t pyramid_bytes() const { return pyramid_bytes_; }
  /// Distinct files (with their colour or data role) the images read.
  size_t file_count() const { return files_; }
  /// Files whose pyramids were read back from the cache folder rather than decoded.
  size_t cached_file_count() const { return cached_files_; }
  /// Wall-clock seconds the constructor took (headers, decoding, pyramids or cache copies).
  double load_seconds() const { return load_seconds_; }
  size_t size() const { return images_.size(); }
  /// Channels of one image (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA).
  int channels(int32_t image) const;
  /// One texel's width and height in (s, t) at the finest level: 1 / resolution.
  Vec2 texel_size(int32_t image) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::vector<TextureImage> images_;
  size_t texels_ = 0;
  TexturePlan plan_ = TexturePlan::in_memory;
  size_t pyramid_bytes_ = 0;
  size_t files_ = 0;
  size_t cached_files_ = 0;
  double load_seconds_ = 0.0;
};

/// "in-memory pyramids" or "OpenImageIO's cache".
const char* texture_plan_name(TexturePlan plan);

/// Folder the linear copies of sRGB textures are kept in: $GILT_TEXTURE_CACHE, else
/// $XDG_CACHE_HOME/gilt/textures, else ~/.cache/gilt/textures, else the system's temporary folder.
std::string texture_cache_folder();

}  // namespace gilt::raytrace_core::scene
