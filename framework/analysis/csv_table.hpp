// A CSV file with a header row, read whole (RFC 4180: quoted fields may hold commas, doubled quotes
// and line breaks; csvField in framework/output/csv_field.hpp writes them). For the run folder's
// tables (timeseries.csv, impacts.csv) read by gem view.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

struct CsvTable {
  std::filesystem::path file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // each row's line in the file, for messages

  // The column's index, or -1 when the header has no such column.
  int column(const std::string& name) const;
  // The column as numbers: an empty cell is NaN. Throws InputError (file:line, column) for a cell
  // that is not a number, or when the header lacks the column.
  std::vector<double> numbers(const std::string& name) const;
};

// Throws InputError naming the file when it cannot be read, is empty, has an unterminated quote, or
// has a row whose cell count differs from the header's (file:line). Blank lines are skipped.
CsvTable readCsvTable(const std::filesystem::path& file);

}  // namespace gem
