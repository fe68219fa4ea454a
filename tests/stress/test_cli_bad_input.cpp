// The gilt command line on bad numbers and bad files, beyond tests/unit/test_cli.cpp: every
// numeric flag of `gilt render` and `gilt radiosity` given the value most likely to slip past its
// check (NaN, an infinity, a number past the type's range, a negative), camera vectors with NaN
// or huge coordinates; truncated and corrupt files of every scene format (.obj, .mtl, .gltf,
// .glb, .ply, .json); a scene without lights. Bad input must exit with code 2, name the problem
// on stderr and leave no file behind; a scene without lights is not bad input (warning, exit 0).

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "raytrace_core/util/image_io.h"
#include "tests/stress/bad_files.h"

namespace fs = std::filesystem;
namespace rc = gilt::raytrace_core;
using gilt::stress::BadFile;
using gilt::stress::corpus_file;
using gilt::stress::kTriangle;

namespace {

struct Outcome {
  int code = -1;
  std::string out, err;
};

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// A scratch folder per test; gilt runs with its standard streams captured in a second folder,
/// so "no file left behind" means the scratch folder holds exactly the inputs written to it.
class CliBadInput : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string id =
        std::to_string(::getpid()) + "-" + ::testing::UnitTest::GetInstance()->current_test_info()->name();
    dir_ = fs::temp_directory_path() / ("gilt-stress-cli-" + id);
    streams_ = fs::temp_directory_path() / ("gilt-stress-cli-streams-" + id);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    fs::create_directories(streams_);
  }
  void TearDown() override {
    fs::remove_all(dir_);
    fs::remove_all(streams_);
  }

  /// Runs gilt with `args` (a shell word list) under a 60 s limit; a hang shows as code 124.
  Outcome run(const std::string& args) {
    const fs::path out = streams_ / "out", err = streams_ / "err";
    const std::string cmd = "timeout 60 '" + std::string(GILT_BINARY_PATH) + "' " + args + " >'" +
                            out.string() + "' 2>'" + err.string() + "' </dev/null";
    const int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_file(out), read_file(err)};
  }

  fs::path write(const std::string& name, const std::string& bytes) {
    std::ofstream(dir_ / name, std::ios::binary) << bytes;
    return dir_ / name;
  }

  std::vector<std::string> files() const {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir_)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }

  /// Runs one bad command line and checks exit code 2, a message containing one of `names`,
  /// and no new file.
  Outcome expect_rejected(const std::string& what, const std::string& args,
                          const std::vector<std::string>& names) {
    const std::vector<std::string> before = files();
    const Outcome r = run(args);
    EXPECT_EQ(r.code, 2) << what << "\n  gilt " << args << "\n  stderr: " << r.err;
    bool named = false;
    for (const std::string& n : names) named = named || r.err.find(n) != std::string::npos;
    EXPECT_TRUE(named) << what << ": stderr names none of the expected words (first: '" << names.front()
                       << "'):\n  " << r.err;
    EXPECT_EQ(files(), before) << what << " left a file behind";
    for (const std::string& f : files())
      if (std::find(before.begin(), before.end(), f) == before.end()) fs::remove(dir_ / f);
    return r;
  }

  fs::path dir_, streams_;
};

/// A numeric flag, values it must refuse, the words a message about it may use, and the
/// arguments that make the flag matter (a method, say). Each run of gilt costs about half a
/// second (it loads ~270 shared libraries), so each flag gets the value most likely to slip past
/// its check: NaN or an infinity where a float is range-checked (NaN fails every comparison), a
/// number past the type's range where an integer is; tests/unit/test_cli.cpp has the common
/// mistakes (zero, negative, text).
struct NumericFlag {
  std::string flag;
  std::vector<std::string> bad_values;
  std::vector<std::string> names;  // the flag itself, or the library's name for the quantity
  std::string context;             // extra arguments: a method, or none
};

std::vector<NumericFlag> render_image_flags() {
  return {
      {"--spp", {"1e40"}, {"--spp"}, ""},
      {"--time", {"inf"}, {"--time"}, ""},
      {"--width", {"70000"}, {"--width"}, "--spp 1"},
      {"--height", {"nan"}, {"--height"}, "--spp 1"},
      {"--threads", {"-1"}, {"--threads"}, "--spp 1"},
      {"--seed", {"nan"}, {"--seed"}, "--spp 1"},
      {"--fov", {"nan"}, {"--fov", "field of view"}, "--spp 1"},
      {"--aperture", {"inf"}, {"--aperture", "aperture"}, "--spp 1"},
      {"--focus-distance", {"-1"}, {"--focus-distance", "focus distance"}, "--spp 1"},
      {"--filter-radius", {"inf"}, {"--filter-radius"}, "--spp 1"},
      {"--exposure", {"inf"}, {"--exposure"}, "--spp 1"},
      {"--max-depth", {"1e40"}, {"--max-depth"}, "--spp 1"},
  };
}

std::vector<NumericFlag> render_method_flags() {
  return {
      {"--photons", {"1e40"}, {"--photons"}, "--spp 1 --method photon"},
      {"--caustic-photons", {"nan"}, {"--caustic-photons"}, "--spp 1 --method photon"},
      {"--k", {"nan"}, {"--k"}, "--spp 1 --method photon"},
      {"--radius", {"nan", "inf"}, {"--radius"}, "--spp 1 --method photon"},
      {"--gather-rays", {"-1"}, {"--gather-rays"}, "--spp 1 --method photon"},
      {"--radius", {"nan"}, {"--radius"}, "--spp 1 --method sppm"},
      {"--alpha", {"nan"}, {"--alpha"}, "--spp 1 --method sppm"},
      {"--max-edge", {"nan"}, {"--max-edge", "max_edge"}, "--spp 1 --method radiosity"},
      {"--elements", {"1e40"}, {"--elements"}, "--spp 1 --method radiosity"},
      {"--tolerance", {"nan"}, {"--tolerance"}, "--spp 1 --method radiosity"},
      {"--subdivision-levels", {"9"}, {"--subdivision-levels"}, "--spp 1 --method radiosity"},
      {"--subdivision-threshold",
       {"nan"},
       {"--subdivision-threshold", "subdivision threshold"},
       "--spp 1 --method radiosity"},
  };
}

/// `gilt radiosity` shares the solver flags with `render --method radiosity` (add_solver_options);
/// these are its own, plus one shared flag to prove the sharing.
std::vector<NumericFlag> radiosity_flags() {
  return {
      {"--tolerance", {"nan"}, {"--tolerance"}, "--elements 50"},
      {"--time", {"inf"}, {"--time"}, "--elements 50"},
      {"--exposure", {"inf"}, {"--exposure"}, "--elements 50 --srgb8"},
      {"--threads", {"nan"}, {"--threads"}, "--elements 50"},
      {"--seed", {"1e40"}, {"--seed"}, "--elements 50"},
      {"--solver", {"bogus", "nan"}, {"--solver"}, "--elements 50"},
      {"--link-tolerance", {"nan", "0", "2"}, {"--link-tolerance"}, "--elements 50 --solver hierarchical"},
      {"--gather-tolerance", {"inf", "-1"}, {"--gather-tolerance"}, "--elements 50 --solver hierarchical"},
      {"--final-gather", {"maybe", "1"}, {"--final-gather"}, "--elements 50 --solver hierarchical"},
  };
}

}  // namespace

TEST_F(CliBadInput, RenderRejectsBadImageAndCameraNumbers) {
  const std::string out = (dir_ / "out.png").string();
  for (const NumericFlag& f : render_image_flags())
    for (const std::string& v : f.bad_values) {
      const std::string size = (f.flag == "--width" || f.flag == "--height") ? "" : "--width 8 --height 8 ";
      expect_rejected(
          "render " + f.flag + " " + v,
          "render cornell " + size + f.context + " -q " + f.flag + " '" + v + "' -o '" + out + "'", f.names);
    }
}

TEST_F(CliBadInput, RenderRejectsBadMethodNumbers) {
  const std::string out = (dir_ / "out.png").string();
  for (const NumericFlag& f : render_method_flags())
    for (const std::string& v : f.bad_values)
      expect_rejected("render " + f.context + " " + f.flag + " " + v,
                      "render cornell --width 8 --height 8 " + f.context + " -q " + f.flag + " '" + v +
                          "' -o '" + out + "'",
                      f.names);
}

TEST_F(CliBadInput, RenderRejectsBadVectors) {
  const std::string out = (dir_ / "out.png").string();
  for (const std::string flag : {"--lookfrom", "--lookat", "--up"})
    for (const std::string v : {flag == std::string("--up") ? "0,inf,1" : "nan,0,1e40"})
      expect_rejected(
          "render " + flag + " " + v,
          "render cornell --spp 1 --width 8 --height 8 -q " + flag + " '" + v + "' -o '" + out + "'", {flag});
}

TEST_F(CliBadInput, RadiosityRejectsBadNumbers) {
  const std::string out = (dir_ / "out.ply").string();
  for (const NumericFlag& f : radiosity_flags())
    for (const std::string& v : f.bad_values)
      expect_rejected("radiosity " + f.flag + " " + v,
                      "radiosity cornell " + f.context + " -q " + f.flag + " '" + v + "' -o '" + out + "'",
                      f.names);
}

// Regression: NaN passed CLI11's range checks (it fails every comparison) and no later check
// caught it for these flags, so gilt exited 0 and wrote the output (render --time nan rendered
// the scene's spp, radiosity --time nan solved without a limit); CLI11 read --seed -1 and 2^64
// as 2^64 − 1. cli/commands.h now has finite_number() and unsigned_integer() checks.
TEST_F(CliBadInput, NanAndOutOfRangeSeedAreRefused) {
  const std::string png = (dir_ / "out.png").string(), ply = (dir_ / "out.ply").string();
  const std::string render = "render cornell --width 8 --height 8 -q ";
  expect_rejected("render --time nan", render + "--time nan -o '" + png + "'", {"--time"});
  expect_rejected("render --filter-radius nan", render + "--spp 1 --filter-radius nan -o '" + png + "'",
                  {"--filter-radius"});
  expect_rejected("render --exposure nan", render + "--spp 1 --exposure nan -o '" + png + "'",
                  {"--exposure"});
  expect_rejected("render --seed -1", render + "--spp 1 --seed -1 -o '" + png + "'", {"--seed"});
  expect_rejected("render --seed 2^64", render + "--spp 1 --seed 18446744073709551616 -o '" + png + "'",
                  {"--seed"});
  const std::string radiosity = "radiosity cornell --elements 50 -q ";
  expect_rejected("radiosity --time nan", radiosity + "--time nan -o '" + ply + "'", {"--time"});
  expect_rejected("radiosity --exposure nan", radiosity + "--srgb8 --exposure nan -o '" + ply + "'",
                  {"--exposure"});
  expect_rejected("radiosity --seed -1", radiosity + "--seed -1 -o '" + ply + "'", {"--seed"});
}

// A few bad files of each format (tests/stress/bad_files.h; test_loader_corruption.cpp checks
// them all in-process).
TEST_F(CliBadInput, CorruptFilesOfEveryFormatExitTwoAndNameTheProblem) {
  const std::string out = (dir_ / "out.png").string();
  for (const auto& [name, text] : gilt::stress::kSideFiles) write(name, text);
  for (const BadFile& f : gilt::stress::bad_files()) {
    if (!f.via_cli) continue;
    const fs::path path = write(f.name, f.bytes);
    const Outcome r = expect_rejected(
        f.name, "render '" + path.string() + "' --spp 1 --width 8 --height 8 -q -o '" + out + "'", {f.name});
    EXPECT_NE(r.err.find(f.problem), std::string::npos)
        << f.name << ": expected '" << f.problem << "' in: " << r.err;
  }
}

// `gilt radiosity` loads scenes by the same path: one bad file of each format.
TEST_F(CliBadInput, RadiosityRejectsCorruptFiles) {
  const std::string out = (dir_ / "out.ply").string();
  for (const auto& [name, text] : gilt::stress::kSideFiles) write(name, text);
  for (const BadFile& f : gilt::stress::bad_files()) {
    if (f.name != "face_index_zero.obj" && f.name != "truncated.glb" && f.name != "wrong_type.json") continue;
    const fs::path path = write(f.name, f.bytes);
    expect_rejected(f.name, "radiosity '" + path.string() + "' --elements 50 -q -o '" + out + "'", {f.name});
  }
}

// MTL values out of float's range: the MTL file and line are named.
TEST_F(CliBadInput, MtlWithOverflowingValueExitsTwo) {
  const std::string out = (dir_ / "out.png").string();
  write("huge.mtl", "newmtl lamp\nKe 1e40 1 1\n");
  const fs::path obj = write("huge.obj", "mtllib huge.mtl\n" + kTriangle + "usemtl lamp\nf 1 2 3\n");
  expect_rejected("Ke 1e40", "render '" + obj.string() + "' --spp 1 --width 8 --height 8 -q -o '" + out + "'",
                  {"huge.mtl:2"});
}

// tinyobjloader reads a number it cannot parse as 0 without saying so ("Kd nan 0 0" would load
// as black, "Kd 0.5" as (0.5, 0, 0)): the loader checks the MTL text first, as it does the OBJ's.
TEST_F(CliBadInput, MtlWithNonNumbersExitsTwo) {
  const std::string out = (dir_ / "out.png").string();
  const std::vector<std::pair<std::string, std::string>> mtls = {{"nan_kd", "newmtl a\nKd nan 0 0\n"},
                                                                 {"inf_ke", "newmtl a\nKe inf 1 1\n"},
                                                                 {"short_kd", "newmtl a\nKd 0.5\nKe 1 1 1\n"},
                                                                 {"negative_ke", "newmtl a\nKe -5 0 0\n"}};
  for (const auto& [name, text] : mtls) {
    write(name + ".mtl", text);
    const fs::path obj =
        write(name + ".obj", "mtllib " + name + ".mtl\n" + kTriangle + "usemtl a\nf 1 2 3\n");
    expect_rejected(name, "render '" + obj.string() + "' --spp 1 --width 8 --height 8 -q -o '" + out + "'",
                    {name + ".mtl"});
  }
}

// A valid file of each format cut at two thirds: gilt either renders (a prefix may be a valid
// file) and writes the image, or exits 2 and writes nothing; never 1, a signal or a hang.
// (test_loader_corruption.cpp runs hundreds of such variants through the loaders in-process;
// this checks the command line's side.)
TEST_F(CliBadInput, TruncatedFilesExitZeroOrTwo) {
  const std::string out = (dir_ / "out.png").string();
  for (const auto& [name, text] : gilt::stress::kSideFiles) write(name, text);
  for (const std::string seed : {"obj/lit_quad.obj", "gltf/lit_quad.gltf", "glb/lit_quad.glb",
                                 "ply/quad_ascii.ply", "ply/quad_binary.ply", "json/scene.json"}) {
    const std::string bytes = corpus_file(seed);
    const std::string name = "cut" + fs::path(seed).extension().string();
    const fs::path path = write(name, bytes.substr(0, 2 * bytes.size() / 3));
    const Outcome r = run("render '" + path.string() + "' --spp 1 --width 8 --height 8 -q -o '" + out + "'");
    EXPECT_TRUE(r.code == 0 || r.code == 2) << seed << ": exit " << r.code << "\n  " << r.err;
    EXPECT_EQ(fs::exists(out), r.code == 0)
        << seed << ": exit " << r.code << " but the output is " << (fs::exists(out) ? "there" : "missing");
    if (r.code == 2) {
      EXPECT_NE(r.err.find(name), std::string::npos) << seed << ": " << r.err;
    }
    fs::remove(out);
  }
}

// A scene without lights is not an error: a warning, exit 0, a black image (render, at once:
// nothing is traced) or black vertex colours (radiosity).
TEST_F(CliBadInput, SceneWithoutLightsWarnsAndExitsZero) {
  write("grey.mtl", "newmtl grey\nKd 0.5 0.5 0.5\n");
  const fs::path obj =
      write("dark.obj", "mtllib grey.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl grey\nf 1 2 3 4\n");
  for (const std::string method : {"path", "whitted", "radiosity", "photon", "sppm"}) {
    const fs::path out = dir_ / ("dark-" + method + ".exr");
    const Outcome r = run("render '" + obj.string() + "' --method " + method +
                          " --spp 2 --photons 1000 --width 8 --height 8 --json -o '" + out.string() + "'");
    EXPECT_EQ(r.code, 0) << method << ": " << r.err;
    EXPECT_NE(r.err.find("no lights"), std::string::npos) << method << ": " << r.err;
    EXPECT_TRUE(fs::exists(out)) << method;
    EXPECT_NE(r.out.find("\"non_finite_samples\":0"), std::string::npos) << method << ": " << r.out;
    EXPECT_NE(r.out.find("\"rays\":0,"), std::string::npos) << method << ": " << r.out;
    const rc::util::Image image = rc::util::read_image(out.string());
    for (const rc::Rgb& p : image.pixels) EXPECT_TRUE(p.is_black()) << method;
  }
  const fs::path mesh = dir_ / "dark.ply";
  const Outcome r = run("radiosity '" + obj.string() + "' --elements 20 -q -o '" + mesh.string() + "'");
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(mesh));
  EXPECT_NE(r.err.find("no lights"), std::string::npos) << "gilt radiosity says nothing: " << r.err;
}
