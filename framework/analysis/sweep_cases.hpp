// What gem analyze knows of a sweep's cases, read from the sweep folder alone, never from a case's
// name: the varied keys (summary.csv's columns after "name"), and per case folder its name and
// base scenario (the comment lines gem sweep writes at the top of case.toml) and the values of its
// inputs (its own scenario.toml, the run's record). Cases group by the values of the varied keys
// other than vessel.bollard_thrust and simulation.seed (a study's thrusts and repeats of one ice
// condition), and by their base scenario when the cases' bases differ.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

struct SweepCaseInfo {
  std::filesystem::path dir;
  std::string name;                 // from case.toml; the folder's name when there is none
  std::string base;                 // the base scenario's file stem, from case.toml; "" when unknown
  std::vector<std::string> values;  // per SweepCases::variedKeys, from scenario.toml; "" when absent
  std::string group;                // its group's label: "concentration=0.4", "random_35", "all"
  double concentration, thrust;     // field.concentration, vessel.bollard_thrust; NaN when absent
  bool ran;                         // it has its scenario.toml (the run's record)
};

struct SweepCases {
  std::vector<std::string> variedKeys;  // summary.csv's columns between "name" and the results
  std::vector<SweepCaseInfo> cases;     // every folder under cases/, by folder name
};

// The keys that never group cases: a study varies them within one ice condition.
bool isUngroupedKey(const std::string& key);

// Reads DIR/summary.csv's header (no varied keys without one) and every DIR/cases/*/ folder.
// Throws InputError (file:line) for a malformed summary.csv or scenario.toml.
SweepCases readSweepCases(const std::filesystem::path& sweepDir);

}  // namespace gem
