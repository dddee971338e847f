#include "framework/api/table_reader.hpp"

#include <algorithm>
#include <vector>

#include <cmath>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

TableReader::TableReader(const toml::table* table, std::string path, std::string file)
    : m_table(table), m_path(std::move(path)), m_file(std::move(file)) {}

bool TableReader::has(const std::string& key) const { return m_table && m_table->contains(key); }

const toml::node* TableReader::node(const std::string& key) {
  m_known.insert(key);
  return m_table ? m_table->get(key) : nullptr;
}

void TableReader::accept(const std::string& key) { m_known.insert(key); }

InputError TableReader::errorFor(const std::string& key, const std::string& message) const {
  const toml::node* n = m_table ? m_table->get(key) : nullptr;
  if (n) return errorAt(*n, fmt::format("{}: {}", keyPath(key), message));
  if (m_table) {
    const auto& src = m_table->source();
    return InputError(m_file, static_cast<int>(src.begin.line), static_cast<int>(src.begin.column),
                      fmt::format("{}: {}", keyPath(key), message));
  }
  return InputError(m_file, 0, 0, fmt::format("{}: {}", keyPath(key), message));
}

void TableReader::fail(const std::string& key, const std::string& message) const { throw errorFor(key, message); }
void TableReader::failAt(const toml::node& n, const std::string& message) const { throw errorAt(n, message); }

void TableReader::report(const std::string& key, const std::string& message) const {
  if (ErrorCollector* errors = ErrorCollector::active()) return errors->add(errorFor(key, message).what(), keyPath(key));
  fail(key, message);
}

void TableReader::reportAt(const toml::node& n, const std::string& message) const {
  // The messages start with the key path they are about ("vessel.mass: ...", "unknown key ...").
  if (ErrorCollector* errors = ErrorCollector::active())
    return errors->add(errorAt(n, message).what(), message.substr(0, message.find(':')));
  failAt(n, message);
}

namespace {
thread_local ErrorCollector* t_collector = nullptr;
}  // namespace

namespace {
thread_local DefaultsRecorder* t_defaults = nullptr;
}  // namespace

DefaultsRecorder::DefaultsRecorder(toml::table& into) : m_into(&into), m_previous(t_defaults) { t_defaults = this; }
DefaultsRecorder::~DefaultsRecorder() { t_defaults = m_previous; }
DefaultsRecorder* DefaultsRecorder::active() { return t_defaults; }

toml::table* DefaultsRecorder::parentOf(const std::string& path) {
  if (path.find('.') == std::string::npos) return nullptr;
  toml::table* table = m_into;
  size_t start = 0;
  for (size_t dot = path.find('.'); dot != std::string::npos; start = dot + 1, dot = path.find('.', start)) {
    const std::string part = path.substr(start, dot - start);
    const size_t bracket = part.find('[');
    if (bracket == std::string::npos) {
      if (!table->contains(part)) table->insert(part, toml::table{});
      table = table->get(part)->as_table();
    } else {
      // "floes[3]": element 3 of an array of tables; the elements before it are kept as empty
      // tables, so that each recorded element sits at its own index (recordScenario merges by index).
      const std::string name = part.substr(0, bracket);
      const size_t index = std::stoul(part.substr(bracket + 1));
      if (!table->contains(name)) table->insert(name, toml::array{});
      toml::array* elements = table->get(name)->as_array();
      if (!elements) return nullptr;
      while (elements->size() <= index) elements->push_back(toml::table{});
      table = elements->get(index)->as_table();
    }
    if (!table) return nullptr;
  }
  return table;
}

ErrorCollector::ErrorCollector() : m_previous(t_collector) { t_collector = this; }
ErrorCollector::~ErrorCollector() { t_collector = m_previous; }
ErrorCollector* ErrorCollector::active() { return t_collector; }

void ErrorCollector::add(const std::string& message, const std::string& key) {
  // The same error twice (a value read by two readers) is one error.
  if (m_seen.insert(message).second) m_messages.push_back(message);
  if (!key.empty() && key.find(' ') == std::string::npos && m_keys.size() < kMostKeys) m_keys.insert(key);
}

bool ErrorCollector::followsFrom(const std::string& message) const {
  for (const std::string& key : m_keys)
    if (message.find(" " + key + ":") != std::string::npos || message.find(" " + key + "[") != std::string::npos) return true;
  return false;
}

void ErrorCollector::throwIfAny() const {
  if (m_messages.empty()) return;
  std::string text = m_messages.front();
  if (m_messages.size() > 1) text += fmt::format("\n  ({} errors in all; the others:)", m_messages.size());
  for (size_t k = 1; k < m_messages.size() && k < kMostShown; ++k) text += "\n  " + m_messages[k];
  if (m_messages.size() > kMostShown) text += fmt::format("\n  ... and {} more", m_messages.size() - kMostShown);
  throw InputError::multiline(text);
}

namespace {
thread_local const std::vector<std::string>* t_overrides = nullptr;
}  // namespace

OverrideScope::OverrideScope(const std::vector<std::string>& assignments) : m_previous(t_overrides) { t_overrides = &assignments; }
OverrideScope::~OverrideScope() { t_overrides = m_previous; }

std::string overrideNamedIn(const std::string& message, const std::vector<std::string>& assignments) {
  // The message's own key path, when it starts with one ("broadphase.x: unknown broadphase"): a
  // --set of a key below it (broadphase.x.skin=1) made the table it is about.
  const std::string about = message.substr(0, std::min(message.find(':'), message.find(' ')));
  // The key an "unknown key" message quotes: a --set below it (a.b.c=1, unknown key "a") made it.
  std::string unknown;
  if (const size_t at = message.find("unknown key \""); at != std::string::npos) {
    const size_t from = at + 13, to = message.find('"', from);
    if (to != std::string::npos) unknown = message.substr(from, to - from);
  }
  for (auto a = assignments.rbegin(); a != assignments.rend(); ++a) {
    const std::string key = a->substr(0, a->find('='));
    const bool named = message.rfind(key + ":", 0) == 0 || message.rfind(key + "[", 0) == 0 || message.rfind(key + ".", 0) == 0 ||
                       message.find("\"" + key + "\"") != std::string::npos || message.find("\"" + key + ".") != std::string::npos ||
                       (!about.empty() && key.rfind(about + ".", 0) == 0) || (!unknown.empty() && key.rfind(unknown + ".", 0) == 0);
    if (named) return *a;
  }
  return "";
}

InputError TableReader::errorAt(const toml::node& n, const std::string& message) const {
  const auto& src = n.source();
  // A value from --set (no source): the last assignment of the key the message is about is the
  // one in force.
  if (!src.path && t_overrides)
    if (const std::string set = overrideNamedIn(message, *t_overrides); !set.empty())
      return InputError(fmt::format("--set {}: {}", set, message));
  return InputError(m_file, static_cast<int>(src.begin.line), static_cast<int>(src.begin.column), message);
}

namespace {
// Edit distance (insertions, deletions, substitutions), for "did you mean".
size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t next = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = row[j];
      row[j] = next;
    }
  }
  return row[b.size()];
}
}  // namespace

std::string didYouMean(const std::string& word, const std::vector<std::string>& candidates) {
  std::string nearest;
  size_t best = std::max<size_t>(2, word.size() / 3) + 1;
  for (const std::string& candidate : candidates)
    if (const size_t d = editDistance(word, candidate); d < best) best = d, nearest = candidate;
  return nearest.empty() ? std::string() : fmt::format("; did you mean \"{}\"?", nearest);
}

std::optional<Real> TableReader::toReal(const toml::node& n, const std::string& key) const {
  double v;
  if (auto f = n.value_exact<double>()) {
    v = *f;
  } else if (auto i = n.value_exact<std::int64_t>()) {
    v = static_cast<double>(*i);
  } else {
    reportAt(n,
             fmt::format("{}: expected a number, got {}", keyPath(key), toml::impl::node_type_friendly_names[static_cast<int>(n.type())]));
    return std::nullopt;
  }
  if (!std::isfinite(v)) {
    reportAt(n, fmt::format("{}: expected a finite number, got {}", keyPath(key), v));
    return std::nullopt;
  }
  return static_cast<Real>(v);
}

std::optional<Real> TableReader::findReal(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  return toReal(*n, key);
}

Real TableReader::getReal(const std::string& key, Real fallback) {
  if (!has(key)) recordDefault(key, static_cast<double>(fallback));
  return findReal(key).value_or(fallback);
}

Real TableReader::getPositive(const std::string& key, Real fallback) {
  Real v = getReal(key, fallback);
  if (!(v > 0)) report(key, fmt::format("must be positive, got {}", v)), v = fallback;
  return v;
}

Real TableReader::getNonNegative(const std::string& key, Real fallback) {
  Real v = getReal(key, fallback);
  if (!(v >= 0)) report(key, fmt::format("must not be negative, got {}", v)), v = fallback;
  return v;
}

std::int64_t TableReader::getInt(const std::string& key, std::int64_t fallback, std::int64_t min, std::int64_t max) {
  const toml::node* n = node(key);
  if (!n) return recordDefault(key, fallback), fallback;
  auto i = n->value_exact<std::int64_t>();
  if (!i) return reportAt(*n, fmt::format("{}: expected an integer", keyPath(key))), fallback;
  if (*i < min || *i > max) return reportAt(*n, fmt::format("{}: must be in [{}, {}], got {}", keyPath(key), min, max, *i)), fallback;
  return *i;
}

bool TableReader::getBool(const std::string& key, bool fallback) {
  const toml::node* n = node(key);
  if (!n) return recordDefault(key, fallback), fallback;
  auto b = n->value_exact<bool>();
  if (!b) return reportAt(*n, fmt::format("{}: expected true or false", keyPath(key))), fallback;
  return *b;
}

std::string TableReader::getString(const std::string& key, const std::string& fallback) {
  const toml::node* n = node(key);
  if (!n) return recordDefault(key, fallback), fallback;
  auto s = n->value_exact<std::string>();
  if (!s) return reportAt(*n, fmt::format("{}: expected a string", keyPath(key))), fallback;
  // A NUL ("\u0000") ends a path or a name early in every system call: "a\u0000b" would write to "a".
  if (s->find('\0') != std::string::npos)
    return reportAt(*n, fmt::format("{}: a string may not hold a NUL character", keyPath(key))), fallback;
  return *s;
}

std::string TableReader::getPath(const std::string& key, const std::string& fallback) {
  const std::string v = getString(key, fallback);
  const toml::node* n = m_table ? m_table->get(key) : nullptr;
  if (n && n->value_exact<std::string>() && n->value_exact<std::string>()->empty())
    return reportAt(*n, fmt::format("{}: an empty path: name a file or folder, or leave the key out", keyPath(key))), fallback;
  return v;
}

Real TableReader::getRealIn(const std::string& key, Real fallback, Real min, Real max) {
  Real v = getReal(key, fallback);
  if (!(v >= min && v <= max)) report(key, fmt::format("must be from {:g} to {:g}, got {}", min, max, v)), v = fallback;
  return v;
}

Real TableReader::getPositive(const std::string& key, Real fallback, Real most) {
  Real v = getReal(key, fallback);
  if (!(v > 0 && v <= most)) report(key, fmt::format("must be positive and at most {:g}, got {}", most, v)), v = fallback;
  return v;
}

std::string TableReader::getChoice(const std::string& key, const std::string& fallback, const std::vector<std::string>& choices) {
  std::string v = getString(key, fallback);
  for (const auto& c : choices)
    if (c == v) return v;
  report(key, fmt::format("unknown value \"{}\"{} (valid: {})", v, didYouMean(v, choices), fmt::join(choices, ", ")));
  return fallback;
}

std::optional<std::vector<Real>> TableReader::findReals(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  if (!a) return reportAt(*n, fmt::format("{}: expected an array of numbers", keyPath(key))), std::nullopt;
  std::vector<Real> out;
  for (const toml::node& e : *a) {
    const std::optional<Real> v = toReal(e, key);
    if (!v) return std::nullopt;
    out.push_back(*v);
  }
  return out;
}

std::optional<Vec2> TableReader::findVec2(const std::string& key) {
  auto v = findReals(key);
  if (!v) return std::nullopt;
  if (v->size() != 2) return report(key, fmt::format("expected [x, y], got {} numbers", v->size())), std::nullopt;
  return Vec2{(*v)[0], (*v)[1]};
}

Vec2 TableReader::getVec2(const std::string& key, Vec2 fallback) {
  if (!has(key)) recordDefault(key, toml::array{static_cast<double>(fallback.x), static_cast<double>(fallback.y)});
  return findVec2(key).value_or(fallback);
}

std::optional<std::vector<Vec2>> TableReader::findPoints(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return std::nullopt;
  const toml::array* a = n->as_array();
  if (!a) return reportAt(*n, fmt::format("{}: expected an array of [x, y] points", keyPath(key))), std::nullopt;
  std::vector<Vec2> out;
  for (const toml::node& e : *a) {
    const toml::array* p = e.as_array();
    if (!p || p->size() != 2) return reportAt(e, fmt::format("{}: expected [x, y]", keyPath(key))), std::nullopt;
    const std::optional<Real> x = toReal(*p->get(0), key), y = toReal(*p->get(1), key);
    if (!x || !y) return std::nullopt;
    out.push_back({*x, *y});
  }
  return out;
}

const toml::table* TableReader::findTable(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return nullptr;
  if (!n->as_table()) return reportAt(*n, fmt::format("{}: expected a table", keyPath(key))), nullptr;
  return n->as_table();
}

const toml::array* TableReader::findArray(const std::string& key) {
  const toml::node* n = node(key);
  if (!n) return nullptr;
  if (!n->as_array()) return reportAt(*n, fmt::format("{}: expected an array", keyPath(key))), nullptr;
  return n->as_array();
}

void TableReader::finish() const {
  if (!m_table) return;
  for (const auto& [k, v] : *m_table) {
    std::string key(k.str());
    if (m_known.count(key)) continue;
    std::vector<std::string> valid(m_known.begin(), m_known.end());
    reportAt(v, fmt::format("unknown key \"{}\"{} (valid keys here: {})", keyPath(key), didYouMean(key, valid),
                            valid.empty() ? std::string("none") : fmt::format("{}", fmt::join(valid, ", "))));
  }
}

}  // namespace gem
