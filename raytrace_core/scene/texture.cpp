#include "raytrace_core/scene/texture.h"

#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/texture.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "raytrace_core/util/error.h"
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

OIIO::TextureOpt::Wrap oiio_wrap(TextureWrap w) {
  switch (w) {
    case TextureWrap::clamp: return OIIO::TextureOpt::WrapClamp;
    case TextureWrap::mirror: return OIIO::TextureOpt::WrapMirror;
    case TextureWrap::repeat: break;
  }
  return OIIO::TextureOpt::WrapPeriodic;
}

/// The linear, MIP-mapped copy of an sRGB image, made once and kept in the cache folder.
std::string linear_copy(const std::string& file) {
  std::error_code ec;
  const fs::path source = fs::absolute(file, ec);
  const auto size = fs::file_size(source, ec);
  if (ec) throw InputError(file + ": texture cannot be read: " + ec.message());
  const auto time = fs::last_write_time(source, ec).time_since_epoch().count();
  const std::string key = source.string() + '|' + std::to_string(size) + '|' + std::to_string(time) + "|srgb-linear-half-v1";
  char name[40];
  std::snprintf(name, sizeof name, "%016llx.exr", static_cast<unsigned long long>(fnv1a(key)));
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
  const int alpha = spec.alpha_channel >= 0 ? spec.alpha_channel : (channels == 2 || channels == 4 ? channels - 1 : -1);
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

}  // namespace

struct TextureSet::Impl {
  OIIO::TextureSystem* system = nullptr;
  std::vector<OIIO::TextureSystem::TextureHandle*> handles;
  std::vector<int> channels;
  std::vector<Vec2> texel_size;
  std::vector<OIIO::TextureOpt> options;
  ~Impl() {
    if (system) OIIO::TextureSystem::destroy(system);
  }
};

TextureSet::TextureSet(const std::vector<TextureImage>& images) : impl_(std::make_unique<Impl>()), images_(images) {
  impl_->system = OIIO::TextureSystem::create(/*shared=*/false);
  OIIO::TextureSystem& ts = *impl_->system;
  ts.attribute("automip", 1);             // data textures without MIP levels get them in memory
  ts.attribute("unassociatedalpha", 1);   // see linear_copy
  ts.attribute("max_memory_MB", 1024.0f);
  ts.attribute("autotile", 64);
  for (const TextureImage& image : images_) {
    const std::string path = image.srgb ? linear_copy(image.file) : image.file;
    OIIO::TextureSystem::TextureHandle* handle = ts.get_texture_handle(OIIO::ustring(path));
    int resolution[2] = {0, 0};
    int channels = 0;
    if (!handle || !ts.get_texture_info(handle, nullptr, 0, OIIO::ustring("resolution"), OIIO::TypeDesc(OIIO::TypeDesc::INT, 2), resolution) ||
        !ts.get_texture_info(handle, nullptr, 0, OIIO::ustring("channels"), OIIO::TypeInt, &channels) || channels < 1) {
      const std::string why = ts.geterror();
      throw InputError(image.file + ": texture cannot be read" + (why.empty() ? std::string() : ": " + why));
    }
    impl_->handles.push_back(handle);
    impl_->channels.push_back(channels);
    impl_->texel_size.push_back(Vec2(1.0f / float(std::max(resolution[0], 1)), 1.0f / float(std::max(resolution[1], 1))));
    OIIO::TextureOpt opt;
    opt.swrap = oiio_wrap(image.wrap_s);
    opt.twrap = oiio_wrap(image.wrap_t);
    opt.fill = 1.0f;
    // Bilinear within a level: the default, "smart" bicubic, is a B-spline that blurs even an
    // exactly placed texel when the footprint is below one texel.
    opt.interpmode = OIIO::TextureOpt::InterpBilinear;
    impl_->options.push_back(opt);
    texels_ += size_t(resolution[0]) * size_t(resolution[1]) * size_t(channels);
  }
}

TextureSet::~TextureSet() = default;

int TextureSet::channels(int32_t image) const { return impl_->channels[size_t(image)]; }

Vec2 TextureSet::texel_size(int32_t image) const { return impl_->texel_size[size_t(image)]; }

Texel TextureSet::lookup(int32_t image, Vec2 st, Vec2 dx, Vec2 dy) const {
  OIIO::TextureSystem& ts = *impl_->system;
  const size_t i = size_t(image);
  OIIO::TextureOpt opt = impl_->options[i];
  float v[4] = {1.0f, 1.0f, 1.0f, 1.0f};
  const int n = std::min(impl_->channels[i], 4);
  if (!ts.texture(impl_->handles[i], ts.get_perthread_info(), opt, st.x, st.y, dx.x, dx.y, dy.x, dy.y, n, v))
    return Texel{};
  Texel out;
  if (n <= 2) {  // grey, or grey and alpha
    out.rgb = Rgb(v[0]);
    if (n == 2) out.alpha = v[1];
  } else {
    out.rgb = Rgb(v[0], v[1], v[2]);
    if (n == 4) out.alpha = v[3];
  }
  // Filtering with negative lobes or a half-float copy can stray below zero.
  out.rgb = Rgb(std::max(out.rgb.r, 0.0f), std::max(out.rgb.g, 0.0f), std::max(out.rgb.b, 0.0f));
  out.alpha = std::clamp(out.alpha, 0.0f, 1.0f);
  return out;
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
