// `mpirun -np 2 gilt render` against one process: the same seed gives the same file, bit for bit,
// for every method (tiles, SPPM's rows and photon chunks, the photon method's photon chunks and
// irradiance points are split across the ranks and joined by copying, never by adding).

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
  /// --oversubscribe; as root in CI: Open MPI's two variables that allow it).
  gilt::test::CliResult gilt(int ranks, const std::string& args) {
    std::string command = std::string("'") + GILT_BINARY_PATH + "' " + args;
    if (ranks > 1)
      command = "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 '" + std::string(GILT_MPIEXEC) + "' -np " +
                std::to_string(ranks) + " --oversubscribe " + command;
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

TEST_F(Mpi, OtherCommandsRefuseSeveralRanks) {
  const gilt::test::CliResult r = gilt(2, "radiosity cornell -o " + (dir_ / "r.ply").string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("only `gilt render` splits"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "r.ply"));
}
