// GEM's one CSV module (RFC 4180), for every file GEM writes or reads as CSV: quoting a field,
// writing a row, reading a file into its header and rows (quoted fields may hold commas, doubled
// quotes and line breaks; CRLF line ends), and numeric columns by name with errors naming
// file:line. Nothing else in GEM splits or quotes CSV by hand.
#pragma once
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace gem {

// The field as it is, or quoted with its quotes doubled when it holds a comma, a quote, a line
// break, or leading/trailing spaces (which many readers trim). Numbers never need quoting, so
// rows of numbers are the same bytes as before there was a module.
std::string csvField(std::string_view text);
// The field always quoted (quotes doubled): for the columns GEM has always quoted (state.csv's
// vertices, the device names of gem bench), whose bytes must not change.
std::string csvQuoted(std::string_view text);
// The fields through csvField, joined by commas, with a "\n" at the end.
std::string csvRow(const std::vector<std::string>& fields);

// Every record of the text (blank lines skipped), each with the line it starts on. Throws
// InputError naming file:line for a quoted field that is never closed.
struct CsvRecords {
  std::vector<std::vector<std::string>> cells;
  std::vector<int> lines;
};
CsvRecords parseCsvRecords(std::string_view text, const std::string& file = "CSV");

struct CsvTable {
  std::filesystem::path file;
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  std::vector<int> lines;  // each row's line in the file, for messages

  // The column's index, or -1 when the header has no such column.
  int column(const std::string& name) const;
  // The column as numbers (spaces around a number and a leading '+' allowed). An empty cell is
  // NaN, or with emptyIsNaN false an InputError. Throws InputError (file:line, column) for a cell
  // that is not a number, or when the header lacks the column.
  std::vector<double> numbers(const std::string& name, bool emptyIsNaN = true) const;
};

// Parses text as a table: the first record is the header. Throws InputError (file:line) for a
// row whose cell count differs from the header's, an unclosed quote, or no header at all.
CsvTable parseCsvTable(std::string_view text, const std::filesystem::path& file);
// Reads and parses a file; throws InputError naming it when it cannot be read.
CsvTable readCsvTable(const std::filesystem::path& file);

// The header row's column names.
std::vector<std::string> readCsvHeader(const std::filesystem::path& file);

// GEM's own outputs (impacts.csv, timeseries.csv) as numeric columns by name, strictly: the columns
// asked for, in that order. Throws InputError when the file cannot be opened, a column is missing,
// a row has the wrong number of cells, a cell is not a number (an empty one is allowed with
// emptyIsNaN: timeseries.csv leaves the vessel's columns empty in a run without one) or a value
// lies outside what GEM writes (an apex angle beyond 180 degrees), naming file:line.
std::vector<std::vector<double>> readColumns(const std::filesystem::path& file, const std::vector<std::string>& wanted,
                                             bool emptyIsNaN = false);

}  // namespace gem
