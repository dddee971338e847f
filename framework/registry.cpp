#include "framework/registry.hpp"

#include <fmt/format.h>

#include "framework/errors.hpp"

namespace gem {

const char* eventPhaseName(EventPhase phase) {
  switch (phase) {
    case EventPhase::Pair: return "two-body";
    case EventPhase::Solo: return "solo";
    case EventPhase::Motion: return "motion";
    case EventPhase::Topology: return "topology";
  }
  return "unknown";
}

Registry& Registry::global() {
  static Registry registry;
  return registry;
}

void Registry::addEvent(EventEntry entry) {
  auto [it, inserted] = m_events.emplace(entry.name, entry);
  if (!inserted)
    throw InputError(fmt::format("event \"{}\" from {} clashes with the one from {}", entry.name, entry.origin, it->second.origin));
}

void Registry::addBroadphase(BroadphaseEntry entry) {
  auto [it, inserted] = m_broadphases.emplace(entry.name, entry);
  if (!inserted)
    throw InputError(fmt::format("broadphase \"{}\" from {} clashes with the one from {}", entry.name, entry.origin, it->second.origin));
}

const EventEntry* Registry::findEvent(const std::string& name) const {
  auto it = m_events.find(name);
  return it == m_events.end() ? nullptr : &it->second;
}

const EventEntry& Registry::event(const std::string& name) const {
  if (auto* e = findEvent(name)) return *e;
  throw InputError(fmt::format("unknown event \"{}\" (valid: {})", name, fmt::join(eventNames(), ", ")));
}

const BroadphaseEntry& Registry::broadphase(const std::string& name) const {
  auto it = m_broadphases.find(name);
  if (it != m_broadphases.end()) return it->second;
  throw InputError(fmt::format("unknown broadphase \"{}\" (valid: {})", name, fmt::join(broadphaseNames(), ", ")));
}

std::vector<const EventEntry*> Registry::events() const {
  std::vector<const EventEntry*> out;
  for (EventPhase phase : {EventPhase::Pair, EventPhase::Solo, EventPhase::Motion, EventPhase::Topology})
    for (const auto& [name, e] : m_events)
      if (e.phase == phase) out.push_back(&e);
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

}  // namespace gem
