// The CSV module (csv.hpp): one character-level RFC 4180 reader and the writer's quoting.
#include "framework/output/csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"

namespace gem {

namespace fs = std::filesystem;

namespace {

// The values a column of GEM's own files can hold: an edited file outside them is refused (naming
// the line) rather than plotted (an apex of 1e7 deg made a 5-degree histogram of 150 MB).
struct ColumnRange {
  const char* column;
  double lo, hi;
  const char* why;
  bool whole = false;  // a count, an id or a flag: a whole number
};
constexpr double kAnyFinite = std::numeric_limits<double>::max();
constexpr ColumnRange kColumnRanges[] = {
    {"apex_deg", 0, 180, "an apex angle is 0 to 180 degrees"},
    {"y_from_centerline", -1e4, 1e4, "no hull is 20 km wide"},
    {"x_from_stem", -1e5, 1e5, "no hull is 100 km long"},
    // Far past any load GEM computes (MN at most), and small enough that sums of 10^7 rows stay finite.
    {"fn", -1e15, 1e15, "no impact force reaches 1e15 N"},
    {"flim", 0, 1e15, "a force limit is 0 to 1e15 N"},
    {"vn", -1e6, 1e6, "no impact speed reaches 1000 km/s"},
    {"floe_mass", std::numeric_limits<double>::min(), 1e15, "a floe's mass is positive, and none weighs 1e15 kg"},
    {"thickness", 0.01, 1000, "a floe is 0.01 to 1000 m thick"},
    {"floe_id", 0, 9007199254740992.0, "an id is a whole number from 0", true},
    {"broke", 0, 1, "broke is 0 or 1", true},
    {"x", -kAnyFinite, kAnyFinite, "a finite number"},
    {"y", -kAnyFinite, kAnyFinite, "a finite number"},
    {"t", 0, 1e15, "a run's time is 0 to 1e15 s"},
    // timeseries.csv: any finite number (a run stops before it writes another), counts whole.
    {"ship_speed", -kAnyFinite, kAnyFinite, "a finite number"},
    {"net_thrust", -kAnyFinite, kAnyFinite, "a finite number"},
    {"ice_force_x", -kAnyFinite, kAnyFinite, "a finite number"},
    {"contacts", 0, 2147483647.0, "a count is a whole number from 0", true},
};

}  // namespace

std::string csvQuoted(std::string_view text) {
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string csvField(std::string_view text) {
  const bool spaced = !text.empty() && (text.front() == ' ' || text.back() == ' ');
  if (!spaced && text.find_first_of(",\"\n\r") == std::string_view::npos) return std::string(text);
  return csvQuoted(text);
}

std::string csvRow(const std::vector<std::string>& fields) {
  std::string out;
  for (size_t k = 0; k < fields.size(); ++k) {
    if (k > 0) out += ',';
    out += csvField(fields[k]);
  }
  return out + "\n";
}

CsvRecords parseCsvRecords(std::string_view text, const std::string& file) {
  CsvRecords records;
  std::vector<std::string> cells(1);
  bool quoted = false, anyText = false;
  int line = 1, rowLine = 1;
  // Ends the current record; a blank line is no record.
  const auto endRow = [&] {
    if (anyText) {
      records.cells.push_back(std::move(cells));
      records.lines.push_back(rowLine);
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
  if (quoted) throw InputError(file, rowLine, 0, "a quoted field is not closed");
  endRow();
  return records;
}

int CsvTable::column(const std::string& name) const {
  const auto it = std::find(header.begin(), header.end(), name);
  return it == header.end() ? -1 : static_cast<int>(it - header.begin());
}

std::vector<double> CsvTable::numbers(const std::string& name, bool emptyIsNaN) const {
  const int c = column(name);
  if (c < 0) throw InputError(file.string(), 1, 0, fmt::format("no column \"{}\" in the header", name));
  std::vector<double> values;
  values.reserve(rows.size());
  for (size_t r = 0; r < rows.size(); ++r) {
    std::string_view s = rows[r][size_t(c)];
    while (!s.empty() && s.back() == ' ') s.remove_suffix(1);
    while (!s.empty() && s.front() == ' ') s.remove_prefix(1);
    if (s.starts_with('+')) s.remove_prefix(1);
    double v = std::numeric_limits<double>::quiet_NaN();
    if (s.empty() && !emptyIsNaN)
      throw InputError(file.string(), lines[r], 0, fmt::format("column {}: \"{}\" is not a number", name, rows[r][size_t(c)]));
    if (!s.empty()) {
      const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
      if (ec != std::errc() || end != s.data() + s.size())
        throw InputError(file.string(), lines[r], 0, fmt::format("column {}: \"{}\" is not a number", name, rows[r][size_t(c)]));
    }
    values.push_back(v);
  }
  return values;
}

CsvTable parseCsvTable(std::string_view text, const fs::path& file) {
  CsvRecords records = parseCsvRecords(text, file.string());
  if (records.cells.empty()) throw InputError(file.string(), 1, 0, "empty file: expected a header row");
  CsvTable table;
  table.file = file;
  table.header = std::move(records.cells.front());
  for (size_t r = 1; r < records.cells.size(); ++r) {
    if (records.cells[r].size() != table.header.size())
      throw InputError(file.string(), records.lines[r], 0,
                       fmt::format("{} cells, the header has {}", records.cells[r].size(), table.header.size()));
    table.rows.push_back(std::move(records.cells[r]));
    table.lines.push_back(records.lines[r]);
  }
  return table;
}

CsvTable readCsvTable(const fs::path& file) {
  requireRegularFile(file, "CSV file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be opened");
  requireFitsInMemory(file, 6);  // the text, and its cells as strings
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw InputError(file.string() + ": cannot be read");
  return parseCsvTable(text, file);
}

std::vector<std::string> readCsvHeader(const fs::path& file) { return readCsvTable(file).header; }

std::vector<std::vector<double>> readColumns(const fs::path& file, const std::vector<std::string>& wanted, bool emptyIsNaN) {
  const CsvTable table = readCsvTable(file);
  for (const std::string& w : wanted)
    if (table.column(w) < 0) throw InputError(file.string(), 1, 0, fmt::format("no column \"{}\" in the header", w));
  std::vector<std::vector<double>> columns;
  for (const std::string& w : wanted) {
    columns.push_back(table.numbers(w, emptyIsNaN));
    for (const ColumnRange& r : kColumnRanges) {
      if (w != r.column) continue;
      const int c = table.column(w);
      for (size_t k = 0; k < columns.back().size(); ++k) {
        const double v = columns.back()[k];
        // NaN stands for an empty cell only: "nan" or "inf" written in one is refused too.
        const bool empty = std::isnan(v) && table.rows[k][static_cast<size_t>(c)].find_first_not_of(' ') == std::string::npos;
        if (!empty && !(v >= r.lo && v <= r.hi))
          throw InputError(file.string(), table.lines[k], 0,
                           r.lo == -kAnyFinite ? fmt::format("column {}: {} is not {}", r.column, v, r.why)
                                               : fmt::format("column {}: {} is outside {} to {} ({})", r.column, v, r.lo, r.hi, r.why));
        if (!empty && r.whole && v != std::floor(v))
          throw InputError(file.string(), table.lines[k], 0, fmt::format("column {}: {} is not a whole number ({})", r.column, v, r.why));
      }
    }
  }
  return columns;
}

}  // namespace gem
