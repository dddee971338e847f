// Reading GEM's own CSV outputs (impacts.csv, timeseries.csv) as numeric columns by name, strictly:
// a malformed line or a value outside what GEM writes is an InputError naming file:line.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

// The header row's column names.
std::vector<std::string> readCsvHeader(const std::filesystem::path& file);

// The columns asked for, in that order; throws InputError when the file cannot be opened, a column
// is missing, a row has the wrong number of cells or a cell is not a number. With emptyIsNaN an
// empty cell reads as NaN (timeseries.csv leaves the vessel's columns empty in a run without one).
std::vector<std::vector<double>> readColumns(const std::filesystem::path& file, const std::vector<std::string>& wanted,
                                             bool emptyIsNaN = false);

}  // namespace gem
