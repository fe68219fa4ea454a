#include "raytrace_core/scene/texture.h"

#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>
#include <OpenImageIO/texture.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <sstream>

#include "raytrace_core/util/error.h"
#include "raytrace_core/util/parallel.h"
#include "raytrace_core/util/sampling.h"

namespace gilt::raytrace_core::scene {

namespace fs = std::filesystem;

TextureRef TextureRef::then(const std::array<float, 6>& n) const {
  TextureRef out = *this;
  out.map = {n[0] * map[0] + n[1] * map[3], n[0] * map[1] + n[1] * map[4], n[0] * map[2] + n[1] * map[5] + n[2],
             n[3] * map[0] + n[4] * map[3], n[3] * map[1] + n[4] * map[4], n[3] * map[2] + n[4] * map[5] + n[5]};
  return out;
}

std::string texture_cache_folder() {
  if (const char* own = std::getenv("GILT_TEXTURE_CACHE"); own && *own) return own;
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) return (fs::path(xdg) / "gilt" / "textures").string();
  if (const char* home = std::getenv("HOME"); home && *home) return (fs::path(home) / ".cache" / "gilt" / "textures").string();
  return (fs::temp_directory_path() / "gilt-textures").string();
}

namespace {

/// FNV-1a: a cache key that is the same in every run and build.
uint64_t fnv1a(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ull;
  return h;
}

/// The sRGB transfer function's inverse (IEC 61966-2-1): code value in [0, 1] to linear.
float srgb_to_linear(float c) {
  return c <= 0.04045f ? c * (1.0f / 12.92f) : std::pow((c + 0.055f) * (1.0f / 1.055f), 2.4f);
}

/// The alpha channel of an image of `channels` channels: the one its header names, else the last
/// of grey-and-alpha or RGBA; −1 for none.
int alpha_channel(int named, int channels) {
  if (named >= 0 && named < channels) return named;
  return channels == 2 || channels == 4 ? channels - 1 : -1;
}

OIIO::TextureOpt::Wrap oiio_wrap(TextureWrap w) {
  switch (w) {
    case TextureWrap::clamp: return OIIO::TextureOpt::WrapClamp;
    case TextureWrap::mirror: return OIIO::TextureOpt::WrapMirror;
    case TextureWrap::repeat: break;
  }
  return OIIO::TextureOpt::WrapPeriodic;
}

/// The name, in the cache folder, of what is kept there for `file` under `kind` (what was made
/// of it, and how): named by the file's absolute path, size and time, so an edited file gets a
/// new name. Empty, with `ec` set, when the file cannot be looked at.
std::string cache_name(const std::string& file, const std::string& kind, const char* extension,
                       std::error_code& ec) {
  const fs::path source = fs::absolute(file, ec);
  const auto size = fs::file_size(source, ec);
  if (ec) return {};
  const auto time = fs::last_write_time(source, ec).time_since_epoch().count();
  if (ec) return {};
  const std::string key =
      source.string() + '|' + std::to_string(size) + '|' + std::to_string(time) + '|' + kind;
  char name[48];
  std::snprintf(name, sizeof name, "%016llx%s", static_cast<unsigned long long>(fnv1a(key)), extension);
  return name;
}

/// The linear, MIP-mapped copy of an sRGB image, made once and kept in the cache folder.
std::string linear_copy(const std::string& file) {
  std::error_code ec;
  const std::string name = cache_name(file, "srgb-linear-half-v1", ".exr", ec);
  if (ec) throw InputError(file + ": texture cannot be read: " + ec.message());
  const fs::path source = fs::absolute(file, ec);
  const fs::path folder = texture_cache_folder();
  const fs::path target = folder / name;
  if (fs::exists(target, ec)) return target.string();
  fs::create_directories(folder, ec);
  if (ec) throw InputError("texture cache folder " + folder.string() + " cannot be made: " + ec.message());
  // Written under a name of this process's own and renamed into place, so a reader never sees a
  // half-written copy and two processes making the same one do not collide.
  const fs::path partial = folder / (std::string(name) + ".part" + std::to_string(::getpid()) + ".exr");
  // Decoded here rather than by OpenImageIO's colour management, which needs an OCIO
  // configuration that a plain install does not have.
  OIIO::ImageSpec read_config;
  read_config.attribute("oiio:UnassociatedAlpha", 1);  // colours as stored, not multiplied by alpha
  OIIO::ImageBuf source_image(source.string(), 0, 0, nullptr, &read_config);
  if (!source_image.read(0, 0, true, OIIO::TypeDesc::FLOAT))
    throw InputError(file + ": texture cannot be read: " + source_image.geterror());
  OIIO::ImageSpec spec = source_image.spec();
  const int channels = spec.nchannels;
  const int alpha = alpha_channel(spec.alpha_channel, channels);
  std::vector<float> pixels(size_t(spec.width) * size_t(spec.height) * size_t(channels));
  source_image.get_pixels(source_image.roi(), OIIO::TypeDesc::FLOAT, pixels.data());
  for (size_t i = 0; i < pixels.size(); ++i)
    if (int(i % size_t(channels)) != alpha) pixels[i] = srgb_to_linear(pixels[i]);
  spec.set_format(OIIO::TypeDesc::FLOAT);
  spec.attribute("oiio:ColorSpace", "linear");
  spec.erase_attribute("ICCProfile");  // describes the codes, not the linear copy (and OIIO logs it)
  OIIO::ImageBuf linear(spec, pixels.data());
  OIIO::ImageSpec config;
  config.set_format(OIIO::TypeDesc::HALF);
  config.attribute("maketx:filtername", "box");  // each level the exact mean of the one below
  config.attribute("maketx:updatemode", 0);
  std::ostringstream log;
  if (!OIIO::ImageBufAlgo::make_texture(OIIO::ImageBufAlgo::MakeTxTexture, linear, partial.string(), config, &log)) {
    fs::remove(partial, ec);
    throw InputError(file + ": texture cannot be converted: " + OIIO::geterror() + log.str());
  }
  fs::rename(partial, target, ec);
  if (ec) {
    fs::remove(partial, ec);
    throw InputError("texture cache " + target.string() + " cannot be written: " + ec.message());
  }
  return target.string();
}

/// A file and the role it is read in (colour or data): images naming the same pair share one
/// pyramid, whatever their wrap modes.
struct FileRole {
  std::string path;
  bool srgb = true;
  auto operator<=>(const FileRole&) const = default;
};

/// A file's size and channels, from its header.
struct ImageHeader {
  int width = 0, height = 0, channels = 0;
  TexelFormat format = TexelFormat::half;  ///< how its pyramid stores it
};

/// How a file's pyramid stores its texels: a data image of 8-bit codes keeps them (exactly, and
/// in half the memory; its coarser levels rounded to codes, as OpenImageIO's are); colour
/// images decoded from sRGB, and deeper data, as half floats.
TexelFormat storage_for(const OIIO::ImageSpec& spec, bool srgb) {
  const bool eight_bit = spec.format == OIIO::TypeDesc::UINT8 && spec.channelformats.empty();
  return !srgb && eight_bit ? TexelFormat::unorm8 : TexelFormat::half;
}

ImageHeader read_header(const FileRole& file) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file.path);
  if (!in) throw InputError(file.path + ": texture cannot be read: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width < 1 || spec.height < 1 || spec.nchannels < 1)
    throw InputError(file.path + ": texture cannot be read: it holds no pixels");
  return ImageHeader{spec.width, spec.height, spec.nchannels, storage_for(spec, file.srgb)};
}

/// The first subimage of a file in linear values, up to MipMap::kMaxChannels channels: colour
/// channels of an sRGB image decoded, alpha and data images as stored; made into its pyramid.
MipMap decode(const FileRole& file) {
  OIIO::ImageSpec config;
  config.attribute("oiio:UnassociatedAlpha", 1);  // colours as stored, not multiplied by alpha
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file.path, &config);
  if (!in) throw InputError(file.path + ": texture cannot be read: " + OIIO::geterror());
  const OIIO::ImageSpec& spec = in->spec();
  const int channels = std::min(spec.nchannels, MipMap::kMaxChannels);
  const size_t values = size_t(spec.width) * size_t(spec.height) * size_t(channels);
  const int alpha = file.srgb ? alpha_channel(spec.alpha_channel, channels) : -1;
  if (spec.format == OIIO::TypeDesc::UINT8 && spec.channelformats.empty()) {
    // 8-bit codes (PNG, JPEG): read as they are; the pyramid maps them through tables of their
    // 256 values, rather than one std::pow per value.
    CodeImage image{spec.width, spec.height, channels, std::vector<uint8_t>(values), {}};
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::UINT8, image.codes.data()))
      throw InputError(file.path + ": texture cannot be read: " + in->geterror());
    for (int c = 0; c < channels; ++c)
      for (int k = 0; k < 256; ++k) {
        const float stored = float(k) / 255.0f;
        image.values[size_t(c)][size_t(k)] = file.srgb && c != alpha ? srgb_to_linear(stored) : stored;
      }
    return MipMap(image, storage_for(spec, file.srgb));
  }
  LinearImage image{spec.width, spec.height, channels, std::vector<float>(values)};
  if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
    throw InputError(file.path + ": texture cannot be read: " + in->geterror());
  if (file.srgb)
    for (size_t i = 0; i < image.pixels.size(); ++i)
      if (int(i % size_t(channels)) != alpha) image.pixels[i] = srgb_to_linear(image.pixels[i]);
  return MipMap(image, storage_for(spec, file.srgb));
}

/// Pyramids smaller than this are not kept in the cache folder: they decode about as fast as
/// they read back.
constexpr size_t kCachedPyramidBytes = size_t(1) << 20;

/// Where a file's pyramid is kept between runs, by its role; empty when the file cannot be
/// looked at.
fs::path pyramid_cache_path(const FileRole& file) {
  std::error_code ec;
  const std::string name =
      cache_name(file.path, file.srgb ? "srgb-pyramid-v1" : "data-pyramid-v1", ".pyramid", ec);
  return ec ? fs::path() : fs::path(texture_cache_folder()) / name;
}

/// Removes pyramids from `folder`, least recently used first (a read touches its file), until
/// `incoming` more bytes fit within `budget`. False when they cannot. Another process removing
/// the same files at the same time only makes some removals fail, which is harmless.
bool make_room(const fs::path& folder, size_t incoming, size_t budget) {
  if (incoming > budget) return false;
  struct Entry {
    fs::file_time_type time;
    size_t bytes;
    fs::path path;
  };
  std::vector<Entry> entries;
  size_t total = 0;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(folder, ec)) {
    if (e.path().extension() != ".pyramid") continue;
    std::error_code stat;
    const size_t bytes = size_t(e.file_size(stat));
    const fs::file_time_type time = e.last_write_time(stat);
    if (stat) continue;
    entries.push_back(Entry{time, bytes, e.path()});
    total += bytes;
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.time < b.time; });
  for (const Entry& e : entries) {
    if (total + incoming <= budget) break;
    fs::remove(e.path, ec);
    total -= e.bytes;
  }
  return total + incoming <= budget;
}

/// A file's pyramid: read back from the cache folder when an earlier run made it, else decoded
/// and written there for the next run. The benchmark model's five 2048² images decode in about
/// 0.35 s on 2 threads and read back in a fraction of that (bench/README.md). The cache is an
/// aid, never a requirement: a folder that cannot be written, or a cached file that is not a
/// whole pyramid of this build's layout, is passed over, and the image decoded.
MipMap load_pyramid(const FileRole& file, const ImageHeader& header, bool& from_cache) {
  from_cache = false;
  if (MipMap::bytes_for(header.width, header.height, header.channels, header.format) < kCachedPyramidBytes)
    return decode(file);
  const fs::path cached = pyramid_cache_path(file);
  if (cached.empty()) return decode(file);
  if (std::ifstream in(cached, std::ios::binary); in) {
    std::optional<MipMap> pyramid = MipMap::read(in);
    if (pyramid && pyramid->width(0) == header.width && pyramid->height(0) == header.height &&
        pyramid->format() == header.format &&
        pyramid->channels() == std::min(header.channels, MipMap::kMaxChannels)) {
      from_cache = true;
      std::error_code ec;
      fs::last_write_time(cached, fs::file_time_type::clock::now(), ec);  // recently used
      return std::move(*pyramid);
    }
  }
  MipMap pyramid = decode(file);
  // Written under a name of its own and renamed into place, so a reader never sees a
  // half-written pyramid and two writers do not collide.
  static std::atomic<uint64_t> serial{0};
  std::error_code ec;
  fs::create_directories(cached.parent_path(), ec);
  const fs::path partial =
      cached.string() + ".part" + std::to_string(::getpid()) + "-" + std::to_string(serial.fetch_add(1));
  bool written = false;
  const size_t file_bytes = pyramid.bytes() + 64;  // its header's 32 bytes, with room
  if (!ec && make_room(cached.parent_path(), file_bytes, texture_cache_budget())) {
    std::ofstream out(partial, std::ios::binary);
    written = out && pyramid.write(out) && out.flush();
  }
  if (written) fs::rename(partial, cached, ec);
  if (!written || ec) fs::remove(partial, ec);
  return pyramid;
}

/// Calls body(f) for every file f on the thread pool; then throws the error of the first file (in
/// order, so the message does not depend on timing) whose body threw, naming the file.
void for_each_file(const std::vector<FileRole>& files, const std::function<void(size_t)>& body) {
  std::vector<std::string> errors(files.size());
  util::parallel_for(files.size(), [&](size_t f) {
    try {
      body(f);
    } catch (const InputError& e) {
      errors[f] = e.what();
    } catch (const std::exception& e) {  // out of memory, say
      errors[f] = files[f].path + ": texture cannot be read: " + e.what();
    }
  });
  for (const std::string& e : errors)
    if (!e.empty()) throw InputError(e);
}

/// Filtered channels (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA) as a texel.
Texel to_texel(const float* v, int channels) {
  Texel out;
  if (channels <= 2) {
    out.rgb = Rgb(v[0]);
    if (channels == 2) out.alpha = v[1];
  } else {
    out.rgb = Rgb(v[0], v[1], v[2]);
    if (channels == 4) out.alpha = v[3];
  }
  // Filtering with negative lobes or a half-float copy can stray below zero.
  out.rgb = Rgb(std::max(out.rgb.r, 0.0f), std::max(out.rgb.g, 0.0f), std::max(out.rgb.b, 0.0f));
  out.alpha = std::clamp(out.alpha, 0.0f, 1.0f);
  return out;
}

}  // namespace

namespace {

/// Bytes from an environment variable in mebibytes, or `fallback` when it is unset or empty.
size_t mebibytes_from_environment(const char* name, size_t fallback) {
  const char* text = std::getenv(name);
  if (!text || !*text) return fallback;
  char* end = nullptr;
  const unsigned long long mb = std::strtoull(text, &end, 10);
  if (*end != '\0' || text[0] == '-')
    throw InputError(std::string(name) + "=" + text + ": not a whole number of mebibytes");
  return size_t(mb) << 20;
}

}  // namespace

size_t texture_memory_budget() {
  return mebibytes_from_environment("GILT_TEXTURE_MEMORY_MB", size_t(4) << 30);
}

size_t texture_cache_budget() { return mebibytes_from_environment("GILT_TEXTURE_CACHE_MB", size_t(4) << 30); }

const char* texture_plan_name(TexturePlan plan) {
  return plan == TexturePlan::in_memory ? "in-memory pyramids" : "OpenImageIO's cache";
}

struct TextureSet::Impl {
  /// Under in_memory: one image's pyramid and wrap modes.
  struct Image {
    const MipMap* pyramid = nullptr;
    TextureWrap wrap_s = TextureWrap::repeat, wrap_t = TextureWrap::repeat;
  };
  std::vector<std::optional<MipMap>> pyramids;  ///< one per distinct file and role
  size_t cached_files = 0;                      ///< pyramids read back from the cache folder
  std::vector<Image> images;
  // Under oiio_cache.
  OIIO::TextureSystem* system = nullptr;
  std::vector<OIIO::TextureSystem::TextureHandle*> handles;
  std::vector<OIIO::TextureOpt> options;
  // Either.
  std::vector<int> channels;
  std::vector<Vec2> texel_size;

  ~Impl() {
    if (system) OIIO::TextureSystem::destroy(system);
  }
  /// Decodes every file into its pyramid, in parallel; points each image at its file's.
  void open_pyramids(const std::vector<TextureImage>& all, const std::vector<FileRole>& files,
                     const std::vector<ImageHeader>& headers, const std::vector<size_t>& file_of);
  /// Opens every image through OpenImageIO's TextureSystem.
  void open_cache(const std::vector<TextureImage>& all);
};

void TextureSet::Impl::open_pyramids(const std::vector<TextureImage>& all, const std::vector<FileRole>& files,
                                     const std::vector<ImageHeader>& headers,
                                     const std::vector<size_t>& file_of) {
  pyramids.resize(files.size());
  std::vector<char> from_cache(files.size(), 0);
  for_each_file(files, [&](size_t f) {
    bool cached = false;
    pyramids[f].emplace(load_pyramid(files[f], headers[f], cached));
    from_cache[f] = cached;
  });
  cached_files = size_t(std::count(from_cache.begin(), from_cache.end(), 1));
  for (size_t i = 0; i < all.size(); ++i) {
    const MipMap& pyramid = *pyramids[file_of[i]];
    images.push_back(Image{&pyramid, all[i].wrap_s, all[i].wrap_t});
    channels.push_back(pyramid.channels());
    texel_size.push_back(Vec2(1.0f / float(pyramid.width(0)), 1.0f / float(pyramid.height(0))));
  }
}

void TextureSet::Impl::open_cache(const std::vector<TextureImage>& all) {
  system = OIIO::TextureSystem::create(/*shared=*/false);
  OIIO::TextureSystem& ts = *system;
  ts.attribute("automip", 1);             // data textures without MIP levels get them in memory
  ts.attribute("unassociatedalpha", 1);   // see linear_copy
  ts.attribute("max_memory_MB", 1024.0f);
  ts.attribute("autotile", 64);
  for (const TextureImage& image : all) {
    const std::string path = image.srgb ? linear_copy(image.file) : image.file;
    OIIO::TextureSystem::TextureHandle* handle = ts.get_texture_handle(OIIO::ustring(path));
    int resolution[2] = {0, 0};
    int n = 0;
    if (!handle ||
        !ts.get_texture_info(handle, nullptr, 0, OIIO::ustring("resolution"),
                             OIIO::TypeDesc(OIIO::TypeDesc::INT, 2), resolution) ||
        !ts.get_texture_info(handle, nullptr, 0, OIIO::ustring("channels"), OIIO::TypeInt, &n) || n < 1) {
      const std::string why = ts.geterror();
      throw InputError(image.file + ": texture cannot be read" + (why.empty() ? std::string() : ": " + why));
    }
    handles.push_back(handle);
    channels.push_back(n);
    texel_size.push_back(
        Vec2(1.0f / float(std::max(resolution[0], 1)), 1.0f / float(std::max(resolution[1], 1))));
    OIIO::TextureOpt opt;
    opt.swrap = oiio_wrap(image.wrap_s);
    opt.twrap = oiio_wrap(image.wrap_t);
    opt.fill = 1.0f;
    // Bilinear within a level: the default, "smart" bicubic, is a B-spline that blurs even an
    // exactly placed texel when the footprint is below one texel.
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    options.push_back(opt);
  }
}

// A driver over named passes: group the images by file, read the files' headers, choose the
// plan by the pyramids' size, then open the images by it.
TextureSet::TextureSet(const std::vector<TextureImage>& images, size_t memory_budget)
    : impl_(std::make_unique<Impl>()), images_(images) {
  const auto start = std::chrono::steady_clock::now();

  // Group the images by file and role.
  std::vector<FileRole> files;
  std::vector<size_t> file_of;
  std::map<FileRole, size_t> seen;
  for (const TextureImage& image : images_) {
    std::error_code ec;
    fs::path path = fs::absolute(image.file, ec);
    const FileRole key{ec ? image.file : path.lexically_normal().string(), image.srgb};
    const auto [at, fresh] = seen.try_emplace(key, files.size());
    if (fresh) files.push_back(FileRole{image.file, image.srgb});
    file_of.push_back(at->second);
  }
  files_ = files.size();

  // Read the headers: sizes, channels and the pyramids' bytes.
  std::vector<ImageHeader> headers(files.size());
  for_each_file(files, [&](size_t f) { headers[f] = read_header(files[f]); });
  for (const ImageHeader& h : headers)
    pyramid_bytes_ += MipMap::bytes_for(h.width, h.height, h.channels, h.format);
  for (size_t i = 0; i < images_.size(); ++i) {
    const ImageHeader& h = headers[file_of[i]];
    texels_ += size_t(h.width) * size_t(h.height) * size_t(h.channels);
  }

  // Choose the plan and open the images by it.
  plan_ = pyramid_bytes_ <= memory_budget ? TexturePlan::in_memory : TexturePlan::oiio_cache;
  if (plan_ == TexturePlan::in_memory)
    impl_->open_pyramids(images_, files, headers, file_of);
  else
    impl_->open_cache(images_);
  cached_files_ = impl_->cached_files;
  load_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TextureSet::~TextureSet() = default;

int TextureSet::channels(int32_t image) const { return impl_->channels[size_t(image)]; }

Vec2 TextureSet::texel_size(int32_t image) const { return impl_->texel_size[size_t(image)]; }

Texel TextureSet::lookup(int32_t image, Vec2 st, Vec2 dx, Vec2 dy) const {
  const size_t i = size_t(image);
  float v[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  if (plan_ == TexturePlan::in_memory) {
    const Impl::Image& im = impl_->images[i];
    im.pyramid->filter(st, dx, dy, im.wrap_s, im.wrap_t, v);
    return to_texel(v, im.pyramid->channels());
  }
  OIIO::TextureSystem& ts = *impl_->system;
  OIIO::TextureOpt opt = impl_->options[i];
  const int n = std::min(impl_->channels[i], 4);
  if (!ts.texture(impl_->handles[i], ts.get_perthread_info(), opt, st.x, st.y, dx.x, dx.y, dy.x, dy.y, n, v))
    return Texel{};
  return to_texel(v, n);
}

Texel TextureSet::triangle_mean(int32_t image, Vec2 a, Vec2 b, Vec2 c) const {
  constexpr int kSide = 8;
  const Vec2 dx = (b - a) * (1.0f / kSide), dy = (c - a) * (1.0f / kSide);
  Rgb sum(0.0f);
  float alpha = 0.0f;
  for (int i = 0; i < kSide; ++i)
    for (int j = 0; j < kSide; ++j) {
      // The centres of kSide² strata, mapped onto the triangle by area.
      const Vec2 w = util::sample_uniform_triangle({(i + 0.5f) / kSide, (j + 0.5f) / kSide});
      const Texel t = lookup(image, (1.0f - w.x - w.y) * a + w.x * b + w.y * c, dx, dy);
      sum += t.rgb;
      alpha += t.alpha;
    }
  constexpr float inv = 1.0f / float(kSide * kSide);
  return Texel{sum * inv, alpha * inv};
}

}  // namespace gilt::raytrace_core::scene
