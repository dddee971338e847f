#include "framework/api/registry.hpp"

#include "framework/api/table_reader.hpp"

#include <algorithm>
#include <map>
#include <set>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

const char* eventPhaseName(EventPhase phase) {
  switch (phase) {
    case EventPhase::Pair:
      return "two-body";
    case EventPhase::Solo:
      return "solo";
    case EventPhase::Motion:
      return "motion";
    case EventPhase::Topology:
      return "topology";
  }
  return "unknown";
}

Registry& Registry::global() {
  static Registry registry;
  return registry;
}

void Registry::addEvent(EventEntry entry) {
  if (m_staging) {
    entry.origin = m_staging->origin;
    m_staging->events.push_back(std::move(entry));
    return;
  }
  auto [it, inserted] = m_events.emplace(entry.name, entry);
  if (!inserted)
    throw InputError(fmt::format("event \"{}\" from {} clashes with the one from {}", entry.name, entry.origin, it->second.origin));
}

void Registry::addBroadphase(BroadphaseEntry entry) {
  if (m_staging) {
    entry.origin = m_staging->origin;
    m_staging->broadphases.push_back(std::move(entry));
    return;
  }
  auto [it, inserted] = m_broadphases.emplace(entry.name, entry);
  if (!inserted)
    throw InputError(fmt::format("broadphase \"{}\" from {} clashes with the one from {}", entry.name, entry.origin, it->second.origin));
}

void Registry::beginPlugin(const std::string& origin, bool allowOverride) {
  m_staging = std::make_unique<Staging>();
  m_staging->origin = origin;
  m_staging->allowOverride = allowOverride;
}

void Registry::abortPlugin() { m_staging.reset(); }

std::string Registry::pluginOrigin() const { return m_staging ? m_staging->origin : std::string("built-in"); }

namespace {

// A clash of a plugin's entry with one already there (or with another of its own entries).
template <class Entry>
void checkClashes(const char* kind, const std::vector<Entry>& staged, const std::map<std::string, Entry>& table, bool allowOverride) {
  std::map<std::string, const Entry*> seen;
  for (const Entry& e : staged) {
    if (!seen.emplace(e.name, &e).second) throw InputError(fmt::format("plugin {}: registers {} \"{}\" twice", e.origin, kind, e.name));
    auto it = table.find(e.name);
    if (it != table.end() && !allowOverride)
      throw InputError(
          fmt::format("plugin {}: {} \"{}\" clashes with the one from {} (to replace it, give the plugin's "
                      "[[plugins]] entry override = true)",
                      e.origin, kind, e.name, it->second.origin));
  }
}

}  // namespace

void Registry::commitPlugin() {
  std::unique_ptr<Staging> staging = std::move(m_staging);
  if (!staging) return;
  checkClashes("event", staging->events, m_events, staging->allowOverride);
  checkClashes("broadphase", staging->broadphases, m_broadphases, staging->allowOverride);
  checkRecordOutputs(*staging);
  for (EventEntry& e : staging->events) m_events.insert_or_assign(e.name, std::move(e));
  for (BroadphaseEntry& b : staging->broadphases) m_broadphases.insert_or_assign(b.name, std::move(b));
  for (RecordOutputEntry& r : staging->recordOutputs) enterRecordOutput(std::move(r), staging->origin);
}

// A plugin's record outputs may not take what GEM writes itself, nor (but to replace it, with
// override) what another entry writes: a plugin's impacts.csv once replaced ship_impact's rows, and
// its count key "steps" the run's step count in summary.json, without a word.
void Registry::checkRecordOutputs(const Staging& staging) const {
  auto keysOf = [](const RecordOutputEntry& e) {
    std::vector<std::string> keys;
    for (const std::string* k : {&e.countKey, &e.statisticKey, &e.countInIceKey, &e.statisticInIceKey})
      if (!k->empty()) keys.push_back(*k);
    return keys;
  };
  const std::string& origin = staging.origin;
  std::map<std::string, std::string> keyOwner;  // summary keys of the entries that stay, by owner
  for (size_t k = 0; k < m_recordOutputs.size(); ++k) {
    const RecordOutputEntry& e = m_recordOutputs[k];
    const bool replaced = std::any_of(staging.recordOutputs.begin(), staging.recordOutputs.end(),
                                      [&](const RecordOutputEntry& r) { return r.file == e.file && staging.allowOverride; });
    if (replaced) continue;
    for (const std::string& key : keysOf(e))
      keyOwner.emplace(key, fmt::format("the record output {} of {}", e.file, m_recordOutputOrigins[k]));
  }
  std::set<std::string> files;
  for (const RecordOutputEntry& r : staging.recordOutputs) {
    const std::string what = fmt::format("plugin {}: the record output of stream \"{}\" to \"{}\"", origin, r.stream, r.file);
    if (r.file.empty() || r.file == "." || r.file == ".." || r.file.find_first_of("/\\") != std::string::npos)
      throw InputError(what + ": the file must be a plain file name in the run folder");
    for (const char* own : kGemRunFiles)
      if (r.file == own) throw InputError(fmt::format("{}: {} is a file GEM writes itself; choose another name", what, r.file));
    if (!files.insert(r.file).second) throw InputError(fmt::format("{}: the plugin registers a record output to {} twice", what, r.file));
    for (size_t k = 0; k < m_recordOutputs.size(); ++k)
      if (m_recordOutputs[k].file == r.file && !staging.allowOverride)
        throw InputError(
            fmt::format("{}: {} is written by the record output of stream \"{}\" from {} (to replace it, give the "
                        "plugin's [[plugins]] entry override = true)",
                        what, r.file, m_recordOutputs[k].stream, m_recordOutputOrigins[k]));
    for (const std::string& key : keysOf(r)) {
      for (const char* own : kGemSummaryKeys)
        if (key == own) throw InputError(fmt::format("{}: \"{}\" is a key GEM writes in summary.json itself; choose another", what, key));
      const auto [it, fresh] = keyOwner.emplace(key, fmt::format("the record output {} of {}", r.file, origin));
      if (!fresh) throw InputError(fmt::format("{}: the summary key \"{}\" is already written by {}", what, key, it->second));
    }
  }
}

const EventEntry* Registry::findEvent(const std::string& name) const {
  auto it = m_events.find(name);
  return it == m_events.end() ? nullptr : &it->second;
}

const EventEntry& Registry::event(const std::string& name) const {
  if (auto* e = findEvent(name)) return *e;
  throw InputError(fmt::format("unknown event \"{}\"{} (valid: {})", name, didYouMean(name, eventNames()), fmt::join(eventNames(), ", ")));
}

const BroadphaseEntry& Registry::broadphase(const std::string& name) const {
  auto it = m_broadphases.find(name);
  if (it != m_broadphases.end()) return it->second;
  throw InputError(fmt::format("unknown broadphase \"{}\"{} (valid: {})", name, didYouMean(name, broadphaseNames()),
                               fmt::join(broadphaseNames(), ", ")));
}

std::vector<const EventEntry*> Registry::events() const {
  std::vector<const EventEntry*> out;
  for (EventPhase phase : {EventPhase::Pair, EventPhase::Solo, EventPhase::Motion, EventPhase::Topology}) {
    const size_t first = out.size();
    for (const auto& [name, e] : m_events)  // by name: the stable sort keeps it among equal orders
      if (e.phase == phase) out.push_back(&e);
    std::stable_sort(out.begin() + static_cast<std::ptrdiff_t>(first), out.end(),
                     [](const EventEntry* a, const EventEntry* b) { return a->order < b->order; });
  }
  return out;
}

std::vector<const BroadphaseEntry*> Registry::broadphases() const {
  std::vector<const BroadphaseEntry*> out;
  for (const auto& [name, b] : m_broadphases) out.push_back(&b);
  return out;
}

std::vector<std::string> Registry::eventNames() const {
  std::vector<std::string> out;
  for (const auto& [name, e] : m_events) out.push_back(name);
  return out;
}

std::vector<std::string> Registry::broadphaseNames() const {
  std::vector<std::string> out;
  for (const auto& [name, b] : m_broadphases) out.push_back(name);
  return out;
}

void Registry::addRecordOutput(RecordOutputEntry entry) {
  if (m_staging) {
    m_staging->recordOutputs.push_back(std::move(entry));
    return;
  }
  enterRecordOutput(std::move(entry), "built-in");
}

void Registry::enterRecordOutput(RecordOutputEntry entry, const std::string& origin) {
  for (size_t k = 0; k < m_recordOutputs.size(); ++k)
    if (m_recordOutputs[k].file == entry.file) {
      m_recordOutputs[k] = std::move(entry);  // a plugin overriding the event that owns it replaces its writer
      m_recordOutputOrigins[k] = origin;
      return;
    }
  m_recordOutputs.push_back(std::move(entry));
  m_recordOutputOrigins.push_back(origin);
}

std::vector<const RecordOutputEntry*> Registry::recordOutputs() const {
  std::vector<const RecordOutputEntry*> out;
  for (const RecordOutputEntry& e : m_recordOutputs) out.push_back(&e);
  return out;
}

static PluginLibraryLoader& pluginLibraryLoader() {
  static PluginLibraryLoader loader{nullptr, nullptr};
  return loader;
}

void setPluginLibraryLoader(PluginLibraryLoader loader) { pluginLibraryLoader() = loader; }

void requirePluginLibrary(const std::filesystem::path& path, bool allowOverride) {
  if (!pluginLibraryLoader().load) throw InputError(path.string() + ": this program cannot load plugins (no plugin loader)");
  pluginLibraryLoader().load(path, allowOverride);
}

void requireEnvironmentPluginLibraries() {
  if (pluginLibraryLoader().loadEnvironment) pluginLibraryLoader().loadEnvironment();
}

}  // namespace gem
