// Image files: round trips within each format's precision, and atomic, tidy writes.

#include "raytrace_core/util/image_io.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <string>

#include "raytrace_core/util/error.h"

namespace gilt::raytrace_core::util {
namespace {

namespace fs = std::filesystem;

/// A fresh directory per test under the system temporary directory, removed afterwards.
class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    static std::atomic<int> counter{0};
    dir_ = fs::temp_directory_path() /
           ("gilt-test-image-io-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  /// Names of everything in the test directory, hidden files included.
  std::set<std::string> listing() const {
    std::set<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.insert(entry.path().filename().string());
    return names;
  }
  static std::string contents(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  }

  fs::path dir_;
};

/// A w×h image of values uniform in [lo, hi) from a fixed seed.
Image noise(int w, int h, float lo, float hi, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> value(lo, hi);
  Image image{w, h, {}};
  for (int i = 0; i < w * h; ++i) image.pixels.emplace_back(value(rng), value(rng), value(rng));
  return image;
}

/// The sRGB transfer function, written out independently of the library's.
double srgb_encode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }

TEST(ImagePath, RecognisesSupportedExtensions) {
  EXPECT_TRUE(is_supported_image_path("out.exr"));
  EXPECT_TRUE(is_supported_image_path("dir/out.hdr"));
  EXPECT_TRUE(is_supported_image_path("OUT.PNG"));
  EXPECT_FALSE(is_supported_image_path("out.jpg"));
  EXPECT_FALSE(is_supported_image_path("out"));
  EXPECT_FALSE(is_supported_image_path("out.exr/"));
}

TEST_F(ImageIoTest, ExrRoundTripIsBitExact) {
  Image image = noise(7, 5, -2.0f, 1000.0f, 1);
  image.pixels[0] = Rgb(1e-30f, 3e38f, 0.1f);  // far outside half-float range
  image.pixels[1] = Rgb(std::numeric_limits<float>::denorm_min(), -0.0f, 65504.5f);
  write_image(path("a.exr"), image, 3.0f);  // exposure applies to PNG only
  const Image back = read_image(path("a.exr"));
  ASSERT_EQ(back.width, 7);
  ASSERT_EQ(back.height, 5);
  ASSERT_EQ(back.pixels.size(), image.pixels.size());
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_EQ(std::bit_cast<uint32_t>(back.pixels[i][c]), std::bit_cast<uint32_t>(image.pixels[i][c]))
          << "pixel " << i << " channel " << c << ": " << back.pixels[i][c] << " vs " << image.pixels[i][c];
    }
  }
}

TEST_F(ImageIoTest, NonFiniteValuesAreWrittenAsBlack) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const Image image{2, 1, {Rgb(nan, 1.0f, -inf), Rgb(inf, 0.5f, 0.25f)}};
  for (const char* name : {"n.exr", "n.hdr", "n.png"}) {
    write_image(path(name), image);
    const Image back = read_image(path(name));
    EXPECT_EQ(back.pixels[0].r, 0.0f) << name;
    EXPECT_EQ(back.pixels[0].b, 0.0f) << name;
    EXPECT_EQ(back.pixels[1].r, 0.0f) << name;
    EXPECT_NEAR(back.pixels[0].g, 1.0f, 1e-2f) << name;
  }
}

// Radiance RGBE stores one shared exponent e, chosen so that the largest channel M satisfies
// 2^(e−1) ≤ M < 2^e, and an 8-bit mantissa per channel in units of 2^(e−8). Truncating (or
// rounding) to that unit errs by less than 2^(e−8) per channel. Relative to M this is < 2⁻⁸ when
// M is just below 2^e but up to 2⁻⁷ just above 2^(e−1): "1/256 relative" holds only on average,
// so the test uses the exact absolute bound 2^(e−8), computed per pixel.
TEST_F(ImageIoTest, HdrRoundTripWithinRgbePrecision) {
  Image image = noise(16, 9, 0.0f, 1.0f, 2);
  for (size_t i = 0; i < image.pixels.size(); ++i) image.pixels[i] *= std::exp2(float(int(i % 41) - 20));
  write_image(path("a.hdr"), image);
  const Image back = read_image(path("a.hdr"));
  ASSERT_EQ(back.width, 16);
  ASSERT_EQ(back.height, 9);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    int e = 0;
    std::frexp(image.pixels[i].max_component(), &e);
    const float unit = std::ldexp(1.0f, e - 8);
    for (int c = 0; c < 3; ++c) {
      EXPECT_LE(std::fabs(back.pixels[i][c] - image.pixels[i][c]), unit) << "pixel " << i << " channel " << c;
    }
  }
}

// 8-bit sRGB keeps 256 code values: after decoding, a value must re-encode to within half a code
// of the original (plus float slack), and values outside [0, 1] clamp to the ends.
TEST_F(ImageIoTest, PngRoundTripWithinHalfAnSrgbStep) {
  Image image = noise(11, 6, 0.0f, 1.0f, 3);
  image.pixels[0] = Rgb(-0.5f, 2.0f, 0.0031308f);
  write_image(path("a.png"), image);
  const Image back = read_image(path("a.png"));
  ASSERT_EQ(back.width, 11);
  ASSERT_EQ(back.height, 6);
  for (size_t i = 0; i < image.pixels.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double expected = srgb_encode(std::clamp(image.pixels[i][c], 0.0f, 1.0f)) * 255.0;
      EXPECT_NEAR(srgb_encode(back.pixels[i][c]) * 255.0, expected, 0.5 + 1e-3)
          << "pixel " << i << " channel " << c;
    }
  }
  EXPECT_EQ(back.pixels[0].r, 0.0f);
  EXPECT_EQ(back.pixels[0].g, 1.0f);
}

TEST_F(ImageIoTest, PngExposureScalesByPowersOfTwo) {
  const Image image{3, 1, {Rgb(0.25f), Rgb(0.5f), Rgb(0.02f)}};
  write_image(path("up.png"), image, 2.0f);
  write_image(path("down.png"), image, -1.0f);
  const Image up = read_image(path("up.png")), down = read_image(path("down.png"));
  for (int i = 0; i < 3; ++i) {
    const double v = image.pixels[i].r;
    EXPECT_NEAR(srgb_encode(up.pixels[i].r) * 255.0, srgb_encode(std::min(4.0 * v, 1.0)) * 255.0, 0.501) << i;
    EXPECT_NEAR(srgb_encode(down.pixels[i].r) * 255.0, srgb_encode(0.5 * v) * 255.0, 0.501) << i;
  }
  EXPECT_EQ(up.pixels[0].r, 1.0f);  // 0.25 · 2² is exactly white
}

TEST_F(ImageIoTest, SuccessfulWritesLeaveNoTemporaries) {
  const Image image = noise(4, 4, 0.0f, 1.0f, 4);
  write_image(path("a.exr"), image);
  write_image(path("a.hdr"), image);
  write_image(path("a.png"), image);
  write_image(path("a.exr"), noise(4, 4, 0.0f, 1.0f, 5));  // replacing an existing file
  EXPECT_EQ(listing(), (std::set<std::string>{"a.exr", "a.hdr", "a.png"}));
  EXPECT_EQ(read_image(path("a.exr")).pixels[0], noise(4, 4, 0.0f, 1.0f, 5).pixels[0]);
}

TEST_F(ImageIoTest, UnsupportedExtensionThrowsAndCreatesNothing) {
  EXPECT_THROW(write_image(path("a.jpg"), noise(2, 2, 0.0f, 1.0f, 6)), InputError);
  EXPECT_THROW(write_image(path("noext"), noise(2, 2, 0.0f, 1.0f, 6)), InputError);
  EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIoTest, MissingDirectoryThrowsAndCreatesNothing) {
  EXPECT_THROW(write_image(path("missing/a.exr"), noise(2, 2, 0.0f, 1.0f, 7)), InputError);
  EXPECT_TRUE(listing().empty());
}

// Renaming a file over a directory fails after the temporary is complete: the cleanup path.
TEST_F(ImageIoTest, DestinationThatIsADirectoryIsLeftAlone) {
  fs::create_directory(path("taken.png"));
  std::ofstream(path("taken.png/keep.txt")) << "keep";
  try {
    write_image(path("taken.png"), noise(2, 2, 0.0f, 1.0f, 8));
    ADD_FAILURE() << "wrote over a directory";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path("taken.png")), std::string::npos) << e.what();
  }
  EXPECT_EQ(listing(), std::set<std::string>{"taken.png"});
  EXPECT_EQ(contents(path("taken.png/keep.txt")), "keep");
}

TEST_F(ImageIoTest, FailedEncodeKeepsTheExistingFile) {
  for (const char* name : {"a.exr", "a.hdr", "a.png"}) {
    write_image(path(name), noise(3, 3, 0.0f, 1.0f, 9));
    const std::string before = contents(path(name));
    EXPECT_THROW(write_image(path(name), Image{0, 0, {}}), InputError) << name;  // OIIO rejects 0×0
    EXPECT_EQ(contents(path(name)), before) << name;
  }
  EXPECT_EQ(listing(), (std::set<std::string>{"a.exr", "a.hdr", "a.png"}));
}

/// Caps the size of files this process may write, as a full disk would, for its lifetime.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    previous_handler_ = std::signal(SIGXFSZ, SIG_IGN);  // make write() fail with EFBIG instead
    getrlimit(RLIMIT_FSIZE, &previous_);
    rlimit limit = previous_;
    limit.rlim_cur = std::min(bytes, previous_.rlim_max);
    setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &previous_);
    std::signal(SIGXFSZ, previous_handler_);
  }

 private:
  rlimit previous_{};
  void (*previous_handler_)(int) = nullptr;
};

// A write that fails half-way through the file (here: the file-size limit, as with a full disk)
// must leave the old destination intact and remove its partial temporary.
TEST_F(ImageIoTest, WriteFailingMidFileKeepsTheExistingFile) {
  const Image big = noise(256, 256, 0.0f, 1.0f, 10);  // noise does not compress below 8 KiB
  for (const char* name : {"a.exr", "a.hdr", "a.png"}) {
    write_image(path(name), noise(2, 2, 0.0f, 1.0f, 11));
    const std::string before = contents(path(name));
    {
      FileSizeLimit limit(8192);
      EXPECT_THROW(write_image(path(name), big), InputError) << name;
    }
    EXPECT_EQ(contents(path(name)), before) << name;
  }
  EXPECT_EQ(listing(), (std::set<std::string>{"a.exr", "a.hdr", "a.png"}));
}

TEST_F(ImageIoTest, ReadErrorsNameTheFile) {
  std::ofstream(path("text.png")) << "not an image";
  for (const std::string& file : {path("text.png"), path("absent.exr")}) {
    try {
      read_image(file);
      ADD_FAILURE() << "read " << file;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    }
  }
}

// One channel reads as grey. A float PFM ("Pf": one channel, bottom row first) is simple enough to
// write by hand.
TEST_F(ImageIoTest, ReadsOneChannelAsGrey) {
  {
    std::ofstream out(path("grey.pfm"), std::ios::binary);
    out << "Pf\n2 1\n-1.0\n";  // negative scale: little-endian
    const float values[2] = {0.25f, 3.5f};
    out.write(reinterpret_cast<const char*>(values), sizeof(values));
  }
  const Image image = read_image(path("grey.pfm"));
  ASSERT_EQ(image.pixels.size(), 2u);
  EXPECT_EQ(image.pixels[0], Rgb(0.25f));
  EXPECT_EQ(image.pixels[1], Rgb(3.5f));
}

// Four channels read as the first three, as stored (alpha does not darken the colour), and 8-bit
// data is decoded from sRGB. An uncompressed 32-bit TGA is simple enough to write by hand.
TEST_F(ImageIoTest, ReadsTheFirstThreeOfFourChannels) {
  {
    std::ofstream out(path("rgba.tga"), std::ios::binary);
    const uint8_t header[18] = {0, 0, 2, 0, 0, 0, 0, 0, 0, 0, 0, 0, 2, 0, 1, 0, 32, 8 | 0x20};
    const uint8_t bgra[8] = {255, 0, 128, 128, /**/ 0, 255, 0, 0};
    out.write(reinterpret_cast<const char*>(header), sizeof(header));
    out.write(reinterpret_cast<const char*>(bgra), sizeof(bgra));
  }
  const Image image = read_image(path("rgba.tga"));
  ASSERT_EQ(image.pixels.size(), 2u);
  const float mid = static_cast<float>(std::pow((128.0 / 255.0 + 0.055) / 1.055, 2.4));
  EXPECT_NEAR(image.pixels[0].r, mid, 1e-6f);
  EXPECT_EQ(image.pixels[0].g, 0.0f);
  EXPECT_EQ(image.pixels[0].b, 1.0f);
  EXPECT_EQ(image.pixels[1], Rgb(0.0f, 1.0f, 0.0f));
}

}  // namespace
}  // namespace gilt::raytrace_core::util
