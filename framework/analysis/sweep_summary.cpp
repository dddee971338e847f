#include "framework/analysis/sweep_summary.hpp"

#include <fstream>
#include <iterator>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/csv.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

// Flattens a parsed summary.json into "key" and "object.key" entries: numbers as nlohmann writes
// them back (the shortest text that reads back to the same double), strings unescaped, null as "".
// Arrays are skipped: no summary column comes from one.
void flatten(const nlohmann::json& value, const std::string& key, std::map<std::string, std::string>& out) {
  if (value.is_object()) {
    for (const auto& [name, child] : value.items()) flatten(child, key.empty() ? name : key + "." + name, out);
  } else if (value.is_string()) {
    out[key] = value.get<std::string>();
  } else if (value.is_null()) {
    out[key] = "";
  } else if (!value.is_array()) {
    out[key] = value.dump();
  }
}

// summary.csv column -> summary.json key.
const std::vector<std::pair<std::string, std::string>>& columnKeys() {
  static const std::vector<std::pair<std::string, std::string>> keys = {
      {"impacts", "impacts"},
      {"ship_speed_min", "ship_speed.min"},
      {"ship_speed_mean", "ship_speed.mean"},
      {"ship_speed_max", "ship_speed.max"},
      {"impact_force_min", "impact_force_n.min"},
      {"impact_force_mean", "impact_force_n.mean"},
      {"impact_force_max", "impact_force_n.max"},
      {"resistance_mean", "resistance_mean_n"},
      {"wall_time_s", "wall_time_s"},
      // Beyond the list: the means over the steady part of the transit (hull in the field).
      {"ship_speed_in_ice_mean", "ship_speed_in_ice.mean"},
      {"resistance_in_ice_mean", "resistance_in_ice_n"},
      // The impacts over the same window (the transit, thesis 6.2.2.2).
      {"impacts_in_ice", "impacts_in_ice"},
      {"impact_force_in_ice_mean", "impact_force_in_ice_n.mean"},
  };
  return keys;
}

}  // namespace

std::map<std::string, std::string> readSummaryJson(const fs::path& file, const std::string& remedy) {
  requireRegularFile(file, "summary.json");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("cannot read " + file.string());
  const std::string text(std::istreambuf_iterator<char>(in), {});
  // Bad input like any other (exit 2): a damaged file in a sweep's folder, not an internal error.
  auto malformed = [&](const std::string& what) {
    return InputError(fmt::format("{}: malformed JSON: {} ({})", file.string(), what, remedy));
  };
  constexpr int kMostDepth = 64;  // GEM writes 2 levels; a hostile file must not exhaust the stack
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(text, [&](int depth, nlohmann::json::parse_event_t, nlohmann::json&) {
      if (depth > kMostDepth) throw malformed(fmt::format("nested more than {} deep", kMostDepth));
      return true;
    });
  } catch (const nlohmann::json::exception& e) {
    throw malformed(e.what());
  }
  if (!root.is_object()) throw malformed("expected an object {...}");
  // The values summary.csv takes are numbers (or null): a case whose summary says "impacts":
  // "lots" is not a finished case, and "lots" once reached a numeric column of summary.csv.
  for (const auto& [column, key] : columnKeys()) {
    const nlohmann::json* value = &root;
    for (size_t at = 0; value && at <= key.size();) {
      const size_t dot = std::min(key.find('.', at), key.size());
      const auto it = value->is_object() ? value->find(key.substr(at, dot - at)) : value->end();
      value = value->is_object() && it != value->end() ? &*it : nullptr;
      at = dot + 1;
    }
    if (value && !value->is_number() && !value->is_null())
      throw malformed(fmt::format("\"{}\" is {}, not a number", key, value->dump().substr(0, 40)));
  }
  std::map<std::string, std::string> out;
  flatten(root, "", out);
  return out;
}

std::map<std::string, std::string> readSummaryJson(const fs::path& file) {
  return readSummaryJson(file, "delete it, and the sweep runs that case again");
}

const std::vector<std::string>& sweepSummaryColumns() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> n;
    for (const auto& [column, key] : columnKeys()) n.push_back(column);
    return n;
  }();
  return names;
}

int writeSweepSummary(const SweepDefinition& sweep, const fs::path& csv, const std::vector<fs::path>& caseDirs) {
  AtomicFile out(csv);
  std::vector<std::string> header{"name"};
  header.insert(header.end(), sweep.columns.begin(), sweep.columns.end());
  header.insert(header.end(), sweepSummaryColumns().begin(), sweepSummaryColumns().end());
  out.stream() << csvRow(header);
  int rows = 0;
  for (size_t i = 0; i < sweep.cases.size(); ++i) {
    const fs::path json = caseDirs[i] / "summary.json";
    if (!fs::exists(json)) continue;
    const std::map<std::string, std::string> summary = readSummaryJson(json);
    if (auto completed = summary.find("completed"); completed != summary.end() && completed->second == "false") continue;
    const SweepCase& c = sweep.cases[i];
    std::vector<std::string> row{c.name};
    for (const std::string& key : sweep.columns) row.push_back(sweepCell(c, key));
    for (const auto& [column, key] : columnKeys()) {
      auto it = summary.find(key);
      row.push_back(it == summary.end() ? "" : it->second);
    }
    out.stream() << csvRow(row);
    ++rows;
  }
  out.commit();
  return rows;
}

}  // namespace gem
