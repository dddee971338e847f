// Strict reading of one TOML table (a scenario section or an event's parameters): every key read
// is checked for type and range, and finish() rejects any key nobody asked for, listing the valid
// ones, so a typo can never be silently ignored (docs/scenario.md). Errors name file:line:column.
#pragma once
#include <cmath>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <type_traits>
#include <unordered_set>
#include <vector>

#include <toml++/toml.h>

#include "framework/api/errors.hpp"
#include "geometry/vec2.hpp"

namespace gem {

// While one is alive on this thread, an error about a value that came from `--set KEY=VALUE` (a
// node with no place in any file: toml++ does not copy a node's source) names "--set KEY=VALUE",
// not the scenario file. loadScenario and the CPU stepper's event parsing hold one.
class OverrideScope {
 public:
  explicit OverrideScope(const std::vector<std::string>& assignments);
  ~OverrideScope();
  OverrideScope(const OverrideScope&) = delete;
  OverrideScope& operator=(const OverrideScope&) = delete;

 private:
  const std::vector<std::string>* m_previous;
};

// The `--set KEY=VALUE` among `assignments` that an error message is about: the last one whose
// key the message names, starts with (a key path, "a.b: ..."), quotes (unknown key "a.b"), or lies
// below (unknown key "a" of --set a.b.c=1); "" when none. Errors found after the tables are read
// (a field generator's "field.size_max: expected >= field.size_min = 50 m") use it too.
std::string overrideNamedIn(const std::string& message, const std::vector<std::string>& assignments);

// While one is alive on this thread, a TableReader records a bad value or an unknown key and goes
// on with the key's default, so that one pass over a file reports all of its errors at once, each
// with its line and column (loadScenario holds one). Without one, the first error throws.
class ErrorCollector {
 public:
  ErrorCollector();
  ~ErrorCollector();
  ErrorCollector(const ErrorCollector&) = delete;
  ErrorCollector& operator=(const ErrorCollector&) = delete;

  // key: the dotted key the message is about, when known: a later error about the same key (what
  // its default led to) is not a new error (followsFrom).
  void add(const std::string& message, const std::string& key = "");
  bool followsFrom(const std::string& message) const;
  bool empty() const { return m_messages.empty(); }
  // Throws one InputError listing the errors recorded, one per line (the first kMostShown, then how
  // many more), if there are any.
  void throwIfAny() const;
  static ErrorCollector* active();

  static constexpr size_t kMostShown = 20;
  // Keys kept for followsFrom: enough for any real scenario, and a file of 10^5 bad keys does not
  // make each later check walk them all.
  static constexpr size_t kMostKeys = 1000;

 private:
  std::vector<std::string> m_messages;
  std::unordered_set<std::string> m_seen;  // m_messages as a set: a file of 10^5 bad keys stays linear
  std::set<std::string> m_keys;
  ErrorCollector* m_previous;
};

// While one is alive on this thread, every key a TableReader reads that the table does not give is
// written, with the default it took, into `into` at its dotted path ("floes[2].thickness": element
// 2 of the array floes), so that a run's scenario.toml can show every value in force (loadScenario
// holds one over the scenario's tables, CpuStepper one over the events' tables).
class DefaultsRecorder {
 public:
  explicit DefaultsRecorder(toml::table& into);
  ~DefaultsRecorder();
  DefaultsRecorder(const DefaultsRecorder&) = delete;
  DefaultsRecorder& operator=(const DefaultsRecorder&) = delete;

  // Inserts value at the dotted path unless something is there already.
  template <class T>
  void record(const std::string& path, T value) {
    if (toml::table* parent = parentOf(path)) parent->emplace(path.substr(path.rfind('.') + 1), std::move(value));
  }
  static DefaultsRecorder* active();

 private:
  toml::table* parentOf(const std::string& path);  // null for a top-level key
  toml::table* m_into;
  DefaultsRecorder* m_previous;
};

// "; did you mean \"NAME\"?" for the candidate nearest to word when it is near enough to be a
// typo (edit distance at most a third of the word's length, and at least 2), else "".
std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates);

class TableReader {
 public:
  // table may be null (section absent): every get returns its default. path is the dotted name
  // of the table ("events.drag") used in messages; file is the scenario file.
  TableReader(const toml::table* table, std::string path, std::string file);

  bool has(const std::string& key) const;
  Real getReal(const std::string& key, Real fallback);
  Real getPositive(const std::string& key, Real fallback);     // > 0, finite
  Real getNonNegative(const std::string& key, Real fallback);  // >= 0, finite
  std::optional<Real> findReal(const std::string& key);
  std::int64_t getInt(const std::string& key, std::int64_t fallback, std::int64_t min, std::int64_t max);
  bool getBool(const std::string& key, bool fallback);
  std::string getString(const std::string& key, const std::string& fallback);
  // A file or folder: as getString, and a value given empty ("") is refused (it would name the
  // scenario's folder, or silently mean the default).
  std::string getPath(const std::string& key, const std::string& fallback);
  // A number from min to max (both finite): "must be from MIN to MAX".
  Real getRealIn(const std::string& key, Real fallback, Real min, Real max);
  // > 0 and at most `most`.
  Real getPositive(const std::string& key, Real fallback, Real most);
  // A string that must be one of `choices`.
  std::string getChoice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices);
  std::optional<Vec2> findVec2(const std::string& key);
  Vec2 getVec2(const std::string& key, Vec2 fallback);
  // [[x, y], ...]
  std::optional<std::vector<Vec2>> findPoints(const std::string& key);
  std::optional<std::vector<Real>> findReals(const std::string& key);
  const toml::table* findTable(const std::string& key);
  const toml::array* findArray(const std::string& key);
  // The key's value whatever its type (a key that takes more than one), marked as read; null when absent.
  const toml::node* findNode(const std::string& key) { return node(key); }
  // Marks a key as known without reading it (read elsewhere).
  void accept(const std::string& key);
  // Throws InputError for the first key that was never read.
  void finish() const;

  [[noreturn]] void fail(const std::string& key, const std::string& message) const;
  [[noreturn]] void failAt(const toml::node& node, const std::string& message) const;
  // As fail/failAt, but with an ErrorCollector alive the error is recorded and the caller goes on
  // (with the key's default).
  void report(const std::string& key, const std::string& message) const;
  void reportAt(const toml::node& node, const std::string& message) const;
  const std::string& file() const { return m_file; }
  const std::string& path() const { return m_path; }
  std::string keyPath(const std::string& key) const { return m_path.empty() ? key : m_path + "." + key; }
  // The default a key took when the table does not give it, for the active DefaultsRecorder: the
  // get* methods call it; a caller reading a key through find* (an array, say) calls it itself.
  // A default worked out from other values (an autopilot gain from the vessel's mass) that is not
  // a finite number is refused here, naming the key: it would run as inf and make the run's
  // scenario.toml one that does not load.
  template <class T>
  void recordDefault(const std::string& key, T value) const {
    if constexpr (std::is_floating_point_v<T>)
      if (!std::isfinite(value))
        return report(key,
                      "its default, worked out from other values of the scenario, is not a finite number: give it, or smaller "
                      "values for what it follows from");
    if (DefaultsRecorder* r = DefaultsRecorder::active()) r->record(keyPath(key), std::move(value));
  }

 private:
  const toml::node* node(const std::string& key);
  std::optional<Real> toReal(const toml::node& n, const std::string& key) const;  // nullopt: reported
  InputError errorAt(const toml::node& node, const std::string& message) const;
  InputError errorFor(const std::string& key, const std::string& message) const;

  const toml::table* m_table;
  std::string m_path, m_file;
  std::set<std::string> m_known;
};

}  // namespace gem
