#include "framework/scenario/sweep_file.hpp"

#include <algorithm>
#include <cctype>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/scenario/toml_limits.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

// A leaf of a set table or of [parameters]: the dotted key and its node in the sweep document.
struct Leaf {
  std::string key;
  const toml::node* node;
};

void flatten(const toml::table& table, const std::string& prefix, std::vector<Leaf>& out) {
  for (const auto& [k, v] : table) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (const toml::table* sub = v.as_table())
      flatten(*sub, key, out);
    else
      out.push_back({key, &v});
  }
}

// toml::table is ordered by key; the user's order (file order) is the source position.
std::vector<Leaf> leaves(const toml::table& table, const TableReader& reader) {
  std::vector<Leaf> out;
  flatten(table, "", out);
  std::stable_sort(out.begin(), out.end(), [](const Leaf& a, const Leaf& b) {
    const auto &sa = a.node->source().begin, &sb = b.node->source().begin;
    return sa.line != sb.line ? sa.line < sb.line : sa.column < sb.column;
  });
  for (size_t i = 0; i < out.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (out[i].key == out[j].key) reader.failAt(*out[i].node, fmt::format("{}: key \"{}\" given twice", reader.path(), out[i].key));
  return out;
}

void makeInline(toml::node& node) {
  if (toml::table* t = node.as_table()) {
    t->is_inline(true);
    for (auto&& [k, v] : *t) makeInline(v);
  } else if (toml::array* a = node.as_array()) {
    for (toml::node& e : *a) makeInline(e);
  }
}

// The value in TOML syntax, one line, as loadScenario's overrides read it (floats round-trip exactly).
std::string tomlText(const toml::node& value) {
  toml::table wrapper;
  wrapper.insert("value", value);
  makeInline(*wrapper.get("value"));
  std::ostringstream out;
  out << toml::toml_formatter{wrapper};
  const std::string text = out.str();
  const std::string prefix = "value = ";
  return text.rfind(prefix, 0) == 0 ? text.substr(prefix.size()) : text;
}

bool isScalar(const toml::node& v) { return !v.is_table() && !v.is_array(); }

// For names and cells: shortest round-trip numbers, bare strings.
std::string plainText(const toml::node& v) {
  if (auto d = v.value_exact<double>()) return fmt::format("{}", *d);
  if (auto i = v.value_exact<std::int64_t>()) return fmt::format("{}", *i);
  if (auto b = v.value_exact<bool>()) return *b ? "true" : "false";
  if (auto s = v.value_exact<std::string>()) return *s;
  return tomlText(v);
}

std::string sanitize(const std::string& text) {
  std::string out = text;
  for (char& c : out)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '_' && c != '-' && c != '+') c = '_';
  return out;
}

// What is wrong with a sweep's or a case's name (`what`: "a sweep name"), "" when nothing: each
// rule its own words (a 300-letter name was refused as if it held a bad character).
std::string nameProblem(const std::string& name, const std::string& what) {
  constexpr size_t kMostCharacters = 200;  // a folder's name, with room for the sweep's suffixes
  if (name.empty()) return what + " is empty";
  if (name.size() > kMostCharacters)
    return fmt::format("{} of {} characters; at most {} (it names a folder)", what, name.size(), kMostCharacters);
  if (name[0] == '.' || name[0] == '-') return what + " may not start with '.' or '-' (it names a folder)";
  const bool allValid = std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("._-+=,@#").find(c) != std::string_view::npos;
  });
  return allValid ? std::string() : what + " may hold letters, digits and . _ - + = , @ # (it names a folder)";
}

SweepOverride makeOverride(const Leaf& leaf, bool varied) {
  const auto& src = leaf.node->source().begin;
  return SweepOverride{leaf.key, tomlText(*leaf.node),       plainText(*leaf.node),
                       varied,   static_cast<int>(src.line), static_cast<int>(src.column)};
}

fs::path resolveBase(TableReader& reader, const std::string& key, const std::string& text, const fs::path& folder) {
  if (text.empty()) reader.fail(key, "expected the path of a scenario file");
  const fs::path path = fs::path(text).is_absolute() ? fs::path(text) : folder / text;
  // What is there instead, in requireRegularFile's words: a folder, a device, a loop of links.
  try {
    requireRegularFile(path, "scenario file");
  } catch (const InputError& e) {
    reader.fail(key, e.what());
  }
  return fs::absolute(path).lexically_normal();
}

// One combination of [parameters]: its overrides and its name.
struct Combination {
  std::vector<SweepOverride> overrides;
  std::string name;
};

// At most this many cases in one sweep (each holds its overrides and writes a folder). 10^6 took 13 s
// and a gigabyte only to read (a fuzzing finding, docs/reliability.md); no study needs that many.
constexpr long kMaxSweepCases = 100000;

// A count of cases as a message gives it: exact (100001, not the "1e+05" that reads as the cap
// itself) up to 1e15, then in powers of ten.
std::string caseCount(double count) { return count < 1e15 ? fmt::format("{:.0f}", count) : fmt::format("{:.3g}", count); }

std::vector<Combination> expandParameters(const std::vector<Leaf>& parameters, const TableReader& reader) {
  std::vector<Combination> out;
  if (parameters.empty()) return {Combination{}};
  std::vector<const toml::array*> lists;
  std::vector<std::string> shortKeys;
  for (const Leaf& p : parameters) {
    const toml::array* list = p.node->as_array();
    if (!list) reader.failAt(*p.node, fmt::format("parameters.{}: expected a list of values, e.g. [1.0, 2.0]", p.key));
    if (list->empty()) reader.failAt(*p.node, fmt::format("parameters.{}: the list of values is empty", p.key));
    lists.push_back(list);
    shortKeys.push_back(p.key.substr(p.key.rfind('.') == std::string::npos ? 0 : p.key.rfind('.') + 1));
  }
  // The product's size is known before it is expanded: 10^9 cases would grow until bad_alloc.
  double product = 1;
  for (const toml::array* list : lists) product *= static_cast<double>(list->size());
  if (product > static_cast<double>(kMaxSweepCases))
    reader.failAt(*parameters.front().node,
                  fmt::format("parameters: their product is {} cases; a sweep holds at most {} (split it into several sweeps)",
                              caseCount(product), kMaxSweepCases));
  std::vector<std::string> names = shortKeys;
  for (size_t i = 0; i < shortKeys.size(); ++i)
    if (std::count(shortKeys.begin(), shortKeys.end(), shortKeys[i]) > 1) names[i] = parameters[i].key;
  shortKeys = names;
  // An odometer: the last parameter turns fastest.
  std::vector<size_t> index(parameters.size(), 0);
  while (true) {
    Combination c;
    for (size_t i = 0; i < parameters.size(); ++i) {
      const toml::node& value = *lists[i]->get(index[i]);
      c.overrides.push_back(makeOverride({parameters[i].key, &value}, true));
      const std::string part = isScalar(value) ? sanitize(shortKeys[i]) + "=" + sanitize(plainText(value))
                                               : sanitize(shortKeys[i]) + "#" + std::to_string(index[i]);
      c.name += (i ? "," : "") + part;
    }
    out.push_back(std::move(c));
    size_t k = parameters.size();
    while (k > 0 && ++index[k - 1] == lists[k - 1]->size()) index[--k] = 0;
    if (k == 0) break;
  }
  return out;
}

}  // namespace

// The longest case folder name: room under the file systems' 255 for a "_2" of a clash.
constexpr size_t kMostFolderName = 120;

std::string caseFolderName(const std::string& name) {
  std::string out;
  for (char c : name) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-')
      out += c;
    else if (c == '=' || c == '#')
      out += '-';
    else if (c != '+')
      out += '_';
  }
  if (out.empty() || out[0] == '.' || out[0] == '-') out = "_" + out;
  return out;
}

std::string sweepCell(const SweepCase& c, const std::string& key) {
  for (const SweepOverride& o : c.overrides)
    if (o.varied && o.key == key) return o.text;
  return "";
}

bool isSweepFile(const fs::path& file) {
  try {
    const toml::table root = toml::parse(readTomlFile(file.string(), "scenario"), file.string());
    return root["sweep"].is_table();
  } catch (const InputError&) {
    return false;
  } catch (const toml::parse_error&) {
    return false;
  }
}

SweepDefinition readSweepFile(const fs::path& file) {
  SweepDefinition def;
  def.fileName = file.string();
  const std::string text = readTomlFile(def.fileName, "sweep");  // bounded before the parser sees it
  def.file = fs::absolute(file).lexically_normal();
  const fs::path folder = def.file.parent_path();
  toml::table root;
  try {
    root = toml::parse(text, def.file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(def.fileName, static_cast<int>(e.source().begin.line), static_cast<int>(e.source().begin.column),
                     std::string(e.description()));
  }

  TableReader top(&root, "", def.fileName);
  TableReader sweep(top.findTable("sweep"), "sweep", def.fileName);
  def.name = sweep.getString("name", def.file.stem().string());
  if (const std::string problem = nameProblem(def.name, "a sweep name"); !problem.empty()) sweep.fail("name", problem);
  fs::path base;
  sweep.accept("base");
  if (sweep.has("base")) base = resolveBase(sweep, "base", sweep.getString("base", ""), folder);
  std::vector<SweepOverride> common;
  if (const toml::table* set = sweep.findTable("set")) {
    TableReader reader(set, "sweep.set", def.fileName);
    for (const Leaf& leaf : leaves(*set, reader)) common.push_back(makeOverride(leaf, false));
  }
  sweep.finish();

  std::vector<Leaf> parameters;
  const toml::table* parameterTable = top.findTable("parameters");
  TableReader parameterReader(parameterTable, "parameters", def.fileName);
  if (parameterTable) parameters = leaves(*parameterTable, parameterReader);
  if (parameterTable && parameters.empty())
    throw InputError(def.fileName, static_cast<int>(parameterTable->source().begin.line),
                     static_cast<int>(parameterTable->source().begin.column), "parameters: no parameter to vary");
  const std::vector<Combination> combinations = expandParameters(parameters, parameterReader);
  for (const Leaf& p : parameters) def.columns.push_back(p.key);

  // The [[cases]] entries, or one anonymous entry standing for the plain product.
  struct Entry {
    std::string name;
    fs::path base;
    std::vector<SweepOverride> set;
    int line = 0, column = 0;
  };
  std::vector<Entry> entries;
  const toml::array* cases = top.findArray("cases");
  top.finish();
  if (cases) {
    if (cases->empty()) top.fail("cases", "the list of cases is empty");
    if (static_cast<long>(cases->size()) > kMaxSweepCases)
      top.fail("cases", fmt::format("{} cases; a sweep holds at most {} (split it into several sweeps)", cases->size(), kMaxSweepCases));
    for (size_t k = 0; k < cases->size(); ++k) {
      const toml::table* t = cases->get(k)->as_table();
      if (!t) top.failAt(*cases->get(k), "cases: expected [[cases]] tables with name = \"...\" and set = { ... }");
      TableReader reader(t, fmt::format("cases[{}]", k), def.fileName);
      Entry e;
      e.line = static_cast<int>(t->source().begin.line), e.column = static_cast<int>(t->source().begin.column);
      if (!reader.has("name")) reader.fail("name", "each case needs a name = \"...\"");
      e.name = reader.getString("name", "");
      if (const std::string problem = nameProblem(e.name, "a case name"); !problem.empty()) reader.fail("name", problem);
      reader.accept("base");
      e.base = reader.has("base") ? resolveBase(reader, "base", reader.getString("base", ""), folder) : base;
      if (e.base.empty()) reader.fail("name", "no base scenario: give base = \"...\" here or in [sweep]");
      if (const toml::table* set = reader.findTable("set")) {
        TableReader setReader(set, reader.keyPath("set"), def.fileName);
        for (const Leaf& leaf : leaves(*set, setReader)) {
          for (const Leaf& p : parameters)
            if (p.key == leaf.key)
              setReader.failAt(*leaf.node, fmt::format("{}: \"{}\" is also varied by [parameters]", setReader.path(), leaf.key));
          e.set.push_back(makeOverride(leaf, true));
          if (std::find(def.columns.begin(), def.columns.end(), leaf.key) == def.columns.end()) def.columns.push_back(leaf.key);
        }
      }
      reader.finish();
      entries.push_back(std::move(e));
    }
  } else {
    if (!parameterTable) throw InputError(def.fileName, 0, 0, "a sweep needs [parameters] (lists to combine) or [[cases]], or both");
    if (base.empty()) sweep.fail("base", "missing: the base scenario, relative to the sweep file");
    Entry e;
    e.base = base;
    e.line = static_cast<int>(parameterTable->source().begin.line);
    e.column = static_cast<int>(parameterTable->source().begin.column);
    entries.push_back(std::move(e));
  }

  // Every [[cases]] entry runs every combination of [parameters]: their product is the sweep's
  // size, known before a case is made (1,000 entries times 1,000 seeds once grew past 7 GB).
  const double total = static_cast<double>(entries.size()) * static_cast<double>(combinations.size());
  if (total > static_cast<double>(kMaxSweepCases))
    throw InputError(def.fileName, entries.front().line, entries.front().column,
                     fmt::format("[[cases]] times [parameters]: {} x {} = {} cases; a sweep holds at most {} (split it into several "
                                 "sweeps)",
                                 entries.size(), combinations.size(), caseCount(total), kMaxSweepCases));
  std::map<std::string, size_t> seen;
  for (const Entry& e : entries) {
    for (const Combination& c : combinations) {
      SweepCase sc;
      sc.name = e.name.empty() ? c.name : c.name.empty() ? e.name : e.name + "," + c.name;
      sc.base = e.base;
      sc.line = e.line, sc.column = e.column;
      sc.overrides = common;
      sc.overrides.insert(sc.overrides.end(), e.set.begin(), e.set.end());
      sc.overrides.insert(sc.overrides.end(), c.overrides.begin(), c.overrides.end());
      if (auto [it, inserted] = seen.emplace(sc.name, def.cases.size()); !inserted)
        throw InputError(
            def.fileName, sc.line, sc.column,
            fmt::format("two cases are named \"{}\" (cases {} and {}): case names must differ", sc.name, it->second, def.cases.size()));
      def.cases.push_back(std::move(sc));
    }
  }
  // Folders: unique among the sweep's cases, first come first served (the order of the cases is the
  // sweep file's, so a sweep always gives a case the same folder).
  // A name made of long parameter values is cut to kMostFolderName characters (a file system's
  // limit is 255); the case keeps its whole name in summary.csv.
  std::set<std::string> folders;
  for (SweepCase& c : def.cases) {
    std::string stem = caseFolderName(c.name);
    if (stem.size() > kMostFolderName) stem.resize(kMostFolderName);
    c.folder = stem;
    for (int k = 2; !folders.insert(c.folder).second; ++k) c.folder = fmt::format("{}_{}", stem, k);
  }
  return def;
}

}  // namespace gem
