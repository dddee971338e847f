// readCsvTable: a character-level RFC 4180 reader (quoted fields may span lines).
#include "framework/analysis/csv_table.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include "framework/api/errors.hpp"

namespace gem {

int CsvTable::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : static_cast<int>(it - header.begin());
}

std::vector<double> CsvTable::numbers(const std::string& name) const {
  const int c = column(name);
  if (c < 0) throw InputError(file.string(), 1, 0, fmt::format("no column \"{}\" in the header", name));
  std::vector<double> values;
  values.reserve(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    std::string_view s = rows[r][size_t(c)];
    while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    if (s.starts_with('+')) s.remove_prefix(1);
    // Empty cells are "no value" (timeseries.csv's ship columns in a run without a vessel).
    double v = std::numeric_limits<double>::quiet_NaN();
    if (!s.empty()) {
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec != std::errc() || end != s.data() + s.size())
        throw InputError(file.string(), lines[r], 0, fmt::format("column {}: \"{}\" is not a number", name, rows[r][size_t(c)]));
    }
    values.push_back(v);
  }
  return values;
}

CsvTable readCsvTable(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be opened");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file.string() + ": cannot be read");

  CsvTable table;
  table.file = file;
  std::vector<std::string> cells(1);
  bool quoted = false, anyText = false;
  int line = 1, rowLine = 1;
  // Ends the current record: the first is the header, blank lines are skipped.
  const auto endRow = [&] {
    if (anyText) {
      if (table.header.empty()) {
        table.header = std::move(cells);
      } else {
        if (cells.size() != table.header.size())
          throw InputError(file.string(), rowLine, 0, fmt::format("{} cells, the header has {}", cells.size(), table.header.size()));
        table.rows.push_back(std::move(cells));
        table.lines.push_back(rowLine);
      }
    }
    cells.assign(1, std::string());
    anyText = false;
    rowLine = line;
  };
  // One pass over the characters: a quoted field may hold the line breaks and commas that a split
  // by lines, then by commas, would cut it at.
  for (size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c == '"' && i + 1 < text.size() && text[i + 1] == '"') {
        cells.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        if (c == '\n') ++line;
        cells.back() += c;
      }
      continue;
    }
    if (c == '"') {
      quoted = anyText = true;
    } else if (c == ',') {
      cells.emplace_back();
      anyText = true;
    } else if (c == '\n') {
      ++line;
      endRow();
    } else if (c != '\r') {  // a Windows line end is a line end
      cells.back() += c;
      anyText = true;
    }
  }
  if (quoted) throw InputError(file.string(), rowLine, 0, "a quoted field is not closed");
  endRow();
  if (table.header.empty()) throw InputError(file.string(), 1, 0, "empty file: expected a header row");
  return table;
}

}  // namespace gem
