// gem bench --table intersection | triangulation (bench/geometry_bench.hpp) through the gem
// binary, at small sizes: the CPU columns, the CSV, and on a build without a device the GPU
// columns saying "no CUDA device" (with a device, the GPU's results are checked against the CPU's).
#include <gtest/gtest.h>

#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;

TEST(GemBench, GeometryTablesPrintEveryRowAndWriteCsv) {
  TempDir dir;
  for (const char* table : {"intersection", "triangulation"}) {
    const auto csv = dir.path() / (std::string(table) + ".csv");
    const auto log = dir.path() / (std::string(table) + ".txt");
    ASSERT_EQ(test::runGem(std::string("bench --table ") + table + " --sizes 50 200 --reps 3 --csv " + csv.string(), log), 0)
        << test::readFile(log);
    const std::string text = test::readFile(log);
    EXPECT_NE(text.find("CPU: "), std::string::npos) << text;
    EXPECT_NE(text.find("GPU: "), std::string::npos) << text;
    const std::string rows = test::readFile(csv);
    EXPECT_EQ(rows.rfind(std::string("table,n,cpu_ms"), 0), 0u) << rows;
    EXPECT_NE(rows.find(std::string(table) + ",50,"), std::string::npos) << rows;
    EXPECT_NE(rows.find(std::string(table) + ",200,"), std::string::npos) << rows;
  }
}

TEST(GemBench, UnknownTableIsBadInput) {
  TempDir dir;
  EXPECT_EQ(test::runGem("bench --table nonsense", dir.path() / "log.txt"), 2);
  EXPECT_NE(test::readFile(dir.path() / "log.txt")
                .find("valid tables are step, fields, blocks, copyback, scaling, intersection, triangulation, resident, cpu, all"),
            std::string::npos);
}
