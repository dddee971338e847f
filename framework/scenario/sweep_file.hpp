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
  std::string name;                      // the row label of summary.csv; may hold ',' and '='
  std::string folder;                    // its folder under cases/: caseFolderName(name), unique
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

// Whether file is a sweep file: TOML whose top level holds a [sweep] table (gem check takes a
// scenario or a sweep). False for a file that cannot be read or parsed: its loader says why.
bool isSweepFile(const std::filesystem::path& file);

// A case name as a folder name of only [A-Za-z0-9._-], safe in a shell and in tools that split on
// commas or '=': '=' and '#' become '-', ',' becomes '_', '+' is dropped ("1e+06" -> "1e06"), any
// other character becomes '_'; a name that would start with '.' or '-' gets a leading '_'.
// readSweepFile makes the folders of one sweep unique (a suffix "_2", "_3", ... on a clash).
std::string caseFolderName(const std::string& name);

// The value of `key` among a case's varied overrides ("" when it does not set it).
std::string sweepCell(const SweepCase& c, const std::string& key);

}  // namespace gem
