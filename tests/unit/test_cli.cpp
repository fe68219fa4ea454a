// The gilt command line on good and bad input: bad flags, files and numbers exit with code 2 and
// a message naming the problem, and never leave an output file behind or clobber one.

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "tests/support/cli_run.h"

namespace fs = std::filesystem;

namespace {

using Result = gilt::test::CliResult;
using gilt::test::slurp;

class Cli : public ::testing::Test {
 public:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gilt-cli-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  Result run(const std::string& args) {
    return gilt::test::run_command(std::string("'") + GILT_BINARY_PATH + "' " + args, dir_);
  }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  /// Files in the test folder (to prove nothing was left behind).
  size_t file_count() const { return std::distance(fs::directory_iterator(dir_), fs::directory_iterator()); }

  fs::path dir_;
};

}  // namespace

TEST_F(Cli, RendersBuiltInSceneAndReportsJson) {
  const fs::path out = dir_ / "c.exr";
  const Result r = run("render cornell --spp 2 --width 16 --height 12 --threads 1 --json -o '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  ASSERT_TRUE(fs::exists(out));
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["width"], 16);
  EXPECT_EQ(j["height"], 12);
  EXPECT_EQ(j["spp"], 2);
  EXPECT_EQ(j["samples"], 16 * 12 * 2);
  EXPECT_GT(j["rays"].get<double>(), 16 * 12 * 2 - 1);
  EXPECT_GT(j["triangles"].get<int>(), 0);
}

// A textured OBJ: `render --json` reports how its textures were held and how long they took to
// load, and `info` names the plan; a budget of 0 MiB turns it to OpenImageIO's cache.
TEST_F(Cli, TexturePlanAndLoadTimeAreReported) {
  {
    std::ofstream image(dir_ / "red.ppm", std::ios::binary);
    image << "P6\n2 2\n255\n";
    for (int i = 0; i < 4; ++i) image.put(char(255)).put(char(0)).put(char(0));
  }
  write("quad.mtl", "newmtl red\nKd 1 1 1\nmap_Kd red.ppm\n");
  const fs::path scene = write("quad.obj",
                               "mtllib quad.mtl\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n"
                               "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl red\nf 1/1 2/2 3/3 4/4\n");
  const fs::path out = dir_ / "q.exr";
  for (const bool cache : {false, true}) {
    const std::string env = cache ? "GILT_TEXTURE_MEMORY_MB=0 " : "GILT_TEXTURE_MEMORY_MB= ";
    const Result r =
        gilt::test::run_command(env + "'" + GILT_BINARY_PATH + "' render '" + scene.string() +
                                    "' --spp 1 --width 8 --height 8 --json -o '" + out.string() + "'",
                                dir_);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_GT(j["texture_load_seconds"].get<double>(), 0.0);
    EXPECT_EQ(j["textures"]["files"], 1);
    EXPECT_EQ(j["textures"]["plan"], cache ? "OpenImageIO's cache" : "in-memory pyramids");
    const Result info =
        gilt::test::run_command(env + "'" + GILT_BINARY_PATH + "' info '" + scene.string() + "'", dir_);
    ASSERT_EQ(info.code, 0) << info.err;
    EXPECT_NE(info.out.find(cache ? "texture plan: OpenImageIO's cache" : "texture plan: in-memory pyramids"),
              std::string::npos)
        << info.out;
  }
}

// Same seed, different thread counts, separate runs: the EXR files are identical byte for byte
// (no time stamp or thread-dependent value reaches the file).
TEST_F(Cli, SameSeedGivesIdenticalFilesAcrossRunsAndThreads) {
  const fs::path a = dir_ / "a.exr", b = dir_ / "b.exr";
  const std::string common = "render cornell-caustics --spp 3 --width 24 --height 20 --seed 7 -q ";
  ASSERT_EQ(run(common + "--threads 1 -o '" + a.string() + "'").code, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(1100));  // a time stamp would now differ
  ASSERT_EQ(run(common + "--threads 2 -o '" + b.string() + "'").code, 0);
  EXPECT_EQ(slurp(a), slurp(b));
}

TEST_F(Cli, WhittedRendersPng) {
  const fs::path out = dir_ / "w.png";
  const Result r = run("render cornell-caustics --method whitted --spp 1 --width 16 --height 16 -o '" + out.string() + "'");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
}

TEST_F(Cli, PhotonAndSppmRenderAndReport) {
  const fs::path a = dir_ / "p.exr", b = dir_ / "s.exr";
  const Result p = run("render cornell-caustics --method photon --photons 4000 --caustic-photons 4000 --gather-rays 2 "
                       "--spp 1 --width 16 --height 16 --json -o '" + a.string() + "'");
  ASSERT_EQ(p.code, 0) << p.err;
  const nlohmann::json jp = nlohmann::json::parse(p.out);
  EXPECT_GT(jp["photon"]["global_photons"].get<int>(), 0);
  EXPECT_GT(jp["photon"]["caustic_photons"].get<int>(), 0);
  EXPECT_EQ(jp["non_finite_samples"], 0);
  const Result s = run("render cornell-caustics --method sppm --photons 2000 --spp 3 --alpha 0.5 --width 16 --height 16 "
                       "--json -o '" + b.string() + "'");
  ASSERT_EQ(s.code, 0) << s.err;
  const nlohmann::json js = nlohmann::json::parse(s.out);
  EXPECT_EQ(js["sppm"]["iterations"], 3);
  EXPECT_EQ(js["sppm"]["photons"], 6000);
  EXPECT_LT(js["sppm"]["mean_final_radius"].get<double>(), js["sppm"]["initial_radius"].get<double>());
  // cornell has no mirror or glass: the caustic map is skipped, and said so.
  const Result c = run("render cornell --method photon --photons 2000 --spp 1 --width 8 --height 8 --json -o '" +
                       a.string() + "'");
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.out.find("no specular surface"), std::string::npos) << c.out;
}

TEST_F(Cli, InfoSaysWhatEachMethodRunsAndSkips) {
  const Result r = run("info cornell --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["triangles"], 38);
  EXPECT_EQ(j["lights"]["area triangles"], 2);
  EXPECT_GT(j["memory_estimate_bytes"].get<double>(), 0.0);
  const std::string photon_skipped = j["methods"]["photon"]["skipped"].dump();
  EXPECT_NE(photon_skipped.find("no specular surface"), std::string::npos) << photon_skipped;
  // The blocks stand on the floor: their outlines are imprinted and the floor under them skipped.
  const std::string radiosity_runs = j["methods"]["radiosity"]["runs"].dump();
  EXPECT_NE(radiosity_runs.find("contact lines"), std::string::npos) << radiosity_runs;
  const std::string radiosity_skipped = j["methods"]["radiosity"]["skipped"].dump();
  EXPECT_NE(radiosity_skipped.find("buried"), std::string::npos) << radiosity_skipped;
  // The furnace is one closed box: radiosity needs no visibility rays.
  const Result f = run("info furnace --json");
  ASSERT_EQ(f.code, 0) << f.err;
  const std::string skipped = nlohmann::json::parse(f.out)["methods"]["radiosity"]["skipped"].dump();
  EXPECT_NE(skipped.find("convex enclosure"), std::string::npos) << skipped;
  // cornell-caustics has glass: the caustic map runs.
  const Result c = run("info cornell-caustics");
  ASSERT_EQ(c.code, 0) << c.err;
  EXPECT_NE(c.out.find("runs:    caustic map"), std::string::npos) << c.out;
  EXPECT_EQ(run("info " + (dir_ / "missing.obj").string()).code, 2);
}

struct BadCase {
  const char* name;
  std::string args;     // after "render"
  std::string message;  // expected in stderr
};

TEST_F(Cli, BadInputExitsTwoWithMessageAndNoOutput) {
  const std::string out = (dir_ / "out.png").string();
  const fs::path bad_obj = write("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  const fs::path nan_obj = write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  const fs::path bad_json = write("bad.json", "{\n  \"meshes\": [\n    oops\n  ]\n}\n");
  const fs::path not_image = write("sky.hdr", "not an image");
  const std::vector<BadCase> cases = {
      {"missing file", "render " + (dir_ / "nope.obj").string() + " -o " + out, "nope.obj"},
      {"unknown scene type", "render " + write("scene.xyz", "x").string() + " -o " + out, "scene.xyz"},
      {"face index out of range", "render " + bad_obj.string() + " -o " + out, "bad_index.obj"},
      {"NaN coordinate", "render " + nan_obj.string() + " -o " + out, "nan"},
      {"malformed JSON", "render " + bad_json.string() + " -o " + out, "bad.json"},
      {"zero spp", "render cornell --spp 0 -o " + out, "--spp"},
      {"spp not a number", "render cornell --spp many -o " + out, "--spp"},
      {"spp and time", "render cornell --spp 4 --time 1 -o " + out, "--time"},
      {"two-number lookfrom", "render cornell --lookfrom 1,2 -o " + out, "--lookfrom"},
      {"zero fov", "render cornell --fov 0 --spp 1 -o " + out, "field of view"},
      {"camera up along view", "render cornell --lookfrom 0,0,0 --lookat 0,1,0 --up 0,1,0 -o " + out, "up"},
      {"unknown method", "render cornell --method magic -o " + out, "--method"},
      {"camera number past the list", "render cornell --camera 1 -o " + out, "no such camera; cornell has 0 'scene'"},
      {"camera name not in the list", "compare cornell --camera front -o " + (dir_ / "cmp").string(), "no camera of that name"},
      {"camera of a scene without one", "info " + write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").string() + " --camera 0",
       "defines no camera"},
      {"alpha out of range", "render cornell --method sppm --alpha 1.5 -o " + out, "--alpha"},
      {"zero k", "render cornell --method photon --k 0 -o " + out, "--k"},
      {"negative radius", "render cornell --method photon --radius -1 -o " + out, "--radius"},
      {"zero photons", "render cornell --method sppm --photons 0 -o " + out, "--photons"},
      {"unsupported output", "render cornell -o " + (dir_ / "out.jpg").string(), "out.jpg"},
      {"missing output folder", "render cornell -o " + (dir_ / "no/such/dir/out.png").string(), "does not exist"},
      {"no output", "render cornell", "--output"},
      {"no subcommand", "", "subcommand"},
      {"missing environment image", "render cornell --env " + (dir_ / "none.exr").string() + " -o " + out, "--env"},
      {"environment not an image", "render cornell --env " + not_image.string() + " -o " + out, "sky.hdr"},
      {"negative environment scale", "render cornell --env " + not_image.string() + " --env-scale -1 -o " + out,
       "--env-scale"},
      {"sky without a sun", "render cornell --sky -o " + out, "--sky needs --sun"},
      {"sun of four numbers", "render cornell --sun 1,2,3,4 -o " + out, "--sun"},
      {"sun below the nadir", "render cornell --sun -100,0 -o " + out, "--sun"},
      {"turbidity out of range", "render cornell --sun 40,120 --sky 20 -o " + out, "--sky"},
      {"NaN environment turn", "render cornell --env " + not_image.string() + " --env-rotate nan -o " + out,
       "--env-rotate"},
  };
  const size_t files_before = file_count();
  for (const BadCase& c : cases) {
    const Result r = run(c.args);
    EXPECT_EQ(r.code, 2) << c.name << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << ": stderr was: " << r.err;
    EXPECT_FALSE(fs::exists(out)) << c.name << " left an output file";
    EXPECT_EQ(file_count(), files_before) << c.name << " left a file behind";
  }
}

// An open floor under a constant sky of its own, for the command line's lights to replace.
const char* kOpenFloor = R"({
    "materials": {"grey": {"albedo": 0.5}},
    "shapes": [{"type": "quad", "vertices": [[-1, 0, -1], [-1, 0, 1], [1, 0, 1], [1, 0, -1]], "material": "grey"}],
    "lights": [{"type": "environment", "radiance": 0.2}],
    "camera": {"look_from": [0, 2, 3], "look_at": [0, 0, 0], "vfov": 40}
  })";

// Every method renders `scene` with `flags`, each saying that the scene's sky was `replaced`.
void expect_every_method_renders(Cli& cli, const fs::path& dir, const fs::path& scene, const std::string& flags,
                                 const std::string& replaced) {
  for (const char* method : {"path", "whitted", "photon", "sppm", "radiosity"}) {
    const fs::path out = dir / (std::string(method) + ".exr");
    const Result r = cli.run("render '" + scene.string() + "' " + flags + " --method " + method +
                             " --spp 2 --width 16 --height 12 -q -o '" + out.string() + "'");
    ASSERT_EQ(r.code, 0) << method << ": " << r.err;
    EXPECT_TRUE(fs::exists(out)) << method;
    EXPECT_NE(r.err.find("replaced by " + replaced), std::string::npos) << method << ": " << r.err;
  }
}

// --env lights a scene with an image: here a render of the Cornell box used as a sky over an
// open floor, which the scene's own constant sky gives way to, with a warning. Every method
// renders it, and `info` lists it.
TEST_F(Cli, EnvironmentImageLightsEveryMethod) {
  const fs::path sky = dir_ / "sky.exr";
  ASSERT_EQ(run("render cornell --spp 1 --width 32 --height 16 -q -o '" + sky.string() + "'").code, 0);
  const fs::path scene = write("floor.json", kOpenFloor);
  expect_every_method_renders(*this, dir_, scene, "--env '" + sky.string() + "' --env-scale 2 --env-rotate 45", "--env");
  const Result info = run("info '" + scene.string() + "' --env '" + sky.string() + "'");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.out.find("1 environment"), std::string::npos) << info.out;
}

// --sun and --sky light a scene in every method; the sky takes the place of the scene's own.
TEST_F(Cli, SunAndSkyLightEveryMethod) {
  const fs::path scene = write("floor.json", kOpenFloor);
  expect_every_method_renders(*this, dir_, scene, "--sun 40,120,3 --sky 4", "--sky");
  const Result info = run("info '" + scene.string() + "' --sun 40,120 --sky");
  ASSERT_EQ(info.code, 0) << info.err;
  EXPECT_NE(info.out.find("1 directional; 1 environment"), std::string::npos) << info.out;
}

TEST_F(Cli, FailedRunDoesNotClobberExistingOutput) {
  const fs::path out = write("keep.png", "previous contents");
  const Result r = run("render " + (dir_ / "missing.obj").string() + " -o " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(slurp(out), "previous contents");
}

TEST_F(Cli, CtrlCStopsARenderWithCode130AndNoOutput) {
  // A render of minutes, sent SIGINT once gilt has installed its handler (the SigCgt mask of
  // /proc/PID/status has SIGINT's bit, the last hex digit's 2: a fixed sleep was not enough under
  // AddressSanitizer on a loaded machine, and before its handler the shell's background job
  // ignores SIGINT). The process must be gilt by then (its comm): the shell's child, before it
  // runs gilt, can show the shell's own SIGINT handler, and a SIGINT sent then was ignored once
  // gilt started under AddressSanitizer (the render ran on until the watchdog killed it). It must stop at its next tile, exit with 130 and leave the existing file as
  // it was. A watchdog kills it after 60 s should it not stop: the test fails, not hangs.
  const fs::path out = write("keep.exr", "previous contents");
  const Result r = gilt::test::run_command(
      std::string("{ '") + GILT_BINARY_PATH + "' render cornell --spp 1000000 --width 64 --height 64 --threads 1 -q -o " +
          out.string() +
          " & g=$!; ( sleep 60; kill -KILL $g 2>/dev/null ) & w=$!; i=0; while [ $i -lt 1200 ]; do "
          "c=$(cat /proc/$g/comm 2>/dev/null); m=$(awk '/^SigCgt/ {print $2}' /proc/$g/status 2>/dev/null); "
          "if [ \"$c\" = gilt ]; then case \"${m#${m%?}}\" in 2|3|6|7|a|b|e|f) break;; esac; fi; "
          "i=$((i + 1)); sleep 0.05; done; sleep 0.2; t0=$(date +%s%N); kill -INT $g; wait $g; "
          "code=$?; t1=$(date +%s%N); kill $w 2>/dev/null; echo \"exit $code\"; echo \"stopped_ms "
          "$(( (t1 - t0) / 1000000 ))\"; }",
      dir_);
  EXPECT_NE(r.out.find("exit 130"), std::string::npos) << r.out << r.err;
  EXPECT_NE(r.err.find("gilt: interrupted"), std::string::npos) << r.err;
  const size_t at = r.out.find("stopped_ms ");
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_LT(std::stod(r.out.substr(at + 11)), 10000.0) << r.out;  // a tile of 16 x 16 pixels at 8 spp takes milliseconds
  EXPECT_EQ(slurp(out), "previous contents");
}
