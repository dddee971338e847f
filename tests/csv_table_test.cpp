// readCsvTable: quoted fields (commas, doubled quotes, line breaks), empty cells, and bad rows.
#include <gtest/gtest.h>

#include <cmath>

#include "framework/analysis/csv_table.hpp"
#include "framework/api/errors.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;

TEST(CsvTable, ReadsQuotedFieldsAndEmptyCells) {
  TempDir dir;
  const auto file = dir.write("t.csv", "name,t,v\r\n\"a,b\",1,2\n\n\"say \"\"hi\"\"\nthere\",2.5,\n");
  const CsvTable table = readCsvTable(file);
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.rows[0][0], "a,b");
  EXPECT_EQ(table.rows[1][0], "say \"hi\"\nthere");
  EXPECT_EQ(table.lines[1], 4);  // where the row starts, past the blank line
  const std::vector<double> v = table.numbers("v");
  EXPECT_DOUBLE_EQ(v[0], 2);
  EXPECT_TRUE(std::isnan(v[1]));
  EXPECT_EQ(table.column("missing"), -1);
}

TEST(CsvTable, RefusesBadRowsAndCellsNamingTheLine) {
  TempDir dir;
  try {
    readCsvTable(dir.write("short.csv", "a,b\n1,2\n3\n"));
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv:3"), std::string::npos) << e.what();
  }
  const CsvTable table = readCsvTable(dir.write("word.csv", "a\n1\nx\n"));
  try {
    table.numbers("a");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("word.csv:3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(table.numbers("b"), InputError);
  EXPECT_THROW(readCsvTable(dir.write("open.csv", "a\n\"1\n")), InputError);
  EXPECT_THROW(readCsvTable(dir.path() / "absent.csv"), InputError);
}
