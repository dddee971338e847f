// Reading a sweep file (format in sweep.hpp) and expanding it into its cases, in order.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

// One scenario key set by a sweep: becomes loadScenario's "key=toml" override.
struct SweepOverride {
  std::string key;           // dotted scenario key
  std::string toml;          // the value in TOML syntax
  std::string text;          // the value for names and summary.csv: shortest numbers, bare strings
  bool varied = false;       // a column of summary.csv (from a case's set or [parameters], not sweep.set)
  int line = 0, column = 0;  // where the sweep file gives it
};

struct SweepCase {
  std::string name;
  std::filesystem::path base;            // absolute
  std::vector<SweepOverride> overrides;  // in the order they apply
  int line = 0, column = 0;              // its [[cases]] entry, else [parameters]
};

struct SweepDefinition {
  std::filesystem::path file;  // absolute
  std::string fileName;        // as given, for messages
  std::string name;
  std::vector<std::string> columns;  // the varied keys, [parameters] first, then the cases' set keys
  std::vector<SweepCase> cases;
};

// Throws InputError (file:line:column) for a malformed sweep file. Checks that every base exists;
// the scenarios themselves are checked by the caller.
SweepDefinition readSweepFile(const std::filesystem::path& file);

// The value of `key` among a case's varied overrides ("" when it does not set it).
std::string sweepCell(const SweepCase& c, const std::string& key);

}  // namespace gem
