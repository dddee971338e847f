// `mpirun -np 2 gem sweep` shares the cases between the two ranks (issue 5, item 1).
#include <gtest/gtest.h>

#include <cstdlib>

#include "framework/app/mpi_work.hpp"
#include "test_support.hpp"

using gem::test::TempDir;

TEST(MpiSweep, TwoRanksShareTheCasesAndRankZeroGathersThem) {
  if (!gem::mpiBuilt()) GTEST_SKIP() << "this build of GEM has no MPI";
  if (std::system("command -v mpirun > /dev/null 2>&1") != 0) GTEST_SKIP() << "mpirun is not installed";
  TempDir dir;
  dir.write("base.toml", R"([simulation]
dt = 0.1
steps = 60
[domain]
x = [0.0, 60.0]
y = [-20.0, 20.0]
walls = true
[field]
concentration = 0.3
size_mean = 4.0
size_sd = 1.0
size_min = 2.0
size_max = 8.0
[vessel]
position = [-56.0, 0.0]
[output]
frame_every = 0
)");
  const auto sweep = dir.write(
      "sweep.toml", "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"vessel.bollard_thrust\" = [23e3, 46e3, 92e3, 185e3, 370e3, 740e3]\n");
  const auto log = dir.path() / "log.txt";
  // Root may run mpirun only when it says so; --oversubscribe lets 2 ranks share fewer cores.
  const std::string command =
      "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1 mpirun -np 2 " +
      std::string(GEM_BINARY_DIR) + "/gem sweep " + sweep.string() + " --out " + (dir.path() / "out").string() + " > " + log.string() +
      " 2>&1";
  const int status = std::system(command.c_str());
  const std::string text = gem::test::readFile(log);
  ASSERT_EQ(WIFEXITED(status) ? WEXITSTATUS(status) : -1, 0) << text;
  // A worker rank ran cases (they were handed out). Whether rank 0 also ran one depends on timing:
  // these cases take milliseconds, and on a loaded 2-core machine rank 1 can take all six.
  EXPECT_NE(text.find("rank 1 ["), std::string::npos) << text;
  const std::string csv = gem::test::readFile(dir.path() / "out" / "summary.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7) << csv;  // header + every case once
  for (const char* name : {"bollard_thrust-23000", "bollard_thrust-740000"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / "cases" / name / "summary.json")) << name;
}
