// Ctrl-C and SIGTERM in a sweep: no new case starts, the running case closes its files and writes a
// summary that says it did not complete, the complete cases are gathered, and gem exits 128 + the
// signal; a later `gem sweep` runs the stopped case again (docs/scenario.md 1.8, 5).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "framework/analysis/sweep_summary.hpp"
#include "framework/output/csv.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using namespace gem;

// On the CPU, where the cases run one at a time in the file's order (--jobs 1): on a GPU the three
// 5-step cases would run together in one device state, "never" among them.
TEST(SweepInterrupt, StopsTheRunningCaseWholeAndGathersTheCompleteOnes) {
  test::TempDir dir;
  dir.write("base.toml", test::kTinyChannel);
  const fs::path file = dir.write("study.toml", R"([sweep]
base = "base.toml"
set = { "simulation.backend" = "cpu" }
[[cases]]
name = "short_a"
set = { "simulation.steps" = 5 }
[[cases]]
name = "short_b"
set = { "simulation.steps" = 5 }
[[cases]]
name = "long"
set = { "simulation.steps" = 2000000, "output.checkpoint_every" = 50 }
[[cases]]
name = "never"
set = { "simulation.steps" = 5 }
)");
  const fs::path out = dir.path() / "out";
  const std::string gem = std::string(std::getenv("GEM_BINARY_DIR") ? std::getenv("GEM_BINARY_DIR") : GEM_BINARY_DIR) + "/gem";
  // The signal comes once the long case has started (its run wrote its scenario.toml), however slow
  // the machine or the build (sanitizers).
  const std::string started = (out / "cases" / "long" / "scenario.toml").string();
  const std::string command = "bash -c '" + gem + " sweep " + file.string() + " --jobs 1 --out " + out.string() + " > " +
                              (dir.path() / "log").string() + " 2>&1 & p=$!; for i in $(seq 600); do [ -f " + started +
                              " ] && break; sleep 0.1; done; sleep 0.5; kill -INT $p; wait $p; exit $?'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  const std::string log = test::readFile(dir.path() / "log");
  EXPECT_EQ(WEXITSTATUS(status), 130) << log;
  EXPECT_NE(log.find("sweep interrupted"), std::string::npos) << log;

  // The complete cases are gathered; the stopped one is not, and the last one never started.
  const CsvTable table = readCsvTable(out / "summary.csv");
  ASSERT_EQ(table.rows.size(), 2u) << test::readFile(out / "summary.csv");
  EXPECT_EQ(table.rows[0][0], "short_a");
  EXPECT_EQ(table.rows[1][0], "short_b");
  const auto stopped = readSummaryJson(out / "cases" / "long" / "summary.json");
  EXPECT_EQ(stopped.at("completed"), "false");
  EXPECT_EQ(stopped.at("stop_reason"), "SIGINT");
  // No checkpoint in the stopped case, though its scenario asks for one every 50 steps: the sweep
  // runs it again from its start (the one Ctrl-C wrote, or the last periodic one, was left there).
  EXPECT_FALSE(fs::exists(out / "cases" / "long" / "checkpoint.gem"));
  EXPECT_FALSE(fs::exists(out / "cases" / "never" / "summary.json"));
  for (const auto& entry : fs::recursive_directory_iterator(out))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}
