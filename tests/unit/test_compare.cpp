// `gilt compare` end to end: the report's files and metrics, the reference cache, bad input, and
// the page itself in headless Chromium (a screenshot in which the test finds the reference image
// pixel for pixel and every method's line in the plot).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "raytrace_core/util/image_io.h"

#include "tests/support/cli_run.h"

namespace fs = std::filesystem;
namespace rc = gilt::raytrace_core;

namespace {

using Result = gilt::test::CliResult;
using gilt::test::slurp;

class Compare : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gilt-compare-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& command) {
    return gilt::test::run_command("GILT_CACHE_DIR='" + (dir_ / "cache").string() + "' " + command, dir_);
  }
  Result gilt(const std::string& args) { return run(std::string("'") + GILT_BINARY_PATH + "' " + args); }

  /// A small report: two methods, two budgets (0.3 and 1.5 s), 32 × 32.
  fs::path small_report(const std::string& name) {
    const fs::path report = dir_ / name;
    const Result r = gilt("compare cornell --methods path,radiosity --budgets 0.3,1.5 --reference-time 1 --width 32 "
                          "--height 32 -q -o '" + report.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    return report;
  }

  /// index.html of `report` as headless Chromium shows it in a window `width` × `height`.
  rc::util::Image screenshot(const fs::path& report, int width, int height) {
    const fs::path shot = dir_ / (report.filename().string() + "-shot.png");
    const Result r = run("chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --force-device-scale-factor=1 "
                         "--user-data-dir='" + (dir_ / "profile").string() + "' --window-size=" + std::to_string(width) +
                         "," + std::to_string(height) + " --screenshot='" + shot.string() + "' 'file://" +
                         (report / "index.html").string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    return rc::util::read_image(shot.string());
  }

  fs::path dir_;
};

}  // namespace

TEST_F(Compare, WritesReportMetricsAndImages) {
  const fs::path report = small_report("report");
  ASSERT_TRUE(fs::exists(report / "index.html"));
  const nlohmann::json j = nlohmann::json::parse(slurp(report / "metrics.json"));
  ASSERT_EQ(j["entries"].size(), 4u);
  EXPECT_EQ(j["sampler"], "sobol");  // the default
  // The path-traced reference's noise, from its two halves, is taken out of the squared errors.
  EXPECT_TRUE(j["errors_noise_corrected"].get<bool>());
  const double floor = j["reference_relmse_floor"].get<double>();
  EXPECT_GT(floor, 0.0);
  EXPECT_GT(j["reference_mse_floor"].get<double>(), 0.0);
  for (const auto& e : j["entries"]) {
    for (const char* key : {"image_exr", "image_png", "error_png"})
      EXPECT_TRUE(fs::exists(report / e[key].get<std::string>())) << e[key];
    EXPECT_GT(e["seconds"].get<double>(), 0.0);
    // Corrected, a relMSE may fall below 0 within its standard error, no further (4 of them).
    const double relmse = e["relmse"].get<double>(), stderr_ = e["relmse_stderr"].get<double>();
    EXPECT_GT(stderr_, 0.0);
    EXPECT_GT(relmse, -4.0 * stderr_);
    EXPECT_NEAR(e["relmse_measured"].get<double>() - floor, relmse, 1e-9 * (1.0 + std::abs(relmse)));
    EXPECT_GE(e["rmse"].get<double>(), 0.0);
    EXPECT_LE(e["rmse"].get<double>(), e["rmse_measured"].get<double>());
    if (e["method"] == "radiosity") {
      EXPECT_TRUE(e["object_space_error"].is_number());
      // No shot starts that would end past the budget, and under AddressSanitizer with another
      // test beside it meshing and direct light can take all of 0.3 s (0 shots seen; 8 alone):
      // shots are required at the larger budget only.
      EXPECT_GE(e["shots"].get<int>(), 0);
      if (e["budget_seconds"].get<double>() > 1.0) {
        EXPECT_GT(e["shots"].get<int>(), 0);
      }
    } else {
      EXPECT_TRUE(e["object_space_error"].is_null());
      EXPECT_GT(e["spp_or_iterations"].get<int>(), 0);
    }
  }
  const std::string csv = slurp(report / "metrics.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 5);
  const std::string html = slurp(report / "index.html");
  EXPECT_NE(html.find("data-method=\"path\""), std::string::npos);
  EXPECT_NE(html.find("data-method=\"radiosity\""), std::string::npos);
  EXPECT_NE(html.find("id=\"noise-floor\""), std::string::npos);  // the floor, drawn in the plot
  // Offline: nothing is fetched from elsewhere.
  EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org/2000/svg"));
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

TEST_F(Compare, SecondRunReusesTheCachedReference) {
  small_report("first");
  const std::string first = nlohmann::json::parse(slurp(dir_ / "first/metrics.json"))["reference"];
  EXPECT_EQ(first.find("cached"), std::string::npos) << first;
  small_report("second");
  const std::string second = nlohmann::json::parse(slurp(dir_ / "second/metrics.json"))["reference"];
  EXPECT_NE(second.find("cached"), std::string::npos) << second;
  EXPECT_EQ(slurp(dir_ / "first/images/reference.exr"), slurp(dir_ / "second/images/reference.exr"));
}

// The reference's method: auto renders it with SPPM where the scene has caustics, which a path
// tracer finds only by chance, and with the path tracer elsewhere; either way its noise is
// measured from two halves and taken out of the errors.
TEST_F(Compare, ReferenceMethodFollowsTheScenesCaustics) {
  const auto reference_of = [&](const std::string& scene, const std::string& extra) {
    const fs::path report = dir_ / (extra.empty() ? scene : scene + "-forced");
    const Result r = gilt("compare " + scene + " --methods path --budgets 0.2 --reference-time 1 --width 16 --height 16 " +
                          extra + " -q -o '" + report.string() + "'");
    EXPECT_EQ(r.code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(slurp(report / "metrics.json"));
    EXPECT_TRUE(j["errors_noise_corrected"].get<bool>()) << scene << extra;
    return j["reference"].get<std::string>();
  };
  EXPECT_EQ(reference_of("cornell-caustics", "").rfind("SPPM, ", 0), 0u);
  EXPECT_EQ(reference_of("cornell", "").rfind("path tracer, ", 0), 0u);
  EXPECT_EQ(reference_of("cornell-caustics", "--reference-method path").rfind("path tracer, ", 0), 0u);
}

TEST_F(Compare, BadInputExitsTwo) {
  const std::string out = (dir_ / "r").string();
  const fs::path small = dir_ / "small.exr";
  rc::util::write_image(small.string(), rc::util::Image{4, 4, std::vector<rc::Rgb>(16, rc::Rgb(0.5f))});
  const std::pair<std::string, std::string> cases[] = {
      {"compare cornell --methods path,magic -o " + out, "magic"},
      {"compare cornell --budgets 1,-2 -o " + out, "--budgets"},
      {"compare cornell --budgets 1,x -o " + out, "--budgets"},
      {"compare cornell --reference " + (dir_ / "none.exr").string() + " -o " + out, "none.exr"},
      {"compare cornell --reference " + small.string() + " --width 8 --height 8 -o " + out, "does not match"},
      {"compare cornell -o " + (dir_ / "no/such/folder").string(), "does not exist"},
      {"compare cornell --reference-method magic -o " + out, "--reference-method"},
      {"compare cornell --reference " + small.string() + " --reference-method sppm -o " + out, "excludes"},
  };
  for (const auto& [args, message] : cases) {
    const Result r = gilt(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << args << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}

namespace {

/// Whether `image`, enlarged by the whole factor `scale`, appears as an exact block in `page`
/// (each image pixel's centre compared; pixelated scaling keeps the values).
bool shows_block(const rc::util::Image& page, const rc::util::Image& image, int scale) {
  auto at = [&](int x, int y) { return page.pixels[size_t(y) * page.width + x]; };
  const int w = image.width * scale, h = image.height * scale;
  for (int y = 0; y + h <= page.height; ++y)
    for (int x = 0; x + w <= page.width; ++x) {
      if (!(at(x, y) == image.pixels[0])) continue;
      bool all = true;
      for (int j = 0; j < image.height && all; ++j)
        for (int i = 0; i < image.width && all; ++i)
          all = at(x + i * scale + scale / 2, y + j * scale + scale / 2) == image.pixels[size_t(j) * image.width + i];
      if (all) return true;
    }
  return false;
}

}  // namespace

// The page in a real browser. Chromium from Debian renders index.html headless to a PNG; the test
// then finds (1) the reference image, shown enlarged by a whole factor with pixelated scaling, as
// an exact block of the screenshot, and (2) each method's line colour in the plot. Without
// Chromium the test is skipped, unless GILT_REQUIRE_CHROMIUM is set (CI sets it).
TEST_F(Compare, PageShowsImagesAndPlotInChromium) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) {
    if (std::getenv("GILT_REQUIRE_CHROMIUM")) FAIL() << "chromium is not installed";
    GTEST_SKIP() << "chromium is not installed";
  }
  const fs::path report = small_report("report");
  const rc::util::Image page = screenshot(report, 1200, 1600);
  ASSERT_GT(page.width, 0);
  const rc::util::Image ref = rc::util::read_image((report / "images/reference.png").string());
  ASSERT_EQ(ref.width, 32);
  const int scale = 192 / 32;  // report.cpp: enlarged to about 192 pixels by a whole factor

  // (1) The reference image: a block where every screenshot pixel equals its source pixel.
  EXPECT_TRUE(shows_block(page, ref, scale)) << "the reference image was not found in the screenshot";

  // (2) The plot: pixels of each method's line colour (path #0072B2, radiosity #CC79A7).
  const rc::util::Image swatch = [&] {
    // The same colours through the same PNG decoding as the screenshot.
    const fs::path file = dir_ / "swatch.png";
    auto linear = [](float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); };
    rc::util::write_image(file.string(), rc::util::Image{2, 1, {rc::Rgb(linear(0 / 255.f), linear(114 / 255.f), linear(178 / 255.f)),
                                                    rc::Rgb(linear(204 / 255.f), linear(121 / 255.f), linear(167 / 255.f))}});
    return rc::util::read_image(file.string());
  }();
  for (int m = 0; m < 2; ++m) {
    size_t count = 0;
    for (const rc::Rgb& p : page.pixels) count += p == swatch.pixels[size_t(m)];
    EXPECT_GT(count, 100u) << (m == 0 ? "path" : "radiosity") << " line not found in the plot";
  }
}

// On a laptop's 1,280-pixel-wide window, five 256 × 256 images of a method do not fit on one line:
// the row wraps, and every image is still shown whole at its own size (found pixel for pixel in
// the screenshot, so none is cut off at the window's edge or hidden past it).
TEST_F(Compare, PageFitsALaptopScreen) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) {
    if (std::getenv("GILT_REQUIRE_CHROMIUM")) FAIL() << "chromium is not installed";
    GTEST_SKIP() << "chromium is not installed";
  }
  const fs::path report = dir_ / "wide";
  const Result r = gilt("compare cornell --methods path --budgets 0.05,0.1,0.2,0.4,0.8 --reference-time 0.5 "
                        "--width 256 --height 256 -q -o '" + report.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  const rc::util::Image page = screenshot(report, 1280, 2600);
  ASSERT_EQ(page.width, 1280);
  for (const char* budget : {"0.05s", "0.1s", "0.2s", "0.4s", "0.8s"}) {
    const rc::util::Image image = rc::util::read_image((report / "images" / ("path_" + std::string(budget) + ".png")).string());
    ASSERT_EQ(image.width, 256);
    EXPECT_TRUE(shows_block(page, image, 1)) << "the " << budget << " image is not shown whole at 1,280 pixels";
  }
}
