// Truncated and corrupted files through every loader, in-process: the deterministic cousin of
// the fuzz targets (tests/fuzz/), run on every CI build.
//
// Each valid seed file of tests/fuzz/corpus/ is cut at 128 points (so mid-number, mid-line,
// mid-header and mid-chunk) and has single bytes replaced at 128 points with values that break
// parsers (NUL, 0xff, a quote, a brace, a digit, a minus, a newline). Every variant must either
// load and commit (a prefix may be a valid file) or throw InputError whose message names the
// file: any other exception would make the command line exit 1 ("internal error") instead of 2.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "raytrace_core/util/error.h"
#include "raytrace_core/io/scene_io.h"
#include "tests/stress/bad_files.h"
#include "tests/stress/stress_support.h"

namespace fs = std::filesystem;
namespace rc = gilt::raytrace_core;

namespace {

class Loaders : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gilt-stress-loaders-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    for (const auto& [name, text] : gilt::stress::kSideFiles) std::ofstream(dir_ / name) << text;
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Loads `bytes` as <dir>/<name>; returns "" when it loaded, else the message. Fails the test
  /// on any exception but InputError, and on a message not naming the file.
  std::string load(const std::string& bytes, const std::string& name, const std::string& what) {
    const fs::path path = dir_ / name;
    {
      std::ofstream out(path, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), std::streamsize(bytes.size()));
    }
    // The OBJ seed's MTL half sits after "#---mtl---"; the loader just sees a comment line, and
    // "mtllib scene.mtl" names a file that is absent (a warning, not an error).
    try {
      const rc::scene::Scene scene = rc::io::load_scene(path.string());
      EXPECT_TRUE(scene.committed()) << what;
      return "";
    } catch (const rc::InputError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(name), std::string::npos) << what << ": " << message;
      return message;
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ": " << typeid(e).name()
                    << " escaped the loader (exit code 1, not 2): " << e.what();
    } catch (...) {
      ADD_FAILURE() << what << ": a non-standard exception escaped the loader";
    }
    return "?";
  }

  fs::path dir_;
};

// Every bad file of tests/stress/bad_files.h: InputError naming the file and the problem.
TEST_F(Loaders, BadFilesThrowInputErrorNamingFileAndProblem) {
  for (const gilt::stress::BadFile& f : gilt::stress::bad_files()) {
    const std::string message = load(f.bytes, f.name, f.name);
    EXPECT_NE(message, "") << f.name << " loaded";
    EXPECT_NE(message.find(f.problem), std::string::npos)
        << f.name << ": expected '" << f.problem << "' in: " << message;
  }
}

class LoaderCorruption : public Loaders, public ::testing::WithParamInterface<std::string> {};

TEST_P(LoaderCorruption, EveryCutAndByteChangeLoadsOrThrowsInputError) {
  const gilt::stress::Watchdog watchdog("corrupting " + GetParam(), std::chrono::seconds(120));
  const std::string seed = gilt::stress::corpus_file(GetParam());
  ASSERT_FALSE(seed.empty());
  const std::string name = "variant" + fs::path(GetParam()).extension().string();
  EXPECT_EQ(load(seed, name, "the seed itself"), "") << "the seed file must load";

  constexpr int kPoints = 128;
  int rejected = 0, variants = 0;
  for (int i = 0; i < kPoints; ++i) {
    const size_t at = seed.size() * size_t(i) / kPoints;
    rejected += load(seed.substr(0, at), name, "cut at " + std::to_string(at)).empty() ? 0 : 1;
    ++variants;
  }
  const std::string breakers = std::string("\0\xff\"}9-\n", 7);
  for (int i = 0; i < kPoints; ++i) {
    const size_t at = (seed.size() - 1) * size_t(i) / (kPoints - 1);
    std::string changed = seed;
    changed[at] = breakers[size_t(i) % breakers.size()];
    if (changed == seed) continue;
    rejected += load(changed, name, "byte " + std::to_string(at) + " changed").empty() ? 0 : 1;
    ++variants;
  }
  std::printf("%s: %d of %d variants rejected with InputError, the rest loaded, in %.2f s\n",
              GetParam().c_str(), rejected, variants, watchdog.seconds());
  EXPECT_GT(rejected, 0) << "no variant was rejected: the corruption did not reach the parser";
}

INSTANTIATE_TEST_SUITE_P(Stress, LoaderCorruption,
                         ::testing::Values("obj/lit_quad.obj", "gltf/lit_quad.gltf", "glb/lit_quad.glb",
                                           "ply/quad_ascii.ply", "ply/quad_binary.ply", "json/scene.json"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param;
                           for (char& c : name)
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           return name;
                         });

}  // namespace
