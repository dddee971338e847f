// readSweepCases (sweep_cases.hpp): a sweep's cases as gem analyze groups them.
#include "framework/analysis/sweep_cases.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "framework/analysis/sweep_summary.hpp"
#include "framework/api/input_size.hpp"
#include "framework/api/errors.hpp"
#include "framework/output/csv.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

// A value as a group label shows it: shortest round-trip numbers and bare strings (as summary.csv's
// cells), arrays and tables inline without spaces.
std::string valueText(const toml::node& v) {
  if (auto d = v.value_exact<double>()) return fmt::format("{}", *d);
  if (auto i = v.value_exact<std::int64_t>()) return fmt::format("{}", *i);
  if (auto b = v.value_exact<bool>()) return *b ? "true" : "false";
  if (auto s = v.value_exact<std::string>()) return *s;
  std::string out;
  if (const toml::array* a = v.as_array()) {
    for (const toml::node& e : *a) {
      out += out.empty() ? '[' : ',';  // appended one by one: GCC 12 warns falsely (-Wrestrict) on "x" + string&&
      out += valueText(e);
    }
    return out.empty() ? "[]" : out + "]";
  }
  if (const toml::table* t = v.as_table()) {
    for (const auto& [k, e] : *t) {
      out += out.empty() ? '{' : ',';
      out += k.str();
      out += '=';
      out += valueText(e);
    }
    return out.empty() ? "{}" : out + "}";
  }
  return "";
}

double valueNumber(const toml::table& root, const std::string& key) {
  const toml::node_view<const toml::node> v = root.at_path(key);
  if (auto d = v.value_exact<double>()) return *d;
  if (auto i = v.value_exact<std::int64_t>()) return static_cast<double>(*i);
  return NAN;
}

// case.toml's header: `# Case "NAME" of the sweep FILE (gem sweep)` and `# base: PATH`. A case
// name cannot hold a quote (sweep_file.cpp), so the first `" of the sweep ` ends it.
void readCaseHeader(const fs::path& file, SweepCaseInfo& info) {
  requireRegularFile(file, "case.toml");
  std::ifstream in(file);
  const std::string caseMark = "# Case \"", nameEnd = "\" of the sweep ", baseMark = "# base: ";
  for (std::string line; std::getline(in, line) && line.rfind("#", 0) == 0;) {
    if (line.rfind(caseMark, 0) == 0 && line.find(nameEnd) != std::string::npos)
      info.name = line.substr(caseMark.size(), line.find(nameEnd) - caseMark.size());
    else if (line.rfind(baseMark, 0) == 0)
      info.base = fs::path(line.substr(baseMark.size())).stem().string();
  }
}

}  // namespace

bool isUngroupedKey(const std::string& key) { return key == "vessel.bollard_thrust" || key == "simulation.seed"; }

SweepCases readSweepCases(const fs::path& sweepDir) {
  SweepCases sweep;
  if (fs::exists(sweepDir / "summary.csv")) {
    const std::vector<std::string> header = readCsvHeader(sweepDir / "summary.csv");
    const std::vector<std::string>& results = sweepSummaryColumns();
    for (size_t k = 1; k < header.size() && std::find(results.begin(), results.end(), header[k]) == results.end(); ++k)
      sweep.variedKeys.push_back(header[k]);
  }
  std::vector<fs::path> dirs;
  if (fs::is_directory(sweepDir / "cases"))
    for (const fs::directory_entry& e : fs::directory_iterator(sweepDir / "cases"))
      if (e.is_directory()) dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());
  for (const fs::path& dir : dirs) {
    SweepCaseInfo info{dir, dir.filename().string(), "", {}, "", NAN, NAN, false};
    if (fs::exists(dir / "case.toml")) readCaseHeader(dir / "case.toml", info);
    toml::table root;
    info.ran = fs::exists(dir / "scenario.toml");
    if (info.ran) {
      try {
        root = toml::parse_file((dir / "scenario.toml").string());
      } catch (const toml::parse_error& e) {
        throw InputError((dir / "scenario.toml").string(), static_cast<int>(e.source().begin.line),
                         static_cast<int>(e.source().begin.column), std::string(e.description()));
      }
    }
    for (const std::string& key : sweep.variedKeys) {
      const toml::node* node = root.at_path(key).node();
      info.values.push_back(node ? valueText(*node) : "");
    }
    info.concentration = valueNumber(root, "field.concentration");
    info.thrust = valueNumber(root, "vessel.bollard_thrust");
    sweep.cases.push_back(std::move(info));
  }

  // The label names only what tells the groups apart: a key (or the base) with one value in every
  // case that ran (has its scenario.toml; a folder the sweep only created knows nothing) is left
  // out. Keys by their last part unless two share it.
  const bool anyRan = std::any_of(sweep.cases.begin(), sweep.cases.end(), [](const SweepCaseInfo& c) { return c.ran; });
  const auto differs = [&](auto value) {
    std::set<std::string> seen;
    for (const SweepCaseInfo& c : sweep.cases)
      if (c.ran || !anyRan) seen.insert(value(c));
    return seen.size() > 1;
  };
  const bool byBase = differs([](const SweepCaseInfo& c) { return c.base; });
  std::vector<size_t> keys;
  std::vector<std::string> shortNames;
  for (size_t k = 0; k < sweep.variedKeys.size(); ++k) {
    const std::string& key = sweep.variedKeys[k];
    shortNames.push_back(key.substr(key.rfind('.') == std::string::npos ? 0 : key.rfind('.') + 1));
    if (!isUngroupedKey(key) && differs([k](const SweepCaseInfo& c) { return c.values[k]; })) keys.push_back(k);
  }
  for (SweepCaseInfo& c : sweep.cases) {
    std::string label = byBase ? c.base : "";
    for (size_t k : keys) {
      const bool shared = std::count(shortNames.begin(), shortNames.end(), shortNames[k]) > 1;
      label += (label.empty() ? "" : ",") + (shared ? sweep.variedKeys[k] : shortNames[k]) + "=" + c.values[k];
    }
    c.group = label.empty() ? "all" : label;
  }
  return sweep;
}

}  // namespace gem
