// The CSV module (framework/output/csv.hpp): quoted fields (commas, doubled quotes, line breaks),
// empty cells, bad rows naming file:line, nasty fields round-tripping through the writer, and
// numeric columns by name.
#include <gtest/gtest.h>

#include <cmath>

#include "framework/output/csv.hpp"
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

// Every nasty field comes back as it was written: commas, quotes, CR/LF, leading and trailing
// spaces, empty fields, and a row of nothing but empties.
TEST(Csv, NastyFieldsRoundTrip) {
  const std::vector<std::vector<std::string>> rows = {
      {"name", "value", "note"}, {"a,b", "say \"hi\"", "line\r\nbreak"}, {"  leading", "trailing  ", ""}, {"", "", ""},
      {"\"", ",", "\n"},         {"plain", "1.5", "cr\ronly"},
  };
  std::string text;
  for (const auto& row : rows) text += csvRow(row);
  TempDir dir;
  const CsvTable table = readCsvTable(dir.write("nasty.csv", text));
  ASSERT_EQ(table.header, rows[0]);
  ASSERT_EQ(table.rows.size(), rows.size() - 1);
  for (size_t r = 1; r < rows.size(); ++r) EXPECT_EQ(table.rows[r - 1], rows[r]) << "row " << r;
  // The same text with Windows line ends between the records reads the same.
  std::string crlf;
  for (const auto& row : rows) {
    std::string line = csvRow(row);
    line.insert(line.size() - 1, "\r");
    crlf += line;
  }
  const CsvTable windows = parseCsvTable(crlf, "crlf.csv");
  ASSERT_EQ(windows.rows.size(), rows.size() - 1);
  for (size_t r = 1; r < rows.size(); ++r) EXPECT_EQ(windows.rows[r - 1], rows[r]) << "row " << r;
}

// Fields that need no quoting are written as they are: every numeric output keeps its bytes.
TEST(Csv, PlainFieldsAreNotQuoted) {
  EXPECT_EQ(csvField("1.5e-07"), "1.5e-07");
  EXPECT_EQ(csvField("random_35"), "random_35");
  EXPECT_EQ(csvField(""), "");
  EXPECT_EQ(csvField("a,b"), "\"a,b\"");
  EXPECT_EQ(csvField("x\"y"), "\"x\"\"y\"");
  EXPECT_EQ(csvField(" x"), "\" x\"");
  EXPECT_EQ(csvQuoted("1 2 3 4"), "\"1 2 3 4\"");
  EXPECT_EQ(csvRow({"t", "a,b", ""}), "t,\"a,b\",\n");
}

TEST(Csv, ColumnsByNameNameFileAndLine) {
  TempDir dir;
  const auto file = dir.write("c.csv", "t,\"x,y\",apex_deg\n0,1,30\n1,,40\n");
  const auto columns = readColumns(file, {"apex_deg", "t"});
  EXPECT_EQ(columns[0], (std::vector<double>{30, 40}));
  EXPECT_EQ(readCsvHeader(file)[1], "x,y");
  try {
    readColumns(file, {"x,y"});
    FAIL() << "an empty cell is no number without emptyIsNaN";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("c.csv:3"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(std::isnan(readColumns(file, {"x,y"}, true)[0][1]));
  try {
    readColumns(dir.write("far.csv", "apex_deg\n30\n400\n"), {"apex_deg"});
    FAIL() << "an apex angle beyond 180 degrees is refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("far.csv:3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readColumns(file, {"missing"}), InputError);
}
