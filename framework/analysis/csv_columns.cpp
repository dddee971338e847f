// Numeric columns of a CSV by name (csv_columns.hpp): shared by gem analyze and gem plot.
#include "framework/analysis/csv_columns.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

double parseNumber(const std::string& text, const fs::path& file, int line, const std::string& column) {
  std::string s = text;
  while (!s.empty() && (s.back() == '\r' || s.back() == ' ')) s.pop_back();
  double v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || end != s.data() + s.size() || s.empty())
    throw InputError(file.string(), line, 0, fmt::format("column {}: \"{}\" is not a number", column, text));
  return v;
}

// The values a column of GEM's own files can hold: an edited file outside them is refused (naming
// the line) rather than plotted (an apex of 1e7 deg made a 5-degree histogram of 150 MB).
struct ColumnRange {
  const char* column;
  double lo, hi;
  const char* why;
};
constexpr ColumnRange kColumnRanges[] = {
    {"apex_deg", 0, 180, "an apex angle is 0 to 180 degrees"},
    {"y_from_centerline", -1e4, 1e4, "no hull is 20 km wide"},
    {"x_from_stem", -1e5, 1e5, "no hull is 100 km long"},
};

}  // namespace

std::vector<std::string> readCsvHeader(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot be opened");
  std::string line;
  if (!std::getline(in, line)) throw InputError(file.string(), 1, 0, "empty file: expected a header row");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return splitCsv(line);
}

std::vector<std::vector<double>> readColumns(const fs::path& file, const std::vector<std::string>& wanted, bool emptyIsNaN) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot be opened");
  std::string line;
  if (!std::getline(in, line)) throw InputError(file.string(), 1, 0, "empty file: expected a header row");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const std::vector<std::string> header = splitCsv(line);
  std::vector<size_t> index;
  for (const std::string& w : wanted) {
    const auto it = std::find(header.begin(), header.end(), w);
    if (it == header.end()) throw InputError(file.string(), 1, 0, fmt::format("no column \"{}\" in the header", w));
    index.push_back(size_t(it - header.begin()));
  }
  std::vector<std::vector<double>> columns(wanted.size());
  for (int lineNo = 2; std::getline(in, line); ++lineNo) {
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> cells = splitCsv(line);
    if (cells.size() != header.size())
      throw InputError(file.string(), lineNo, 0, fmt::format("{} cells, the header has {}", cells.size(), header.size()));
    for (size_t c = 0; c < wanted.size(); ++c) {
      const std::string& text = cells[index[c]];
      const bool blank = text.empty() || text == "\r";
      const double v = emptyIsNaN && blank ? NAN : parseNumber(text, file, lineNo, wanted[c]);
      for (const ColumnRange& r : kColumnRanges)
        if (wanted[c] == r.column && std::isfinite(v) && !(v >= r.lo && v <= r.hi))
          throw InputError(file.string(), lineNo, 0, fmt::format("column {}: {} is outside {} to {} ({})", r.column, v, r.lo, r.hi, r.why));
      columns[c].push_back(v);
    }
  }
  return columns;
}

}  // namespace gem
