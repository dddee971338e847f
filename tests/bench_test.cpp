// gem bench's time-per-step tables (bench/bench.hpp) through the gem binary, tiny runs on the
// CPU: the CSV's header and rows, the --csv directory rule, and bad input (exit 2). The CUDA rows
// are timed on a GPU machine (scripts/stage-gpu.sh runs gem bench --table all).
#include <gtest/gtest.h>

#include <thread>

#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;

namespace {

int countLines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

}  // namespace

TEST(GemBench, FieldsTableOnTheCpuWritesOneRowPerBroadphase) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  // A path ending in '/' is a directory: the table goes to fields.csv in it.
  const std::string out = (dir.path() / "bench").string() + "/";
  ASSERT_EQ(test::runGem("bench --table fields --backend cpu --cases 456 --steps 10 --csv " + out, log), 0) << test::readFile(log);
  const std::string rows = test::readFile(dir.path() / "bench" / "fields.csv");
  EXPECT_EQ(rows.rfind("case,backend,broadphase,bodies,floes,ms_per_step,steps_per_s,floe_steps_per_s,real_time_factor,device\n", 0), 0u)
      << rows;
  for (const char* b : {"variable_radius", "fixed_radius", "uniform_grid", "triangulation_mesh", "all_pairs"})
    EXPECT_NE(rows.find(std::string("\"456 hexagons (46 %)\",cpu,") + b + ","), std::string::npos) << b << "\n" << rows;
  EXPECT_EQ(countLines(rows), 6) << rows;
  const std::string text = test::readFile(log);
  EXPECT_NE(text.find("against variable_radius, 456 hexagons (46 %) on cpu"), std::string::npos) << text;
  EXPECT_NE(text.find("(one core)"), std::string::npos) << text;
}

TEST(GemBench, StepTableKeepsItsCsvAndTakesAFloeCount) {
  TempDir dir;
  const auto log = dir.path() / "log.txt", csv = dir.path() / "step.csv";
  ASSERT_EQ(test::runGem("bench --cases 824 300 --steps 10 --csv " + csv.string(), log), 0) << test::readFile(log);
  const std::string rows = test::readFile(csv);
  EXPECT_EQ(rows.rfind("case,backend,broadphase,bodies,floes,ms_per_step", 0), 0u) << rows;
  EXPECT_NE(rows.find("\"824 random (50 %)\",cpu,variable_radius,"), std::string::npos) << rows;
  EXPECT_NE(rows.find("\"300 random (40 %)\",cpu,variable_radius,"), std::string::npos) << rows;
  EXPECT_EQ(countLines(rows), 3) << rows;
}

TEST(GemBench, BadTablesAndOptionsAreBadInput) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  EXPECT_EQ(test::runGem("bench --table nonsense", log), 2);
  EXPECT_NE(test::readFile(log).find("valid tables are step, fields, blocks, copyback, scaling"), std::string::npos) << test::readFile(log);
  // The block-size sweep is a CUDA setting.
  EXPECT_EQ(test::runGem("bench --table blocks --backend cpu", log), 2);
  EXPECT_NE(test::readFile(log).find("cuda only"), std::string::npos) << test::readFile(log);
  EXPECT_EQ(test::runGem("bench --table blocks --blocks 48", log), 2);
  EXPECT_EQ(test::runGem("bench --table fields --copy-back 4", log), 2);
  EXPECT_EQ(test::runGem("bench --table fields --cases 12x", log), 2);
  EXPECT_EQ(test::runGem("bench --table all --cases 456", log), 2);
  // The resident table times the CUDA drivers: without a device it says so (a GPU run times it).
  ASSERT_EQ(test::runGem("info", log), 0);
  const std::string info = test::readFile(log);
  if (info.find("no CUDA backend in this build") != std::string::npos || info.find("no CUDA device found") != std::string::npos) {
    EXPECT_EQ(test::runGem("bench --table resident", log), 2);
    EXPECT_NE(test::readFile(log).find("it times the CUDA drivers"), std::string::npos) << test::readFile(log);
  }
}

// --table cpu: a row a thread count, and after each one above 1 a row of as many independent
// one-thread fields (the machine's ceiling for that thread count), with the line that compares
// them. On a one-core machine the table has the one-thread row only, which is checked too.
TEST(GemBench, CpuTableTimesThreadsAndAsManyIndependentFields) {
  TempDir dir;
  const auto log = dir.path() / "log.txt", csv = dir.path() / "cpu.csv";
  ASSERT_EQ(test::runGem("bench --table cpu --cases 456 --steps 10 --csv " + csv.string(), log), 0) << test::readFile(log);
  const std::string rows = test::readFile(csv);
  EXPECT_EQ(rows.rfind("case,backend,broadphase,threads,bodies,floes,ms_per_step", 0), 0u) << rows;
  EXPECT_NE(rows.find("\"456 hexagons (46 %)\",cpu,variable_radius,1,"), std::string::npos) << rows;
  const std::string text = test::readFile(log);
  if (std::thread::hardware_concurrency() < 2) {
    EXPECT_EQ(countLines(rows), 2) << rows;
    return;
  }
  EXPECT_NE(rows.find("\"456 hexagons (46 %)\",cpu,variable_radius,2,"), std::string::npos) << rows;
  EXPECT_NE(rows.find("\"456 hexagons (46 %)\",cpu,variable_radius,2 fields,459,456,"), std::string::npos) << rows;
  EXPECT_NE(rows.find("(2 independent fields, a thread each)"), std::string::npos) << rows;
  // One row of threads and one of fields for every thread count above 1, after the one-thread row.
  const int counts = countLines(rows) - 2;
  EXPECT_GE(counts, 2) << rows;
  EXPECT_EQ(counts % 2, 0) << rows;
  EXPECT_NE(text.find("2 threads: "), std::string::npos) << text;
  EXPECT_NE(text.find("x one thread; 2 independent fields: "), std::string::npos) << text;
  EXPECT_NE(text.find("x one field's work (the most 2 threads could gain here)"), std::string::npos) << text;
}
