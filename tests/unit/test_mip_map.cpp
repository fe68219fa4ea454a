// In-memory MIP pyramids (raytrace_core/scene/mip_map.h): box levels that are exact means,
// texel-exact reads at texel centres, the wrap modes, and agreement with OpenImageIO's
// TextureSystem (TextureSet's other plan) on filtered lookups.
//
// Tolerances: texels are stored as half floats, whose 11-bit significand rounds a value v to
// within 2⁻¹¹ |v| (kHalf below). A stored level's texel and the mean of the stored texels under
// it each carry one such rounding of values ≤ max |v|, so they agree within 2 · 2⁻¹¹ · max |v|,
// plus single-precision sums (≤ 1e-6 for values ≤ 1).

#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "raytrace_core/scene/mip_map.h"
#include "raytrace_core/scene/texture.h"
#include "raytrace_core/util/error.h"

namespace gilt {
namespace {

namespace fs = std::filesystem;
namespace rc = raytrace_core;
using rc::scene::MipMap;
using rc::scene::TextureWrap;

constexpr float kHalf = 1.0f / 2048.0f;  // a half float's relative rounding, 2⁻¹¹

/// A w × h image with `channels` channels of values in [0, 1], varied at every scale: a
/// fixed hash of (x, y, c), so no two neighbours are alike.
rc::scene::LinearImage hashed_image(int w, int h, int channels) {
  rc::scene::LinearImage image{w, h, channels, {}};
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < channels; ++c) {
        uint32_t k = uint32_t(x) * 73856093u ^ uint32_t(y) * 19349663u ^ uint32_t(c) * 83492791u;
        k = (k ^ (k >> 13)) * 0x5bd1e995u;
        image.pixels.push_back(float((k ^ (k >> 15)) & 0xffffu) / 65535.0f);
      }
  return image;
}

TEST(MipMap, EachLevelIsTheMeanOfTheOneBelow) {
  const MipMap pyramid(hashed_image(16, 8, 3));
  ASSERT_EQ(pyramid.levels(), 5);  // 16×8, 8×4, 4×2, 2×1, 1×1
  EXPECT_EQ(pyramid.width(3), 2);
  EXPECT_EQ(pyramid.height(3), 1);
  const float tolerance = 2.0f * kHalf * 1.0f + 1e-6f;
  for (int l = 1; l < pyramid.levels(); ++l)
    for (int y = 0; y < pyramid.height(l); ++y)
      for (int x = 0; x < pyramid.width(l); ++x)
        for (int c = 0; c < 3; ++c) {
          // The level below is 2 × 2 per texel, except along an axis already one texel long.
          const int ny = pyramid.height(l - 1) == 1 ? 1 : 2;
          float sum = 0.0f;
          for (int j = 0; j < ny; ++j)
            for (int i = 0; i < 2; ++i) sum += pyramid.texel(l - 1, 2 * x + i, ny * y + j, c);
          EXPECT_NEAR(pyramid.texel(l, x, y, c), sum / float(2 * ny), tolerance) << l << ' ' << x << ' ' << y;
        }
}

TEST(MipMap, OddSizesShareTheMiddleTexel) {
  // 5 texels to 2: r = 5/2, so texel 0 is (v0 + v1 + ½ v2) / 2.5 and texel 1 (½ v2 + v3 + v4) /
  // 2.5; 2 to 1 is the plain mean. Every level keeps the image's mean.
  rc::scene::LinearImage row{5, 1, 1, {0.0f, 0.25f, 1.0f, 0.5f, 0.75f}};
  const MipMap pyramid(row);
  ASSERT_EQ(pyramid.levels(), 3);
  const float tolerance = 2.0f * kHalf + 1e-6f;
  EXPECT_NEAR(pyramid.texel(1, 0, 0, 0), (0.0f + 0.25f + 0.5f) / 2.5f, tolerance);
  EXPECT_NEAR(pyramid.texel(1, 1, 0, 0), (0.5f + 0.5f + 0.75f) / 2.5f, tolerance);
  EXPECT_NEAR(pyramid.texel(2, 0, 0, 0), 2.5f / 5.0f, tolerance);
  // A 7 × 3 image: its 1 × 1 level is its mean.
  const rc::scene::LinearImage odd = hashed_image(7, 3, 2);
  const MipMap small(odd);
  ASSERT_EQ(small.levels(), 3);  // 7×3, 3×1, 1×1
  for (int c = 0; c < 2; ++c) {
    double mean = 0.0;
    for (size_t i = size_t(c); i < odd.pixels.size(); i += 2) mean += odd.pixels[i];
    EXPECT_NEAR(small.texel(2, 0, 0, c), mean / 21.0, kHalf + 1e-6f);
  }
}

TEST(MipMap, ZeroFootprintAtATexelCentreReadsTheTexel) {
  // Power-of-two sizes, so (x + ½) / w and its product with w are exact: the bilinear weights
  // are 1, 0, 0, 0 and the read is the stored texel itself, bit for bit.
  const MipMap pyramid(hashed_image(8, 4, 4));
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 8; ++x) {
      float v[4];
      pyramid.filter({(x + 0.5f) / 8.0f, (y + 0.5f) / 4.0f}, {0, 0}, {0, 0}, TextureWrap::clamp,
                     TextureWrap::clamp, v);
      for (int c = 0; c < 4; ++c) EXPECT_EQ(v[c], pyramid.texel(0, x, y, c));
    }
  // A footprint exactly 2 texels wide reads level 1 alone, bilinearly: at a level-1 texel
  // centre, that texel.
  float v[4];
  pyramid.filter({1.5f / 4.0f, 0.5f / 2.0f}, {2.0f / 8.0f, 0.0f}, {0.0f, 2.0f / 4.0f}, TextureWrap::clamp,
                 TextureWrap::clamp, v);
  for (int c = 0; c < 4; ++c) EXPECT_EQ(v[c], pyramid.texel(1, 1, 0, c));
}

TEST(MipMap, WrapModes) {
  EXPECT_EQ(rc::scene::wrap_texel(-1, 4, TextureWrap::repeat), 3);
  EXPECT_EQ(rc::scene::wrap_texel(9, 4, TextureWrap::repeat), 1);
  EXPECT_EQ(rc::scene::wrap_texel(-1, 4, TextureWrap::clamp), 0);
  EXPECT_EQ(rc::scene::wrap_texel(9, 4, TextureWrap::clamp), 3);
  // Mirror: … 1 0 | 0 1 2 3 | 3 2 1 0 | 0 1 …
  EXPECT_EQ(rc::scene::wrap_texel(-1, 4, TextureWrap::mirror), 0);
  EXPECT_EQ(rc::scene::wrap_texel(-2, 4, TextureWrap::mirror), 1);
  EXPECT_EQ(rc::scene::wrap_texel(4, 4, TextureWrap::mirror), 3);
  EXPECT_EQ(rc::scene::wrap_texel(6, 4, TextureWrap::mirror), 1);
  EXPECT_EQ(rc::scene::wrap_texel(8, 4, TextureWrap::mirror), 0);
  // Reads past the image's right edge, at texel x's centre shifted by one image width: repeat
  // reads x again, clamp the last texel, mirror texel 7 − x. Wraps apply per axis: t is clamped
  // while s repeats.
  const MipMap pyramid(hashed_image(8, 2, 1));
  for (int x = 0; x < 8; ++x) {
    const rc::Vec2 st(1.0f + (x + 0.5f) / 8.0f, 0.75f);
    float v = 0.0f;
    pyramid.filter(st, {0, 0}, {0, 0}, TextureWrap::repeat, TextureWrap::clamp, &v);
    EXPECT_EQ(v, pyramid.texel(0, x, 1, 0)) << x;
    pyramid.filter(st, {0, 0}, {0, 0}, TextureWrap::clamp, TextureWrap::clamp, &v);
    EXPECT_EQ(v, pyramid.texel(0, 7, 1, 0)) << x;
    pyramid.filter(st, {0, 0}, {0, 0}, TextureWrap::mirror, TextureWrap::clamp, &v);
    EXPECT_EQ(v, pyramid.texel(0, 7 - x, 1, 0)) << x;
  }
  // Between the last texel and the first, repeat blends them half and half.
  float v = 0.0f;
  pyramid.filter({1.0f, 0.25f}, {0, 0}, {0, 0}, TextureWrap::repeat, TextureWrap::clamp, &v);
  EXPECT_NEAR(v, 0.5f * (pyramid.texel(0, 7, 0, 0) + pyramid.texel(0, 0, 0, 0)), 1e-6f);
}

TEST(MipMap, EightBitCodesAreKeptExactly) {
  // Stored as codes, level 0 reads back code / 255 (to float rounding) and every coarser texel
  // is the code nearest the mean below it: within half a code, plus the same rounding.
  rc::scene::LinearImage image = hashed_image(8, 8, 2);
  for (float& v : image.pixels) v = std::round(v * 255.0f) / 255.0f;
  const MipMap pyramid(image, rc::scene::TexelFormat::unorm8);
  EXPECT_EQ(pyramid.format(), rc::scene::TexelFormat::unorm8);
  EXPECT_EQ(pyramid.bytes(), MipMap::bytes_for(8, 8, 2, rc::scene::TexelFormat::unorm8));
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 2; ++c)
        EXPECT_NEAR(pyramid.texel(0, x, y, c), image.pixels[size_t((y * 8 + x) * 2 + c)], 1e-7f);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x)
      for (int c = 0; c < 2; ++c) {
        float sum = 0.0f;
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) sum += pyramid.texel(0, 2 * x + i, 2 * y + j, c);
        EXPECT_NEAR(pyramid.texel(1, x, y, c), sum / 4.0f, 0.5f / 255.0f + 1e-6f);
      }
}

TEST(MipMap, CodesThroughTablesMakeTheSamePyramidAsTheirValues) {
  // An 8-bit image is made into its pyramid straight from its codes and each channel's table of
  // values (an sRGB curve for colour, code / 255 for alpha). That must be the pyramid of the
  // image of those values, texel for texel and bit for bit, in both formats. The sizes are odd
  // and even, and tall enough (70 rows) that rows are filtered in several blocks in parallel.
  for (const auto& [w, h] : {std::pair{70, 70}, std::pair{37, 70}, std::pair{64, 6}})
    for (const rc::scene::TexelFormat format :
         {rc::scene::TexelFormat::half, rc::scene::TexelFormat::unorm8}) {
      rc::scene::CodeImage codes{w, h, 4, {}, {}};
      for (int c = 0; c < 4; ++c)
        for (int k = 0; k < 256; ++k)
          codes.values[size_t(c)][size_t(k)] = c == 3 ? float(k) / 255.0f : std::pow(float(k) / 255.0f, 2.2f);
      rc::scene::LinearImage values{w, h, 4, {}};
      const rc::scene::LinearImage hashed = hashed_image(w, h, 4);
      for (size_t i = 0; i < hashed.pixels.size(); ++i) {
        const auto code = uint8_t(std::lround(hashed.pixels[i] * 255.0f));
        codes.codes.push_back(code);
        values.pixels.push_back(codes.values[i % 4][code]);
      }
      const MipMap from_codes(codes, format), from_values(values, format);
      ASSERT_EQ(from_codes.levels(), from_values.levels());
      for (int l = 0; l < from_codes.levels(); ++l)
        for (int y = 0; y < from_codes.height(l); ++y)
          for (int x = 0; x < from_codes.width(l); ++x)
            for (int c = 0; c < 4; ++c)
              ASSERT_EQ(from_codes.texel(l, x, y, c), from_values.texel(l, x, y, c))
                  << w << "×" << h << " level " << l << " texel " << x << ',' << y << " channel " << c;
    }
}

TEST(MipMap, RefusesAnEmptyImage) {
  EXPECT_THROW(MipMap(rc::scene::LinearImage{0, 4, 3, {}}), std::invalid_argument);
  EXPECT_THROW(MipMap(rc::scene::LinearImage{2, 2, 3, {0.0f}}), std::invalid_argument);
}

TEST(MipMap, BytesForCountsPaddedTiles) {
  // 4 × 4 tiles: 16 × 8 RGB is 8 tiles, 8 × 4 two, then 4 × 2, 2 × 1, 1 × 1 one each; 2 bytes a
  // value as half floats, 1 as codes.
  EXPECT_EQ(MipMap::bytes_for(16, 8, 3), size_t(8 + 2 + 1 + 1 + 1) * 16 * 3 * 2);
  EXPECT_EQ(MipMap::bytes_for(16, 8, 3, rc::scene::TexelFormat::unorm8), size_t(8 + 2 + 1 + 1 + 1) * 16 * 3);
  EXPECT_EQ(MipMap(hashed_image(16, 8, 3)).bytes(), MipMap::bytes_for(16, 8, 3));
}

class TexturePlans : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("gilt_mip_map_" + std::to_string(::getpid()) + "_" + info->name());
    fs::create_directories(dir_);
    ::setenv("GILT_TEXTURE_CACHE", (dir_ / "cache").c_str(), 1);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  /// Writes an 8-bit RGB image of the hashed values, as a binary PPM; returns its path.
  std::string ppm(const std::string& name, int width, int height) {
    const rc::scene::LinearImage image = hashed_image(width, height, 3);
    const fs::path path = dir_ / name;
    std::ofstream out(path, std::ios::binary);
    out << "P6\n" << width << ' ' << height << "\n255\n";
    for (float v : image.pixels) out.put(char(std::lround(v * 255.0f)));
    return path.string();
  }
  fs::path dir_;
};

TEST_F(TexturePlans, PyramidsAgreeWithOpenImageIOsTextureSystem) {
  // The same 64 × 64 sRGB image through both plans: in memory (budget unlimited) and through
  // OpenImageIO's TextureSystem (budget 0). Both read half floats of the same linear values,
  // box-filtered into the same levels (OpenImageIO's copy is made with maketx's box filter),
  // blend the same two levels with the same weights and read each bilinearly, so they may
  // differ by a half's rounding of each (≤ 2⁻¹¹ of values ≤ 1) and OpenImageIO's own
  // arithmetic in its filter; 1/255, one step of an 8-bit output, bounds both with room. The
  // footprints are isotropic (square, axis-aligned): for elongated ones OpenImageIO takes
  // several probes along the long axis at the level of the short one, where trilinear reads
  // the level of the long axis, and the two differ by design.
  const std::string file = ppm("hashed.ppm", 64, 64);
  const std::vector<rc::scene::TextureImage> images{{file, true, TextureWrap::repeat, TextureWrap::repeat},
                                                    {file, true, TextureWrap::clamp, TextureWrap::mirror}};
  const rc::scene::TextureSet memory(images, size_t(1) << 40);
  const rc::scene::TextureSet cache(images, 0);
  ASSERT_EQ(memory.plan(), rc::scene::TexturePlan::in_memory);
  ASSERT_EQ(cache.plan(), rc::scene::TexturePlan::oiio_cache);
  EXPECT_EQ(memory.file_count(), 1u);  // two images of one file and role share one pyramid
  constexpr float kCode = 1.0f / 255.0f;
  for (const float texels : {0.0f, 1.0f, 2.5f, 7.0f}) {
    const float d = texels / 64.0f;
    float worst = 0.0f;
    for (int image = 0; image < 2; ++image)
      for (int k = 0; k < 400; ++k) {
        // Points over [−0.25, 1.25]² in a fixed low-discrepancy pattern, past the edges too.
        const rc::Vec2 st(-0.25f + 1.5f * std::fmod(0.5f + k * 0.618034f, 1.0f),
                          -0.25f + 1.5f * (k + 0.5f) / 400.0f);
        const rc::scene::Texel a = memory.lookup(image, st, {d, 0.0f}, {0.0f, d});
        const rc::scene::Texel b = cache.lookup(image, st, {d, 0.0f}, {0.0f, d});
        worst = std::max({worst, std::fabs(a.rgb.r - b.rgb.r), std::fabs(a.rgb.g - b.rgb.g),
                          std::fabs(a.rgb.b - b.rgb.b)});
      }
    EXPECT_LE(worst, kCode) << "footprint " << texels << " texels";
  }
}

TEST_F(TexturePlans, PlanFollowsTheBudgetAndLoadIsTimed) {
  const std::string file = ppm("small.ppm", 16, 16);
  const std::vector<rc::scene::TextureImage> images{{file, true}, {file, false}};
  // Colour and data reads of one file are two pyramids: half floats for the colour, the 8-bit
  // codes for the data.
  const size_t bytes = MipMap::bytes_for(16, 16, 3, rc::scene::TexelFormat::half) +
                       MipMap::bytes_for(16, 16, 3, rc::scene::TexelFormat::unorm8);
  const rc::scene::TextureSet fits(images, bytes);
  EXPECT_EQ(fits.plan(), rc::scene::TexturePlan::in_memory);
  EXPECT_EQ(fits.file_count(), 2u);
  EXPECT_EQ(fits.pyramid_bytes(), bytes);
  EXPECT_GT(fits.load_seconds(), 0.0);
  const rc::scene::TextureSet over(images, bytes - 1);
  EXPECT_EQ(over.plan(), rc::scene::TexturePlan::oiio_cache);
  // The environment sets the default budget.
  ::setenv("GILT_TEXTURE_MEMORY_MB", "0", 1);
  EXPECT_EQ(rc::scene::texture_memory_budget(), 0u);
  EXPECT_EQ(rc::scene::TextureSet(images).plan(), rc::scene::TexturePlan::oiio_cache);
  ::setenv("GILT_TEXTURE_MEMORY_MB", "lots", 1);
  EXPECT_THROW(rc::scene::texture_memory_budget(), rc::InputError);
  ::unsetenv("GILT_TEXTURE_MEMORY_MB");
  EXPECT_EQ(rc::scene::texture_memory_budget(), size_t(4) << 30);
}

TEST_F(TexturePlans, UnreadableFilesAreInputErrorsNamingThem) {
  // A missing file, and a file that is not an image, under both plans.
  const std::string missing = (dir_ / "missing.png").string();
  const std::string garbage = (dir_ / "garbage.png").string();
  std::ofstream(garbage) << "not a PNG";
  const std::string good = ppm("good.ppm", 4, 4);
  for (const std::string& bad : {missing, garbage})
    for (const size_t budget : {size_t(1) << 40, size_t(0)}) {
      try {
        rc::scene::TextureSet set({{good, true}, {bad, true}}, budget);
        ADD_FAILURE() << bad << " was accepted";
      } catch (const rc::InputError& e) {
        EXPECT_NE(std::string(e.what()).find(fs::path(bad).filename().string()), std::string::npos)
            << e.what();
      }
    }
}

TEST(MipMap, WrittenAndReadBackBitForBit) {
  // A pyramid written and read back holds the same texels; a stream of something else, cut
  // short, or longer than its header implies, is not taken for a pyramid.
  for (const rc::scene::TexelFormat format : {rc::scene::TexelFormat::half, rc::scene::TexelFormat::unorm8}) {
    const MipMap pyramid(hashed_image(13, 6, 3), format);
    std::stringstream stream;
    ASSERT_TRUE(pyramid.write(stream));
    const std::string bytes = stream.str();
    std::istringstream whole(bytes);
    const std::optional<MipMap> back = MipMap::read(whole);
    ASSERT_TRUE(back.has_value());
    ASSERT_EQ(back->levels(), pyramid.levels());
    EXPECT_EQ(back->format(), format);
    for (int l = 0; l < pyramid.levels(); ++l)
      for (int y = 0; y < pyramid.height(l); ++y)
        for (int x = 0; x < pyramid.width(l); ++x)
          for (int c = 0; c < 3; ++c) ASSERT_EQ(back->texel(l, x, y, c), pyramid.texel(l, x, y, c));
    std::istringstream cut(bytes.substr(0, bytes.size() - 1)), longer(bytes + "x"), other("P6\n4 4\n255\n");
    EXPECT_FALSE(MipMap::read(cut).has_value());
    EXPECT_FALSE(MipMap::read(longer).has_value());
    EXPECT_FALSE(MipMap::read(other).has_value());
  }
}

TEST_F(TexturePlans, LargePyramidsAreKeptInTheCacheFolderAndReadBack) {
  // A 1024 × 512 image's pyramid (over 1 MiB) is written to the cache folder by the first load
  // and read back by the second, which then reads the same values. A cached file spoilt (cut
  // short) is passed over: the image is decoded again and the file made whole. A small image
  // is not cached.
  const std::string large = ppm("large.ppm", 1024, 512), small = ppm("small.ppm", 16, 16);
  const std::vector<rc::scene::TextureImage> images{{large, true}, {small, true}};
  const auto cached_files = [&] {
    std::vector<fs::path> files;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir_ / "cache", ec))
      if (entry.path().extension() == ".pyramid") files.push_back(entry.path());
    return files;
  };
  const auto lookups = [](const rc::scene::TextureSet& set) {
    std::vector<float> values;
    for (int k = 0; k < 200; ++k)
      for (const float d : {0.0f, 1.0f / 256.0f}) {
        const rc::Vec2 st(std::fmod(0.5f + k * 0.618034f, 1.0f), (k + 0.5f) / 200.0f);
        const rc::scene::Texel t = set.lookup(0, st, {d, 0.0f}, {0.0f, d});
        values.insert(values.end(), {t.rgb.r, t.rgb.g, t.rgb.b});
      }
    return values;
  };
  const rc::scene::TextureSet first(images);
  EXPECT_EQ(first.cached_file_count(), 0u);
  const std::vector<fs::path> files = cached_files();
  ASSERT_EQ(files.size(), 1u);  // the large image's only
  EXPECT_EQ(fs::file_size(files[0]), 32 + MipMap::bytes_for(1024, 512, 3));
  const rc::scene::TextureSet second(images);
  EXPECT_EQ(second.cached_file_count(), 1u);
  EXPECT_EQ(lookups(second), lookups(first));

  fs::resize_file(files[0], fs::file_size(files[0]) / 2);
  const rc::scene::TextureSet third(images);
  EXPECT_EQ(third.cached_file_count(), 0u);
  EXPECT_EQ(lookups(third), lookups(first));
  EXPECT_EQ(fs::file_size(files[0]), 32 + MipMap::bytes_for(1024, 512, 3));
}

TEST_F(TexturePlans, TheCacheKeepsWithinItsBudgetDroppingTheLeastRecentlyUsed) {
  // Two images whose pyramids (about 4.2 MB each) fit the cache one at a time (GILT_TEXTURE_CACHE_MB=6):
  // loading the second removes the first's, and loading the first again removes the second's.
  // A budget of 0 keeps nothing; one that is not a number is an input error.
  const std::string a = ppm("a.ppm", 1024, 512), b = ppm("b.ppm", 512, 1024);
  const auto cached = [&] {
    size_t n = 0;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(dir_ / "cache", ec))
      n += entry.path().extension() == ".pyramid";
    return n;
  };
  ::setenv("GILT_TEXTURE_CACHE_MB", "6", 1);
  EXPECT_EQ(rc::scene::texture_cache_budget(), size_t(6) << 20);
  EXPECT_EQ(rc::scene::TextureSet({{a, true}}).cached_file_count(), 0u);
  EXPECT_EQ(cached(), 1u);
  EXPECT_EQ(rc::scene::TextureSet({{a, true}}).cached_file_count(), 1u);
  EXPECT_EQ(rc::scene::TextureSet({{b, true}}).cached_file_count(), 0u);
  EXPECT_EQ(cached(), 1u);
  EXPECT_EQ(rc::scene::TextureSet({{b, true}}).cached_file_count(), 1u);
  EXPECT_EQ(rc::scene::TextureSet({{a, true}}).cached_file_count(), 0u);  // a's was dropped for b's
  ::setenv("GILT_TEXTURE_CACHE_MB", "0", 1);
  fs::remove_all(dir_ / "cache");
  EXPECT_EQ(rc::scene::TextureSet({{a, true}}).cached_file_count(), 0u);
  EXPECT_EQ(cached(), 0u);
  ::setenv("GILT_TEXTURE_CACHE_MB", "some", 1);
  EXPECT_THROW(rc::scene::texture_cache_budget(), rc::InputError);
  ::unsetenv("GILT_TEXTURE_CACHE_MB");
}

}  // namespace
}  // namespace gilt
