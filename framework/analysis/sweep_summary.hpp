// Gathering a sweep: reading the runs' summary.json files and writing summary.csv (sweep.hpp).
#pragma once
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "framework/scenario/sweep_file.hpp"

namespace gem {

// The flat numbers and strings of a summary.json (the subset of JSON GEM writes: objects, numbers,
// strings, true/false/null; arrays are skipped), nested objects flattened to "ship_speed.mean".
// Numbers are written back in their shortest exact form ("1e3" reads as "1000.0"); null is "". Throws InputError (the file and the offset)
// if malformed or nested more than 64 deep; its message ends with `remedy`, what the reader who
// met the file can do (a sweep runs the case again; `gem view` once gave a sweep's advice too).
std::map<std::string, std::string> readSummaryJson(const std::filesystem::path& file, const std::string& remedy);
// The same with a sweep's advice: "delete it, and the sweep runs that case again".
std::map<std::string, std::string> readSummaryJson(const std::filesystem::path& file);

// The summary quantities of summary.csv, after name and the varied keys.
const std::vector<std::string>& sweepSummaryColumns();

// Writes DIR/summary.csv (atomically) from every case whose folder holds a summary.json, in case
// order; returns the number of rows. caseDirs[i] is the folder of case i.
int writeSweepSummary(const SweepDefinition& sweep, const std::filesystem::path& csv, const std::vector<std::filesystem::path>& caseDirs);

}  // namespace gem
