// Numbers appended to a CSV row as printf's "%.Ng" writes them, fast enough for a row every step.
// A record output's writeRow (record_stream.hpp) and the runner's timeseries.csv use it: fmt's
// "{:.9g}" gives the same bytes, but its fixed-precision path falls back on big-number arithmetic
// for many values and cost a quarter of the host's time in the batched load study on a GPU
// (docs/performance.md 3.7). std::to_chars's general format with a precision is specified as
// printf's, so the files do not change (tests/row_text_test.cpp compares the two).
#pragma once
#include <charconv>
#include <cmath>
#include <cstdint>
#include <string>

#include <fmt/format.h>

namespace gem {

// value as "%.{precision}g" (precision 1 to 17); inf and nan as fmt writes them.
inline void appendGeneral(std::string& row, double value, int precision) {
  if (!std::isfinite(value)) {
    fmt::format_to(std::back_inserter(row), "{:.{}g}", value, precision);
    return;
  }
  char text[40];
  const auto written = std::to_chars(text, text + sizeof text, value, std::chars_format::general, precision);
  row.append(text, written.ptr);
}

inline void appendInteger(std::string& row, std::int64_t value) {
  char text[24];
  const auto written = std::to_chars(text, text + sizeof text, value);
  row.append(text, written.ptr);
}

}  // namespace gem
