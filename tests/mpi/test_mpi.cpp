// `mpirun -np N gilt render|radiosity` against one process: the same seed gives the same file, bit
// for bit, for every method (tiles, SPPM's rows and photon chunks, the photon method's photon
// chunks and irradiance points, and radiosity's vertices, elements, links and receivers are split
// across the ranks and joined by copying, never by adding).

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/cli_run.h"

namespace fs = std::filesystem;

namespace {

class Mpi : public ::testing::TestWithParam<std::string> {
 public:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("gilt-mpi-" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// gilt with `args`, under `mpirun -np ranks` when ranks > 1 (two ranks on any machine:
  /// --oversubscribe; as root in CI: Open MPI's two variables that allow it). Ranks whose work
  /// diverges wait for each other in a collective for ever: `timeout` makes that a failure.
  gilt::test::CliResult gilt(int ranks, const std::string& args) {
    std::string command = std::string("'") + GILT_BINARY_PATH + "' " + args;
    if (ranks > 1)
      command = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 timeout 300 '" + std::string(GILT_MPIEXEC) +
                "' -np " + std::to_string(ranks) + " --oversubscribe " + command;
    return gilt::test::run_command(command, dir_);
  }

  fs::path dir_;
};

}  // namespace

TEST_P(Mpi, TwoRanksWriteTheImageOfOneProcess) {
  const std::string method = GetParam();
  const std::string common = "render cornell-caustics --method " + method +
                             " --spp 3 --width 40 --height 30 --seed 11 --photons 20000 --json -o ";
  const gilt::test::CliResult one = gilt(1, common + (dir_ / "one.exr").string() + " --threads 2");
  ASSERT_EQ(one.code, 0) << one.err;
  const gilt::test::CliResult two = gilt(2, common + (dir_ / "two.exr").string() + " --threads 1");
  ASSERT_EQ(two.code, 0) << two.err;
  const std::string a = gilt::test::slurp(dir_ / "one.exr"), b = gilt::test::slurp(dir_ / "two.exr");
  ASSERT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == b) << method << ": the two-rank image differs from the one-process image";
  // Rank 0 alone prints: one JSON line, which counts both ranks' rays.
  const nlohmann::json j1 = nlohmann::json::parse(one.out), j2 = nlohmann::json::parse(two.out);
  EXPECT_EQ(j2.at("ranks"), 2);
  EXPECT_EQ(j1.at("ranks"), 1);
  EXPECT_EQ(j2.at("rays"), j1.at("rays"));
}

INSTANTIATE_TEST_SUITE_P(EveryMethod, Mpi, ::testing::Values("path", "sppm", "photon", "whitted", "radiosity"));

TEST_F(Mpi, TimeBudgetEndsEveryRankTogether) {
  // Rank 0's clock decides each pass for all: the run ends, and one file is written.
  const gilt::test::CliResult r =
      gilt(2, "render cornell --method sppm --time 1 --width 32 --height 32 --threads 1 --json -o " +
                  (dir_ / "timed.exr").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_GE(nlohmann::json::parse(r.out).at("spp").get<int>(), 1);
  EXPECT_TRUE(fs::exists(dir_ / "timed.exr"));
}

/// One process against 2 and 3 ranks (3 splits the tree's subtrees unevenly): the same export,
/// byte for byte, and the same counts of work in the statistics.
void expect_same_bake(Mpi& test, const fs::path& dir, const std::string& args) {
  const gilt::test::CliResult one = test.gilt(1, args + " --json --threads 2 -o " + (dir / "one.ply").string());
  ASSERT_EQ(one.code, 0) << one.err;
  const std::string a = gilt::test::slurp(dir / "one.ply");
  ASSERT_GT(a.size(), 1000u);
  const nlohmann::json j1 = nlohmann::json::parse(one.out);
  for (int ranks : {2, 3}) {
    const std::string name = "ranks" + std::to_string(ranks) + ".ply";
    const gilt::test::CliResult r = test.gilt(ranks, args + " --json --threads 1 -o " + (dir / name).string());
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_TRUE(a == gilt::test::slurp(dir / name)) << args << ": " << ranks << " ranks' export differs from one process's";
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j.at("ranks"), ranks);
    for (const char* key : {"elements", "links", "iterations", "shots", "shadow_rays", "form_factors"})
      EXPECT_EQ(j.at(key), j1.at(key)) << args << ": " << key << " at " << ranks << " ranks";
  }
}

TEST_F(Mpi, RadiositySplitAcrossRanksExportsWhatOneProcessDoes) {
  expect_same_bake(*this, dir_, "radiosity cornell --solver progressive --elements 1500");
  // Links, iterations and the vertex final gather split by the tree's subtrees.
  expect_same_bake(*this, dir_, "radiosity cornell --solver hierarchical --elements 3000");
}

TEST_F(Mpi, RadiosityOfASunlitModelSplitAcrossRanks) {
  // The milk truck under a sun and sky (when ../shared is beside the checkout): elements' direct
  // light, links that split mixed clusters, and the final gather.
  const std::string scene = std::string(GILT_SOURCE_DIR) + "/../shared/scenes/wrap/truck-lit.json";
  if (!fs::exists(scene)) GTEST_SKIP() << scene << " is not there";
  expect_same_bake(*this, dir_, "radiosity '" + scene + "' --solver hierarchical --elements 4000");
}

TEST_F(Mpi, RadiosityTimeBudgetEndsEveryRankTogether) {
  const gilt::test::CliResult r =
      gilt(2, "radiosity cornell --solver hierarchical --elements 30000 --time 2 --threads 1 --json -o " +
                  (dir_ / "timed.ply").string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out).at("ranks"), 2);
  EXPECT_TRUE(fs::exists(dir_ / "timed.ply"));
}

TEST_F(Mpi, OtherCommandsRefuseSeveralRanks) {
  const gilt::test::CliResult r = gilt(2, "compare cornell --methods path --budgets 1 -o " + (dir_ / "report").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("only `gilt render` and `gilt radiosity` split"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "report"));
}
