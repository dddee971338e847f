#include "framework/step/cpu_stepper.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <type_traits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <cmath>
#include <map>
#include <string_view>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/field/ice_file.hpp"
#include "framework/api/log_channel.hpp"
#include "framework/api/parallel.hpp"
#include "framework/api/still_bodies.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/world/constants.hpp"
#include "framework/world/vessel.hpp"
#include "framework/step/phases.hpp"
#include "geometry/contact.hpp"
#include "geometry/packed_host.hpp"

namespace gem {

void validateBodySpec(BodySpec& spec, int maxVertices) {
  const int n = static_cast<int>(spec.vertices.size());
  if (n < 3 || n > maxVertices)
    throw InputError(fmt::format("{}: a {} needs 3 to {} vertices, got {}", spec.origin, bodyKindName(spec.kind), maxVertices, n));
  for (const Vec2& v : spec.vertices) {
    if (!std::isfinite(v.x) || !std::isfinite(v.y))
      throw InputError(fmt::format("{}: vertex coordinates must be finite numbers", spec.origin));
    // Walls are made from the domain's edges, which are checked, and reach a little past them.
    if (spec.kind != BodyKind::Wall && !(std::fabs(v.x) <= kMostCoordinate && std::fabs(v.y) <= kMostCoordinate))
      throw InputError(
          fmt::format("{}: each vertex coordinate must be within +-{:g} m, got ({}, {})", spec.origin, kMostCoordinate, v.x, v.y));
  }
  if (!std::isfinite(spec.velocity.x) || !std::isfinite(spec.velocity.y) || !std::isfinite(spec.angularVelocity))
    throw InputError(fmt::format("{}: velocity must be finite", spec.origin));
  // A body starts no faster than any ship or floe could (a .ice field's objects too): beyond it
  // the first step overflowed.
  if (!(std::fabs(spec.velocity.x) <= kMostStartSpeed && std::fabs(spec.velocity.y) <= kMostStartSpeed))
    throw InputError(fmt::format("{}: each velocity component must be within +-{:g} m/s, got ({}, {})", spec.origin, kMostStartSpeed,
                                 spec.velocity.x, spec.velocity.y));
  if (!(std::fabs(spec.angularVelocity) <= kMostStartAngularSpeed))
    throw InputError(fmt::format("{}: the angular velocity must be within +-{:g} rad/s, got {}", spec.origin, kMostStartAngularSpeed,
                                 spec.angularVelocity));
  if (!(spec.thickness > 0) || !std::isfinite(spec.thickness))
    throw InputError(fmt::format("{}: thickness must be a positive number, got {}", spec.origin, spec.thickness));
  // A floe (a .ice field's too) from young ice to an iceberg: thinner, its mass was too small for
  // a finite first impulse (the vessel's draft and the walls are checked where they are made).
  if (spec.kind == BodyKind::Floe && !(spec.thickness >= kLeastIceThickness && spec.thickness <= kMostIceThickness))
    throw InputError(fmt::format("{}: a floe's thickness must be from {:g} to {:g} m, got {}", spec.origin, kLeastIceThickness,
                                 kMostIceThickness, spec.thickness));
  if (signedArea(spec.vertices.data(), n) < 0) reverseOrder(spec.vertices.data(), n);  // docs/model.md 1
  if (!isStrictlyConvexCCW(spec.vertices.data(), n, Real(1e-9)))
    throw InputError(
        fmt::format("{}: the polygon is not convex (or is self-intersecting or has repeated or collinear vertices)", spec.origin));
}

// A body's mass properties, worked out from its polygon, thickness (or the vessel's mass), must be
// finite numbers: a floe 1e308 m thick has an infinite mass that would reach every output.
static void requireFiniteMass(const World& world, int i, const std::string& origin) {
  for (Real v : {world.area[i], world.mass[i], world.invMass[i], world.invInertia[i], world.gyration2[i]})
    if (!std::isfinite(v))
      throw InputError(
          fmt::format("{}: its mass or moment of inertia is not a finite number (area {:g} m^2, thickness {:g} m, mass {:g} kg)", origin,
                      world.area[i], world.thickness[i], world.mass[i]));
}

// Static walls along the long sides of the domain (docs/scenario.md [domain] walls): the channel. They
// reach past both ends so that a vessel starting before the field is already between them.
static void addWalls(const Scenario& s, std::vector<BodySpec>& bodies) {
  const Real margin = std::max<Real>(2 * s.vessel.length, 50);
  const Real x0 = s.domain.x0 - margin, x1 = s.domain.x1 + margin;
  const Real t = s.wallThickness;
  for (int side = 0; side < 2; ++side) {
    const Real inner = side == 0 ? s.domain.y0 : s.domain.y1;
    const Real outer = side == 0 ? inner - t : inner + t;
    BodySpec wall;
    wall.kind = BodyKind::Wall;
    wall.thickness = 10;
    wall.origin = s.fileName + (side == 0 ? ": [domain] wall along y0" : ": [domain] wall along y1");
    wall.vertices = {
        {x0, std::min(inner, outer)}, {x1, std::min(inner, outer)}, {x1, std::max(inner, outer)}, {x0, std::max(inner, outer)}};
    bodies.push_back(wall);
  }
}

// The generators report bad specs by key; this adds where the value came from: the --set that the
// message names, else the key's line in the file (s.document keeps the places; s.root, a copy, has
// none, so the message once named the file alone), else the [field] table's.
static std::vector<BodySpec> generateField(const Scenario& s) {
  try {
    if (s.fieldKind == "random_convex") return generateRandomConvexField(s.randomField);
    return generateHexagonField(s.hexagonField);
  } catch (const InputError& e) {
    const std::string message = e.what();
    if (const std::string set = overrideNamedIn(message, s.overrides); !set.empty())
      throw InputError(fmt::format("--set {}: {}", set, message));
    // A bound set by another key ("field.size_max: expected >= field.size_min = 50 m").
    // The key as a whole word of the message ("... >= field.size_min = 50 m", "[field.size_min, ...]").
    const auto namesKey = [&message](const std::string& key) {
      for (size_t at = message.find(key); at != std::string::npos; at = message.find(key, at + 1)) {
        const char before = at ? message[at - 1] : ' ', after = at + key.size() < message.size() ? message[at + key.size()] : ' ';
        if (std::string_view(" [(,").find(before) != std::string_view::npos &&
            std::string_view(" ],)=:").find(after) != std::string_view::npos)
          return true;
      }
      return false;
    };
    for (auto a = s.overrides.rbegin(); a != s.overrides.rend(); ++a)
      if (namesKey(a->substr(0, a->find('=')))) throw InputError(fmt::format("--set {}: {}", *a, message));
    const toml::table& document = s.document ? *s.document : s.root;
    const toml::node* at = document.at_path(message.substr(0, message.find(':'))).node();
    if (!at || !at->source().begin) at = document.get("field");
    const auto line = at ? at->source().begin.line : 0, column = at ? at->source().begin.column : 0;
    throw InputError(s.fileName, static_cast<int>(line), static_cast<int>(column), message);
  }
}

World buildWorld(const Scenario& s) {
  std::vector<BodySpec> bodies;
  if (s.walls) addWalls(s, bodies);
  if (s.fieldKind == "random_convex" || s.fieldKind == "hexagons") {
    auto field = generateField(s);
    bodies.insert(bodies.end(), field.begin(), field.end());
  } else if (s.fieldKind == "file") {
    auto field = readIceInitialBodies(s.fieldFile);
    bodies.insert(bodies.end(), field.begin(), field.end());
  }
  bodies.insert(bodies.end(), s.floes.begin(), s.floes.end());

  // Ids are unique: bodies given with ids (a .ice field's object indices) keep them, and the ones
  // without (walls, generated floes, the vessel) are numbered after the largest given id, whatever
  // their order. Two bodies given the same id are refused, naming both.
  World world;
  std::map<std::int64_t, const std::string*> given;
  for (const BodySpec& spec : bodies) {
    if (spec.id < 0 || spec.kind == BodyKind::Vessel) continue;
    const auto [it, fresh] = given.emplace(spec.id, &spec.origin);
    if (!fresh) throw InputError(fmt::format("{}: two bodies have the id {}: {} and {}", s.fileName, spec.id, *it->second, spec.origin));
    world.nextId = std::max(world.nextId, spec.id + 1);
  }
  std::vector<std::string> origins;
  for (BodySpec& spec : bodies) {
    if (spec.kind == BodyKind::Vessel) continue;  // a vessel comes from [vessel]
    validateBodySpec(spec, spec.kind == BodyKind::Floe ? kMaxFloeVertices : kMaxVertices);
    requireFiniteMass(world, world.addBody(spec), spec.origin);
    origins.push_back(spec.origin);
  }
  if (s.vessel.present) {
    HullGeometry hull = hullGeometry(s.vessel);
    BodySpec check;
    check.kind = BodyKind::Vessel;
    check.origin = s.fileName + ": vessel.vertices (the hull)";
    check.vertices = hull.vertices;
    check.thickness = s.vessel.draft;
    validateBodySpec(check, kMaxVertices);
    requireFiniteMass(world, addVessel(world, s.vessel), s.fileName + ": [vessel]");
    origins.push_back("vessel");
  }

  // Bodies never start in contact (docs/model.md 1): any conservative broadphase + the exact contact.
  BroadphaseSettings noSkin;
  noSkin.skin = 0;
  auto broadphase = Registry::global().broadphase("variable_radius").make(noSkin);
  std::vector<CandidatePair> pairs;
  broadphase->findCandidates(world, pairs);
  Vec2 p[kMaxVertices], q[kMaxVertices];
  for (const CandidatePair& pair : pairs) {
    if (world.invMass[pair.a] == 0 && world.invMass[pair.b] == 0) continue;
    const int n = world.worldVertices(pair.a, p), m = world.worldVertices(pair.b, q);
    const Contact c = computeContact(p, n, world.position(pair.a), q, m, world.position(pair.b));
    if (c.touching)
      throw InputError(fmt::format("{}: bodies overlap at the start: {} (id {}) and {} (id {}), overlap area {:.4g} m^2", s.fileName,
                                   origins[pair.a], world.id[pair.a], origins[pair.b], world.id[pair.b], c.area));
  }
  return world;
}

CpuStepper::CpuStepper(const Scenario& scenario) : CpuStepper(scenario, buildWorld(scenario)) {}

CpuStepper::CpuStepper(const Scenario& scenario, World world) : m_scenario(scenario), m_world(std::move(world)) { setUp(); }

CpuStepper::~CpuStepper() {
  if (!m_clock.on || m_clock.steps == 0) return;
  double total = 0;
  for (const double t : m_clock.seconds) total += t;
  std::string line = fmt::format("gem cpu timing, {} steps, {} bodies, {} thread{}: {:.4f} ms a step; of it", m_clock.steps, m_world.size(),
                                 threads(), threads() == 1 ? "" : "s", 1e3 * total / static_cast<double>(m_clock.steps));
  for (int p = 0; p < PhaseClock::kPhases; ++p)
    line += fmt::format("{} {} {:.4f}", p ? "," : "", PhaseClock::kNames[static_cast<size_t>(p)],
                        1e3 * m_clock.seconds[static_cast<size_t>(p)] / static_cast<double>(m_clock.steps));
  std::fprintf(stderr, "%s\n", line.c_str());
  const std::array<const char*, PhaseClock::kStepKinds> kinds{"plain", "breaking or re-sorting", "right after those"};
  std::string byKind = "gem cpu steps by kind:";
  for (int k = 0; k < PhaseClock::kStepKinds; ++k) {
    const auto q = static_cast<size_t>(k);
    const long count = m_clock.stepCount[q];
    byKind += fmt::format("{} {} {} at {:.4f} ms, {:.4f} ms a step of all", k ? ";" : "", count, kinds[q],
                          count ? 1e3 * m_clock.stepSeconds[q] / static_cast<double>(count) : 0.0,
                          1e3 * m_clock.stepSeconds[q] / static_cast<double>(m_clock.steps));
  }
  std::fprintf(stderr, "%s\n", byKind.c_str());
  if (!m_pool) return;
  // Where the threads' time goes: a step is its rounds on the pool and the calling thread's work
  // between them; a round ends when its last task does, so "waiting on the last tasks" is the
  // imbalance, and the threads' busy share of the rounds' time is the pool's efficiency.
  const ThreadPool::Stats& pool = m_pool->stats();
  const double steps = static_cast<double>(m_clock.steps);
  const double threadSeconds = pool.inRounds * m_pool->size();
  std::fprintf(stderr,
               "gem cpu pool, %d threads: %.1f rounds and %.1f tasks a step; %.4f ms a step in rounds, %.4f of it waiting on the last "
               "tasks; %.4f ms a step between rounds on the calling thread; the threads busy %.0f %% of the rounds' time; the longest "
               "task %.4f ms a round\n",
               m_pool->size(), pool.rounds / steps, pool.tasks / steps, 1e3 * pool.inRounds / steps, 1e3 * pool.tail / steps,
               1e3 * (total - pool.inRounds) / steps, threadSeconds > 0 ? 100 * pool.busy / threadSeconds : 0.0,
               pool.rounds ? 1e3 * pool.longestTask / static_cast<double>(pool.rounds) : 0.0);
  // The serial part phase by phase: what a phase spent outside its rounds.
  std::string serial = "gem cpu pool, between rounds by phase, ms a step:";
  for (int p = 0; p < PhaseClock::kPhases; ++p) {
    const auto k = static_cast<size_t>(p);
    serial += fmt::format("{} {} {:.4f}", p ? "," : "", PhaseClock::kNames[k], 1e3 * (m_clock.seconds[k] - m_clock.inRounds[k]) / steps);
  }
  std::fprintf(stderr, "%s\n", serial.c_str());
}

namespace {

// Calls a plugin's parse function (make): what it throws other than an InputError (a
// std::runtime_error where TableReader::fail was meant, or anything at all) is refused as bad input
// naming the scenario, the event's table and the plugin, not left to end gem as an internal error
// that names nothing. A built-in's exception stays an internal error.
template <class Make>
auto parsePluginSafely(const EventEntry& entry, const toml::table* table, const std::string& file, Make&& make) {
  if (entry.origin == "built-in") return make();
  auto refuse = [&](const std::string& what) {
    const int line = table ? static_cast<int>(table->source().begin.line) : 0;
    const int column = table ? static_cast<int>(table->source().begin.column) : 0;
    return InputError(file, line, column,
                      fmt::format("events.{}: the plugin's parse function threw instead of reporting through its TableReader: {} "
                                  "(plugin {})",
                                  entry.name, what, entry.origin));
  };
  try {
    return make();
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw refuse(e.what());
  } catch (...) {
    throw refuse("an exception that is not a std::exception");
  }
}

}  // namespace

void CpuStepper::setUp() {
  const char* timing = std::getenv("GEM_CPU_TIMING");
  m_clock.on = timing && timing[0] == '1';
  const OverrideScope blameSet(m_scenario.overrides);  // an error in a --set value names the --set
  const BroadphaseEntry& strategy = Registry::global().broadphase(m_scenario.broadphase);
  m_broadphase = strategy.make(m_scenario.broadphaseSettings);
  m_broadphaseFromPlugin = strategy.origin != "built-in";
  // Every event's table is checked, and all their errors reported together (docs/scenario.md 2).
  ErrorCollector errors;
  std::optional<DefaultsRecorder> defaults;
  if (m_scenario.defaultsTaken) defaults.emplace(*m_scenario.defaultsTaken);
  try {
    for (const EventEntry* entry : Registry::global().events()) {
      auto it = m_scenario.events.find(entry->name);
      const toml::table* table = m_scenario.eventTable(entry->name);
      const bool enabled = it == m_scenario.events.end() ? entry->enabledByDefault : it->second.enabled;
      if (defaults) defaults->record("events." + entry->name + ".enabled", enabled);
      TableReader reader(table, "events." + entry->name, m_scenario.fileName);
      reader.accept("enabled");
      const std::string place = table
                                    ? fmt::format("{}:{}:{}", m_scenario.fileName, table->source().begin.line, table->source().begin.column)
                                    : m_scenario.fileName;
      m_streams.setOpener(
          fmt::format("{}: events.{} ({})", place, entry->name, entry->origin == "built-in" ? "built-in" : "plugin " + entry->origin));
      EventConfig config{reader, m_scenario, m_streams, enabled};
      auto instance = parsePluginSafely(*entry, table, m_scenario.fileName,
                                        [&] { return entry->makeCpu(config); });  // even when off: its table is checked
      reader.finish();
      if (enabled) m_events.push_back({entry->name, entry->phase, std::move(instance)});
    }
  } catch (const InputError& e) {
    if (!errors.followsFrom(e.what())) errors.add(e.what());
  }
  errors.throwIfAny();
  m_records.reset(m_streams);
  m_skipStillBodies = std::all_of(m_events.begin(), m_events.end(), [](const EnabledEvent& e) {
    return (e.phase != EventPhase::Solo && e.phase != EventPhase::Motion) || e.instance->timeInvariant();
  });
  for (int i = 0; i < m_world.size(); ++i)
    if (m_world.kind[i] == BodyKind::Vessel) m_vesselId = m_world.id[i];
  if (m_scenario.mortonSort) reorderAlongCurve();
}

const std::vector<std::pair<std::int64_t, Real>>* CpuStepper::contactForces() const {
  if (!m_contactForcesBuilt) {
    m_contactForces.clear();
    // The last gather wrote the forces of the bodies of a contact only: m_byBody lists their slots
    // until the next step's narrowphase.
    for (const int i : m_byBody.bodies) {
      if (static_cast<size_t>(i) >= m_contactImpulseOfSlot.size()) continue;
      const Vec2 onBody = m_contactImpulseOfSlot[static_cast<size_t>(i)];
      if (onBody.x == 0 && onBody.y == 0) continue;
      const Real force = norm(onBody) / m_scenario.dt;
      if (force > 0) m_contactForces.emplace_back(m_contactForceId[static_cast<size_t>(i)], force);
    }
    std::sort(m_contactForces.begin(), m_contactForces.end());
    m_contactForcesBuilt = true;
  }
  return &m_contactForces;
}

StepperState CpuStepper::saveState() {
  std::vector<std::pair<std::int64_t, std::int64_t>> touching = m_previousContacts;
  if (!m_previousSorted) std::sort(touching.begin(), touching.end());
  return StepperState{m_world, m_step, m_time, std::move(touching), m_rubbleMass, m_floesBroken};
}

void CpuStepper::restoreState(const StepperState& state) {
  m_world = state.world;
  m_step = state.step;
  m_time = state.time;
  m_previousContacts = state.touching;
  std::sort(m_previousContacts.begin(), m_previousContacts.end());
  m_previousSorted = true;
  m_rubbleMass = state.rubbleMass;
  m_floesBroken = state.floesBroken;
  // What was derived from the old world goes: every body's vertices are computed afresh (the same
  // poses give the same vertices), and the broadphase builds its lists from the new world.
  m_vertexPose.clear();
  m_lastSlotId.clear();  // "touched before" then comes from state.touching
  m_lastSeparated.clear();
  m_broadphase->invalidate();
  m_stillnessKnown = false, m_slotsRenamed = false;
  m_vesselId = -1;
  for (int i = 0; i < m_world.size(); ++i)
    if (m_world.kind[i] == BodyKind::Vessel) m_vesselId = m_world.id[i];
}

int CpuStepper::vesselSlot() const {
  if (m_vesselId < 0) return -1;
  // The slot found last time, while it still holds the vessel (a re-sort or a break may move it):
  // the gather searched all 10^5 slots on one thread every step.
  if (m_vesselSlotSeen >= 0 && m_vesselSlotSeen < m_world.size() && m_world.id[m_vesselSlotSeen] == m_vesselId) return m_vesselSlotSeen;
  for (int i = 0; i < m_world.size(); ++i)
    if (m_world.id[i] == m_vesselId) return m_vesselSlotSeen = i;
  return -1;
}

VesselSample CpuStepper::vessel() {
  const int v = vesselSlot();
  if (v < 0) return VesselSample{false, {0, 0}, 0, {0, 0}};
  return VesselSample{true, m_world.position(v), m_world.angle[v], m_world.velocity(v)};
}

// Re-sorts the bodies along a Morton curve (World::curveOrder). Every strategy sees the same order,
// so results stay identical.
void CpuStepper::reorderAlongCurve() {
  if (m_world.size() < 2) return;
  World::TaskRunner onThePool;
  if (m_pool) onThePool = [this](int count, const std::function<void(int)>& task) { m_pool->run(count, task); };
  m_world.permute(m_world.curveOrder(onThePool), onThePool, &m_permuteRoom);
  m_broadphase->bodiesRenamed();
  followBodiesToNewSlots();
}

int CpuStepper::rangesFor(int n, int from, int grain) const {
  // Small fields stay on one thread: waking the pool costs more than their work (on 2 cores the
  // 456-hexagon field took 0.116 ms a step on 2 threads against 0.079 ms on one).
  return m_pool && n >= from ? std::max(1, std::min(n / grain, kTasksPerThread * m_pool->size())) : 1;
}

void CpuStepper::forEachPart(int n, const std::function<void(int, int, int)>& range, int from, int grain) {
  const int tasks = rangesFor(n, from, grain);
  if (tasks <= 1) {
    range(0, 0, n);
    return;
  }
  m_pool->run(tasks, [&](int t) {
    range(t, static_cast<int>(static_cast<long>(n) * t / tasks), static_cast<int>(static_cast<long>(n) * (t + 1) / tasks));
  });
}

void CpuStepper::forEachRange(int n, const std::function<void(int, int)>& range, int from, int grain) {
  forEachPart(
      n, [&](int, int begin, int end) { range(begin, end); }, from, grain);
}

// Whether block b's bodies all hold kStill in m_stillness: one flag a block, kept with the flags
// (m_blockStill). Scanning every body's flag and contact stamp each step to find the few blocks to
// update was an O(bodies) pass (0.2 million instructions a step at 10^5 floes, half a megabyte
// read) in a step whose work follows the few hundred moving bodies.
void CpuStepper::noteBlockStill(int b) {
  const int begin = b * kBlock, end = std::min(static_cast<int>(m_stillness.size()), begin + kBlock);
  int still = 0;  // a count, not a bool: the compiler vectorizes an integer sum
  for (int i = begin; i < end; ++i) still += m_stillness[static_cast<size_t>(i)] == kStill;
  m_blockStill[static_cast<size_t>(b)] = still == end - begin;
}

// Body i's flags for the coming narrowphase, from its pose now: moved when the pose is not the one
// its world vertices and box were made for (a slot that changed hands has moved: the pose holds
// the id), and then the vertices and box are made again, or when `movedBefore` says the body moved
// since the last narrowphase though its vertices already follow; active when moved or in a contact
// of the last narrowphase. Most floes of a pack rest untouched (drag keeps a resting floe exactly
// at rest): their world vertices from an earlier step are still exact. Inline (it is used in this
// file only): called out of line for every body of every step, its call was 1 % of the 824-floe
// step's instructions, and a member of a shared library is not inlined unless it says so.
inline bool CpuStepper::refreshPose(int i, bool inContact, bool movedBefore) {
  const Pose pose{m_world.id[i], m_world.x[i], m_world.y[i], m_world.angle[i]};
  const bool changed = !(pose == m_vertexPose[static_cast<size_t>(i)]);
  const bool moved = changed || movedBefore;
  m_moved[static_cast<size_t>(i)] = moved;
  m_active[static_cast<size_t>(i)] = moved || inContact;
  if (!changed) return moved;
  m_vertexPose[static_cast<size_t>(i)] = pose;
  m_boxes[static_cast<size_t>(i)] =
      toWorldWithBox(m_world.local(i), m_world.vertexCount[i], m_world.position(i), m_world.angle[i], worldVerticesOf(i));
  return true;
}

// A re-sort or a break leaves every body's state as it was (TopologyData: an event changes the
// bodies only through World::removeBodies and World::addBody) but puts most bodies in other slots:
// a break shifts every slot after the broken floe's, a re-sort nearly every slot. What the last
// body updates left by slot (the still flags, the poses' flags, boxes and vertex rows) moves with
// its body, found by id (a body keeps its shape while it keeps its id, as the kept lists assume),
// so that the next step passes over the bodies that did not move, as any step does. Taken afresh
// instead, every body counted as moved: at 10^5 floes on one core the step after a re-sort or a
// break took 20 to 30 ms (every body's vertices made again, every pair whose boxes overlap tested
// from scratch, every body updated), more in all than the plain steps between re-sorts.
// A new body, or one whose pose is not the one its vertices were made for (an event that broke
// the contract above), is moving, its vertices made here in a free row. The trajectories are the
// same: what follows a body is what the next step would compute for it (the same pose gives the
// same vertices), and the pairs it lets the narrowphase pass over are those of two bodies that did
// not move and did not touch, as in any step.
void CpuStepper::followBodiesToNewSlots() {
  const int n = m_world.size();
  const size_t before = m_vertexPose.size();
  const bool known = m_stillnessKnown && m_stillness.size() == before && m_moved.size() == before && m_active.size() == before &&
                     m_boxes.size() == before && m_vertexRow.size() == before;
  m_stillnessKnown = false;  // unless the flags follow their bodies below
  if (!known) return;
  // Each id's slot before, in a table by id up to the world's next id (an id outside it, negative
  // or set by hand past it, is a body taken for new); ids too sparse for a table leave the next
  // step to read every body afresh.
  const std::int64_t ids = m_world.nextId;
  // The table is not cleared: an entry this pass did not write may name any slot, and a new slot
  // takes an old one only if that slot held the body's id at the body's pose (below), which a
  // stale entry never does (the slot holding that id would have written the entry). Clearing it
  // was a serial pass over every id, a tenth of a rename's serial time on 16 threads.
  if (ids > 4 * (static_cast<std::int64_t>(n) + static_cast<std::int64_t>(before)) + 1024) return;
  if (m_oldSlotOfId.size() < static_cast<size_t>(std::max<std::int64_t>(ids, 0))) m_oldSlotOfId.resize(static_cast<size_t>(ids));
  const int slotsBefore = static_cast<int>(before);
  m_takenBy.resize(before);
  forEachRange(slotsBefore, [&](int begin, int end) {  // relaxed atomic stores: a repeated id races only over which slot
    for (int j = begin; j < end; ++j) {
      m_takenBy[static_cast<size_t>(j)] = -1;
      if (const std::int64_t id = m_vertexPose[static_cast<size_t>(j)].id; id >= 0 && id < ids)
        std::atomic_ref<int>(m_oldSlotOfId[static_cast<size_t>(id)]).store(j, std::memory_order_relaxed);
    }
  });
  // Each new slot takes what its body's old slot holds, and notes that it did (m_takenBy); a body
  // that is new, or not at the pose its vertices were made for, or whose old slot another new slot
  // took (a repeated id), gets a free row below.
  const size_t bodies = static_cast<size_t>(n);
  m_nextVertexRow.resize(bodies), m_nextBoxes.resize(bodies), m_nextVertexPose.resize(bodies);
  m_nextMoved.resize(bodies), m_nextActive.resize(bodies), m_nextStillness.resize(bodies), m_oldSlot.resize(bodies);
  forEachRange(n, [&](int begin, int end) {
    for (int i = begin; i < end; ++i) {
      const size_t k = static_cast<size_t>(i);
      const Pose pose{m_world.id[k], m_world.x[k], m_world.y[k], m_world.angle[k]};
      int old = pose.id >= 0 && pose.id < ids
                    ? std::atomic_ref<int>(m_oldSlotOfId[static_cast<size_t>(pose.id)]).load(std::memory_order_relaxed)
                    : -1;
      if (old >= 0 && (old >= slotsBefore || !(m_vertexPose[static_cast<size_t>(old)] == pose))) old = -1;
      m_oldSlot[k] = old;
      if (old < 0) continue;
      std::atomic_ref<int>(m_takenBy[static_cast<size_t>(old)]).store(i, std::memory_order_relaxed);
      const size_t j = static_cast<size_t>(old);
      m_nextVertexRow[k] = m_vertexRow[j], m_nextBoxes[k] = m_boxes[j], m_nextVertexPose[k] = pose;
      m_nextMoved[k] = m_moved[j], m_nextActive[k] = m_active[j], m_nextStillness[k] = m_stillness[j];
    }
  });
  // Over ranges of the old slots and the new, each range's part lists, in order, the rows of the
  // bodies that went (free now) and the new slots whose body took no old slot (a row each below,
  // on one thread: they are the few new bodies of a break). The parts joined in order give the
  // lists one pass over the slots would: on 16 threads these two serial passes over every slot
  // were most of a rename's serial time.
  const int slots = std::max(slotsBefore, n);
  m_followParts.resize(static_cast<size_t>(rangesFor(slots)));
  forEachPart(slots, [&](int part, int begin, int end) {
    FollowPart& mine = m_followParts[static_cast<size_t>(part)];
    mine.freeRows.clear(), mine.newSlots.clear();
    for (int j = begin; j < std::min(end, slotsBefore); ++j)
      if (m_takenBy[static_cast<size_t>(j)] < 0) mine.freeRows.push_back(m_vertexRow[static_cast<size_t>(j)]);
    for (int i = begin; i < std::min(end, n); ++i)
      if (const int old = m_oldSlot[static_cast<size_t>(i)]; old < 0 || m_takenBy[static_cast<size_t>(old)] != i)
        mine.newSlots.push_back(i);
  });
  for (const FollowPart& part : m_followParts) m_freeRows.insert(m_freeRows.end(), part.freeRows.begin(), part.freeRows.end());
  m_vertexRow.swap(m_nextVertexRow), m_boxes.swap(m_nextBoxes), m_vertexPose.swap(m_nextVertexPose);
  m_moved.swap(m_nextMoved), m_active.swap(m_nextActive), m_stillness.swap(m_nextStillness);
  for (const FollowPart& part : m_followParts)
    for (const int i : part.newSlots) {
      if (m_freeRows.empty()) {
        m_freeRows.push_back(m_rowCount++);
        m_worldVertices.resize(static_cast<size_t>(m_rowCount) * kMaxVertices);
      }
      m_vertexRow[static_cast<size_t>(i)] = m_freeRows.back();
      m_freeRows.pop_back();
      m_vertexPose[static_cast<size_t>(i)] = Pose{-1, 0, 0, 0};  // made afresh: refreshPose
      m_stillness[static_cast<size_t>(i)] = kMoving;
      refreshPose(i, false, true);
    }
  m_blockStill.resize(static_cast<size_t>((n + kBlock - 1) / kBlock));
  forEachRange(static_cast<int>(m_blockStill.size()), [&](int begin, int end) {
    for (int b = begin; b < end; ++b) noteBlockStill(b);
  });
  m_stillnessKnown = true;
  m_slotsRenamed = true;
}

void CpuStepper::narrowphase() {
  const int n = m_world.size();
  m_boxes.resize(n);
  // Every slot's own row: those followBodiesToNewSlots left, or, after an edit that changed the
  // slots, each slot's row its own again, its vertices to be made afresh.
  if (m_vertexRow.size() != static_cast<size_t>(n)) {
    m_vertexRow.resize(static_cast<size_t>(n));
    for (int i = 0; i < n; ++i) m_vertexRow[static_cast<size_t>(i)] = i;
    m_freeRows.clear(), m_rowCount = n;
    // Room for an eighth more rows, untouched until used: a break adds a row for each piece beyond
    // the rows it freed, and the first growth past the rows made here moved them all (38 MB at
    // 10^5 floes, 20 ms on one thread in the bench's first break).
    m_worldVertices.reserve((static_cast<size_t>(n) + static_cast<size_t>(n) / 8 + 64) * kMaxVertices);
    m_worldVertices.resize(static_cast<size_t>(n) * kMaxVertices);
    m_vertexPose.assign(static_cast<size_t>(n), Pose{-1, 0, 0, 0});
  }
  m_vertexPose.resize(n, Pose{-1, 0, 0, 0});
  m_moved.resize(n), m_active.resize(n);  // each body's flags are set below, or were by the body updates
  // Whether a slot changed hands since the last narrowphase (a re-sort, a break, a restored state),
  // seen in the pass over the bodies below rather than in a serial one of its own.
  const int lastSlots = static_cast<int>(m_lastSlotId.size());
  std::atomic<bool> slotsChanged{n != lastSlots || m_slotsRenamed};
  m_slotsRenamed = false;
  // While the still flags are known (m_stillness), the last body updates left every body's pose
  // flags, world vertices and box ready for this narrowphase (refreshPose, called as they wrote each
  // pose back), by the slots the bodies hold now (a re-sort or a break moved them along:
  // followBodiesToNewSlots): nothing is left to do here. After an edit or a restored state every
  // body is looked at afresh. A body whose slot kept it
  // keeps the body updates' "moved" too: they made its vertices for the pose it has now, so the
  // pose alone no longer tells that it moved (a slot that changed hands has moved anyway).
  const bool posesReady = m_stillnessKnown && static_cast<int>(m_stillness.size()) == n;
  if (!posesReady) {
    forEachRange(n, [&](int begin, int end) {
      for (int i = begin; i < end; ++i) {
        if (i < lastSlots && m_lastSlotId[i] != m_world.id[i]) slotsChanged.store(true, std::memory_order_relaxed);
        refreshPose(i, m_byBody.has(i), m_moved[static_cast<size_t>(i)] != 0);
      }
    });
  }

  // touchedAtLastStep searches the last step's contacts only for a pair whose two slots have both
  // changed hands since (a re-sort, a break, a restored state): only then are they sorted.
  if (!m_previousSorted && slotsChanged.load(std::memory_order_relaxed)) {
    std::sort(m_previousContacts.begin(), m_previousContacts.end());
    m_previousSorted = true;
  }

  // The candidates in two passes. The box pass keeps, part by part, the candidates whose boxes
  // overlap; the exact pass tests the survivors, cut into parts of equal counts of survivors. The
  // box pass reads only the stretches between the broadphase's resting ranges (m_toScan), cut
  // into parts of equal counts of candidates to read: at 10^5 floes they are an eighth of the
  // candidates, around the vessel, and ranges of all the candidates gave one task nearly all of
  // them. The survivors crowd there too, so ranges of candidates can give one task nearly all the
  // exact tests while the other threads wait. The parts' contacts, joined in order, are the
  // contacts of one pass over all the pairs.
  const int pairs = static_cast<int>(m_pairs.size());
  m_toScan.clear(), m_scanBefore.assign(1, 0);
  long scanned = 0;
  for (const CandidateRange& r : m_restingPairs) {
    if (r.begin > scanned) m_toScan.push_back({scanned, r.begin}), m_scanBefore.push_back(m_scanBefore.back() + r.begin - scanned);
    scanned = r.end;
  }
  if (scanned < pairs) m_toScan.push_back({scanned, pairs}), m_scanBefore.push_back(m_scanBefore.back() + pairs - scanned);
  const long toScan = m_scanBefore.back();
  const int tasks =
      m_pool && toScan >= kParallelPairs ? static_cast<int>(std::min<long>(toScan / kGrain, kTasksPerThread * m_pool->size())) : 1;
  m_parts.resize(static_cast<size_t>(tasks));
  auto boxPass = [&](int t) {
    NarrowphasePart& part = m_parts[static_cast<size_t>(t)];
    const long shareBegin = toScan * t / tasks, shareEnd = toScan * (t + 1) / tasks;
    // Most candidates are near misses: the world-aligned boxes reject them in four comparisons.
    // About one in four passes, so a branch would mispredict often: every candidate is written
    // to the scratch list and kept by advancing the count (boxesOverlap's test, without its
    // short-circuits), and only the survivors take the branches of mayTouch and after.
    part.boxSurvivors.resize(static_cast<size_t>(shareEnd - shareBegin));
    int* survivor = part.boxSurvivors.data();
    int survivors = 0;
    const Box* boxes = m_boxes.data();
    const char* active = m_active.data();
    auto scan = [&](int from, int to) {
      for (int p = from; p < to; ++p) {
        const CandidatePair pair = m_pairs[static_cast<size_t>(p)];
        // Two bodies that have not moved since the last step and touched nothing then do not touch
        // now (the test after mayTouch below): skipped before their boxes are read. In a pack most
        // pairs rest, and reading the boxes was the loop's main cost.
        if (!(active[pair.a] | active[pair.b])) continue;
        survivor[survivors] = p;
        survivors += boxesMeet(boxes[pair.a], boxes[pair.b]);
      }
    };
    // The task's share of the stretches to read, stretch by stretch from the one holding its first.
    size_t k = static_cast<size_t>(std::upper_bound(m_scanBefore.begin(), m_scanBefore.end(), shareBegin) - m_scanBefore.begin()) - 1;
    for (long at = shareBegin; at < shareEnd; ++k) {
      const long stretchEnd = std::min(shareEnd, m_scanBefore[k + 1]);
      const long offset = m_toScan[k].begin - m_scanBefore[k];  // candidate number = share position + offset
      scan(static_cast<int>(at + offset), static_cast<int>(stretchEnd + offset));
      at = stretchEnd;
    }
    part.survivors = survivors;  // the scratch keeps its size: grown again, it would be zeroed every step
  };
  // The exact tests of `count` survivors (candidate numbers, in order), appended to `part`'s
  // contacts and separated pairs. `cached` walks the last step's separated pairs, in the same
  // (a, b) order as the candidates, alongside: a broadphase that lists its pairs out of order only
  // finds fewer of them.
  using SeparatedCursor = std::vector<SeparatedPair>::const_iterator;
  const int* vertexRow = m_vertexRow.data();
  auto exactTests = [&](NarrowphasePart& part, const int* survivor, int count, SeparatedCursor& cached) {
    for (int s = 0; s < count; ++s) {
      const int p = survivor[s];
      const int a = m_pairs[static_cast<size_t>(p)].a, b = m_pairs[static_cast<size_t>(p)].b;
      if (m_world.invMass[a] == 0 && m_world.invMass[b] == 0) continue;  // mayTouch: two walls (the boxes passed above)
      const bool touchedBefore = touchedAtLastStep(a, b);
      // Two bodies that have not moved since the last step, and did not touch then, do not touch
      // now: the same polygons give the same answer. Most of a pack rests ahead of the vessel.
      // (A touching pair is always a candidate, whatever the broadphase, so "did not touch then"
      // is exactly "not among the last step's contacts".)
      if (!m_moved[a] && !m_moved[b] && !touchedBefore) continue;
      const Vec2* pa = &m_worldVertices[static_cast<size_t>(vertexRow[a]) * kMaxVertices];
      const Vec2* pb = &m_worldVertices[static_cast<size_t>(vertexRow[b]) * kMaxVertices];
      const int na = m_world.vertexCount[a], nb = m_world.vertexCount[b];
      if (!touchedBefore) {
        // Apart last step, most likely apart now, and most likely along the same edge: try it
        // first, then the others. An edge that separates is a "not touching" from computeContact
        // (sat.hpp), so this only skips work, never changes an answer.
        while (cached != m_lastSeparated.cend() && (cached->a < a || (cached->a == a && cached->b < b))) ++cached;
        const bool hit = cached != m_lastSeparated.cend() && cached->a == a && cached->b == b;
        SeparatingEdge axis = hit ? cached->axis : SeparatingEdge{-1, 0};
        if (!separatesAlong(axis, pa, na, pb, nb)) axis = findSeparatingEdge(pa, na, pb, nb);
        if (axis.side >= 0) {
          part.separated.push_back(SeparatedPair{a, b, axis});
          continue;
        }
      }
      // A pair apart last step that no edge separates now overlaps: only the clipping is left. Its
      // merge tolerance comes from the boxes the pose pass made: the scan clipConvex would repeat.
      const Box& boxA = m_boxes[static_cast<size_t>(a)];
      const Box& boxB = m_boxes[static_cast<size_t>(b)];
      const Real clipTol =
          clipToleranceOf(clipScaleOfBox(boxA.x0, boxA.y0, boxA.x1, boxA.y1), clipScaleOfBox(boxB.x0, boxB.y0, boxB.x1, boxB.y1));
      const Contact c = touchedBefore ? computeContact(pa, na, m_world.position(a), pb, nb, m_world.position(b), clipTol)
                                      : contactOfOverlapping(pa, na, m_world.position(a), pb, nb, m_world.position(b), clipTol);
      if (!c.touching) continue;
      part.a.push_back(a);
      part.b.push_back(b);
      part.contacts.push_back(PairContact{c, !touchedBefore});
      part.keys.emplace_back(std::minmax(m_world.id[a], m_world.id[b]));
    }
  };
  auto clearContacts = [](NarrowphasePart& part) {
    part.a.clear(), part.b.clear(), part.contacts.clear(), part.keys.clear(), part.separated.clear();
  };
  if (tasks == 1) {
    boxPass(0);
    NarrowphasePart& part = m_parts[0];
    clearContacts(part);
    SeparatedCursor cached = m_lastSeparated.cbegin();
    exactTests(part, part.boxSurvivors.data(), part.survivors, cached);
  } else {
    m_pool->run(tasks, boxPass);
    // The survivors numbered across the parts: part t's come from m_survivorsBefore[t] on.
    m_survivorsBefore.resize(static_cast<size_t>(tasks) + 1);
    m_survivorsBefore[0] = 0;
    for (int t = 0; t < tasks; ++t)
      m_survivorsBefore[static_cast<size_t>(t) + 1] = m_survivorsBefore[static_cast<size_t>(t)] + m_parts[static_cast<size_t>(t)].survivors;
    const long survivors = m_survivorsBefore[static_cast<size_t>(tasks)];
    m_pool->run(tasks, [&](int t) {
      NarrowphasePart& part = m_parts[static_cast<size_t>(t)];
      clearContacts(part);
      long from = survivors * t / tasks;
      const long to = survivors * (t + 1) / tasks;
      if (from >= to) return;
      // The part holding survivor `from`, then the survivors up to `to` part by part.
      int source =
          static_cast<int>(std::upper_bound(m_survivorsBefore.begin(), m_survivorsBefore.end(), from) - m_survivorsBefore.begin()) - 1;
      const int first =
          m_parts[static_cast<size_t>(source)].boxSurvivors[static_cast<size_t>(from - m_survivorsBefore[static_cast<size_t>(source)])];
      SeparatedCursor cached =
          std::lower_bound(m_lastSeparated.cbegin(), m_lastSeparated.cend(), m_pairs[static_cast<size_t>(first)],
                           [](const SeparatedPair& s, const CandidatePair& c) { return s.a < c.a || (s.a == c.a && s.b < c.b); });
      for (; from < to; ++source) {
        const long begin = m_survivorsBefore[static_cast<size_t>(source)],
                   end = std::min(to, m_survivorsBefore[static_cast<size_t>(source) + 1]);
        if (from >= end) continue;
        exactTests(part, m_parts[static_cast<size_t>(source)].boxSurvivors.data() + (from - begin), static_cast<int>(end - from), cached);
        from = end;
      }
    });
  }
  m_clock.lap(PhaseClock::Tests);

  joinParts(tasks);
  if (slotsChanged.load(std::memory_order_relaxed)) {  // after a break or a re-sort: 0.8 MB at 10^5 floes, over ranges
    m_lastSlotId.resize(static_cast<size_t>(n));
    forEachRange(
        n, [&](int begin, int end) { std::copy(m_world.id.begin() + begin, m_world.id.begin() + end, m_lastSlotId.begin() + begin); });
  }
  m_byBody.build(m_contactA, m_contactB, n);
  m_clock.lap(PhaseClock::Join);
}

// The narrowphase's parts joined in task order: the contacts of one pass over all the pairs. One
// part (one thread) is taken over whole. Several are copied to their places, on the pool when
// they hold more than kParallelJoin pairs: in a pack at rest they are a few dozen (a resting pair
// is not tested again), but where the whole field moves (a current, a re-sort step) the separated
// pairs of 10^5 floes pass a megabyte, too much for one thread of sixteen.
void CpuStepper::joinParts(int tasks) {
  if (tasks == 1) {
    NarrowphasePart& part = m_parts[0];
    m_contactA.swap(part.a), m_contactB.swap(part.b), m_contacts.swap(part.contacts);
    m_previousContacts.swap(part.keys), m_lastSeparated.swap(part.separated);
  } else {
    m_joinAt.resize(static_cast<size_t>(tasks));
    size_t contacts = 0, separated = 0;
    for (int t = 0; t < tasks; ++t) {
      const NarrowphasePart& part = m_parts[static_cast<size_t>(t)];
      m_joinAt[static_cast<size_t>(t)] = {contacts, separated};
      contacts += part.a.size(), separated += part.separated.size();
    }
    // resize, not clear: only what grows past last step's size is filled before it is overwritten.
    m_contactA.resize(contacts), m_contactB.resize(contacts), m_contacts.resize(contacts), m_currentContacts.resize(contacts);
    m_separated.resize(separated);
    auto copyPart = [&](int t) {
      const NarrowphasePart& part = m_parts[static_cast<size_t>(t)];
      const auto [c, s] = m_joinAt[static_cast<size_t>(t)];
      const auto at = static_cast<std::ptrdiff_t>(c);
      std::copy(part.a.begin(), part.a.end(), m_contactA.begin() + at);
      std::copy(part.b.begin(), part.b.end(), m_contactB.begin() + at);
      std::copy(part.contacts.begin(), part.contacts.end(), m_contacts.begin() + at);
      std::copy(part.keys.begin(), part.keys.end(), m_currentContacts.begin() + at);
      std::copy(part.separated.begin(), part.separated.end(), m_separated.begin() + static_cast<std::ptrdiff_t>(s));
    };
    if (contacts + separated >= kParallelJoin)
      m_pool->run(tasks, copyPart);
    else
      for (int t = 0; t < tasks; ++t) copyPart(t);
    m_previousContacts.swap(m_currentContacts);
    m_lastSeparated.swap(m_separated);
  }
  m_previousSorted = false;  // in contact order, sorted only when searched (narrowphase)
}

void CpuStepper::ContactsByBody::build(const std::vector<int>& a, const std::vector<int>& b, int n) {
  if (++current == 0) {  // the stamps wrapped: start them afresh
    stamp.assign(stamp.size(), 0);
    current = 1;
  }
  stamp.resize(static_cast<size_t>(n), 0), start.resize(static_cast<size_t>(n)), count.resize(static_cast<size_t>(n));
  bodies.clear();
  const size_t contacts = a.size();
  for (size_t k = 0; k < contacts; ++k)
    for (const int i : {a[k], b[k]}) {
      if (stamp[static_cast<size_t>(i)] != current)
        stamp[static_cast<size_t>(i)] = current, count[static_cast<size_t>(i)] = 0, bodies.push_back(i);
      ++count[static_cast<size_t>(i)];
    }
  int next = 0;
  for (const int i : bodies) start[static_cast<size_t>(i)] = next, next += count[static_cast<size_t>(i)], count[static_cast<size_t>(i)] = 0;
  entries.resize(2 * contacts);
  for (size_t k = 0; k < contacts; ++k) {
    entries[static_cast<size_t>(start[static_cast<size_t>(a[k])] + count[static_cast<size_t>(a[k])]++)] = static_cast<int>(2 * k);
    entries[static_cast<size_t>(start[static_cast<size_t>(b[k])] + count[static_cast<size_t>(b[k])]++)] = static_cast<int>(2 * k + 1);
  }
}

[[gnu::always_inline]] inline bool CpuStepper::touchedAtLastStep(int a, int b) const {
  // A slot that still holds the body it held then lists that body's partners, most often none or
  // one or two: a's if it can, else b's. Only when both slots changed hands (a re-sort, a break)
  // is the last step's contact list searched.
  const int slots = static_cast<int>(m_lastSlotId.size());
  int self = a, other = b;
  if (a >= slots || m_lastSlotId[a] != m_world.id[a]) {
    if (b >= slots || m_lastSlotId[b] != m_world.id[b])
      return std::binary_search(m_previousContacts.begin(), m_previousContacts.end(),
                                std::pair<std::int64_t, std::int64_t>(std::minmax(m_world.id[a], m_world.id[b])));
    self = b, other = a;
  }
  // The last step's contacts of self's slot (m_contactA/B still hold them): the partner's slot then,
  // and the id that slot held then.
  if (!m_byBody.has(self)) return false;
  const std::int64_t otherId = m_world.id[other];
  const int* entry = &m_byBody.entries[static_cast<size_t>(m_byBody.start[static_cast<size_t>(self)])];
  for (int q = 0; q < m_byBody.count[static_cast<size_t>(self)]; ++q) {
    const size_t k = static_cast<size_t>(entry[q] / 2);
    const int partner = entry[q] % 2 ? m_contactA[k] : m_contactB[k];
    if (m_lastSlotId[static_cast<size_t>(partner)] == otherId) return true;
  }
  return false;
}

void CpuStepper::step() {
  // The pool is made by the first step: a CPU stepper that only mirrors a device's world (the
  // CUDA backend's, one per case of a sweep) never steps and never starts threads.
  if (!m_poolChecked) {
    m_poolChecked = true;
    const int threads = threadsFor(m_scenario.threads);
    if (threads > 1) {
      m_pool = std::make_unique<ThreadPool>(threads);
      m_pool->setMeasuring(m_clock.on);
      m_clock.pool = m_pool.get();
    }
  }
  m_clock.start();
  const bool afterRenaming = m_slotsRenamed;
  const StepContext ctx{m_scenario.dt, m_time, m_step};
  const int n = m_world.size();
  const int vesselDof = m_scenario.vessel.dof;

  // 1-2. Candidates, then contacts. The broadphase may borrow the pool (framework/api/parallel.hpp):
  // the kept lists' build and filter run over ranges joined in order. It is told which bodies the
  // last step left still (framework/api/still_bodies.hpp): the flags hold while no slot has changed
  // hands and nothing has edited the world since the last body updates. A kStill body (the
  // broadphase's kRestingBody) is also inactive in the narrowphase, which passes over the ranges of
  // candidates the broadphase finds to be pairs of two of them (m_restingPairs).
  static_assert(kStill == kRestingBody, "the narrowphase tests no pair of two kStill bodies");
  m_restingPairs.clear();
  {
    const ParallelScope lend(m_pool.get());
    // After a re-sort or a break the flags follow the bodies (followBodiesToNewSlots), which is
    // what they promise a broadphase that was told of the renaming (bodiesRenamed).
    const bool stillKnown = m_stillnessKnown && static_cast<int>(m_stillness.size()) == n;
    const StillBodiesScope still(stillKnown ? m_stillness.data() : nullptr);
    const RestingPairsScope resting(stillKnown ? &m_restingPairs : nullptr);
    m_broadphase->findCandidates(m_world, m_pairs);
  }
  if (m_broadphaseFromPlugin) normalizeCandidatePairs(m_pairs), m_restingPairs.clear();
  m_clock.lap(PhaseClock::Broadphase);
  narrowphase();

  // 3. Two-body events write into each contact's slot. Only the bodies of a contact get a pair
  // view (a pair event reads its two bodies, the gather those that have contacts): about one body
  // in five in a pack.
  const int contacts = static_cast<int>(m_contacts.size());
  m_pairBodies.resize(n);
  forEachRange(
      static_cast<int>(m_byBody.bodies.size()),
      [&](int begin, int end) {
        for (int q = begin; q < end; ++q) {
          const int i = m_byBody.bodies[static_cast<size_t>(q)];
          m_pairBodies[i] =
              pairBodyOf(m_world, i, degreesOfFreedom(m_world.kind[i], vesselDof), worldVerticesOf(i), m_world.vertexCount[i]);
        }
      },
      kParallelPairViews, kPairViewGrain);
  m_slots.assign(contacts, PairSlot{{0, 0}});
  // The pair events over contiguous ranges of contacts, each range running them all in their
  // order (a contact's slot is its own; an event's apply is a function of its contact, as on the
  // device, so a contact meets the events in the order one pass event by event gives). Each range pushes
  // its records into buffers of its own, with the contact numbered within the range; they are
  // joined below event by event, range by range, the numbers shifted to the step's: the very rows,
  // in the very order, of one pass over all contacts. Each stream has room for one row per contact
  // at first; an event may push more (a log of several rows), and then the buffers grow and the
  // phase runs again (pair events only write their slots and records, so running them again is
  // running them once).
  const int streams = m_streams.count();
  const int ranges = m_pool && contacts >= kParallelContacts ? std::min(contacts / kContactGrain, kTasksPerThread * m_pool->size()) : 1;
  auto rangeStart = [&](int t) { return static_cast<int>(static_cast<long>(contacts) * t / ranges); };
  const size_t cells = static_cast<size_t>(ranges) * static_cast<size_t>(streams);
  m_pairRecordRows.resize(std::max(m_pairRecordRows.size(), cells));
  m_pairRecordRoom.resize(std::max(m_pairRecordRoom.size(), cells), 0);
  std::vector<int> counts(cells);
  std::vector<int> ends;  // per pair event, range and stream: the rows pushed by then
  std::vector<EventInstance*> pairEvents;
  for (auto& e : m_events)
    if (e.phase == EventPhase::Pair) pairEvents.push_back(e.instance.get());
  for (;;) {
    std::vector<RecordSink> sinks(static_cast<size_t>(ranges));
    for (int t = 0; t < ranges; ++t)
      for (int s = 0; s < streams; ++s) {
        const size_t c = static_cast<size_t>(t) * static_cast<size_t>(streams) + static_cast<size_t>(s);
        int& room = m_pairRecordRoom[c];
        room = std::max(room, rangeStart(t + 1) - rangeStart(t));
        m_pairRecordRows[c].resize(static_cast<size_t>(room) * static_cast<size_t>(m_streams.info(s).stride));
        counts[c] = 0;
        sinks[static_cast<size_t>(t)].streams[s] = RecordBuffer{m_pairRecordRows[c].data(), m_streams.info(s).stride, room, &counts[c]};
      }
    // One round of the pool for all the events: a round an event cost a hand-off each.
    ends.assign(pairEvents.size() * cells, 0);
    auto range = [&](int t) {
      const int begin = rangeStart(t);
      for (size_t event = 0; event < pairEvents.size(); ++event) {
        const PairPhaseData pairData{m_pairBodies.data(),
                                     m_contactA.data() + begin,
                                     m_contactB.data() + begin,
                                     m_contacts.data() + begin,
                                     m_slots.data() + begin,
                                     rangeStart(t + 1) - begin,
                                     ctx,
                                     sinks[static_cast<size_t>(t)],
                                     static_cast<int>(event)};
        pairEvents[event]->runPairs(pairData);
        for (int s = 0; s < streams; ++s) {
          const size_t c = static_cast<size_t>(t) * static_cast<size_t>(streams) + static_cast<size_t>(s);
          ends[event * cells + c] = counts[c];
        }
      }
    };
    if (ranges > 1)
      m_pool->run(ranges, range);
    else
      range(0);
    bool overflow = false;
    for (size_t c = 0; c < cells; ++c)
      if (counts[c] > m_pairRecordRoom[c]) m_pairRecordRoom[c] = counts[c], overflow = true;
    if (!overflow) break;
    m_slots.assign(contacts, PairSlot{{0, 0}});
  }
  m_records.clear();
  const int events = static_cast<int>(ends.size() / std::max<size_t>(cells, 1));
  for (int s = 0; s < streams; ++s) {
    const size_t stride = static_cast<size_t>(m_streams.info(s).stride);
    for (int event = 0; event < events; ++event)
      for (int t = 0; t < ranges; ++t) {
        const size_t c = static_cast<size_t>(t) * static_cast<size_t>(streams) + static_cast<size_t>(s);
        const int from = event ? ends[static_cast<size_t>(event - 1) * cells + c] : 0, to = ends[static_cast<size_t>(event) * cells + c];
        unsigned char* rows = m_pairRecordRows[c].data();
        for (int row = from; t > 0 && row < to; ++row) {  // the contact's number in the step
          RecordTag tag;
          std::memcpy(&tag, rows + static_cast<size_t>(row) * stride, sizeof tag);
          tag.contact += rangeStart(t);
          std::memcpy(rows + static_cast<size_t>(row) * stride, &tag, sizeof tag);
        }
        m_records.append(s, rows + static_cast<size_t>(from) * stride, to - from);
      }
  }
  if (m_deliverLogs) deliverLogs(m_records);
  m_clock.lap(PhaseClock::PairEvents);

  // 4-5. Solo events from the state at the start of the step, then the gather, the motion events
  // and the write-back, block by block (bodyUpdates).
  bodyUpdates(ctx);
  m_clock.lap(PhaseClock::BodyUpdates);

  // 6. Topology: breaks, rubble, new floes.
  TopologyData topology{&m_world, &m_records, m_time};
  {
    const ParallelScope lend(m_pool.get());  // World::removeBodies compacts its arrays in parallel
    for (auto& e : m_events)
      if (e.phase == EventPhase::Topology) e.instance->runTopology(topology);
  }
  m_rubbleMass += topology.rubbleMass;
  m_floesBroken += topology.floesBroken;
  if (topology.changed) m_broadphase->bodiesRenamed();  // removeBodies and addBody only (TopologyData)
  if (topology.changed || m_world.size() != n) followBodiesToNewSlots();

  ++m_step;
  m_time = stepTime(m_step, m_scenario.dt);
  const bool reSort = m_scenario.mortonSort && isResortStep(m_step);
  if (reSort) reorderAlongCurve();
  m_clock.lap(PhaseClock::Topology);
  ++m_clock.steps;
  m_clock.endStep(topology.changed || reSort ? PhaseClock::Renaming : afterRenaming ? PhaseClock::AfterRenaming : PhaseClock::Plain);
}

// Phases 4 and 5 of the step (docs/architecture.md "The step") for one block of bodies after
// another. A solo event sees one body, and the gather, the motion events and the write-back touch
// only their block's bodies, so a block's solo events still read the state at the start of the
// step, and running the two phases a block at a time gives every body the very same sums, in the
// very same order, as running them one after the other over the whole field. Done that way, the
// views and velocity changes of a block never leave the cache: as two phases they were written
// out for 10^5 bodies and read back, and the two phases were a third of a 10^5-floe step and
// bound by memory (on 2 cores they ran 1.2x to 1.8x faster than on one).
void CpuStepper::bodyUpdates(const StepContext& ctx) {
  const int n = m_world.size();
  const int vesselDof = m_scenario.vessel.dof;
  // Impulses: every body sums its contacts in contact order (sorted by slot pair), so the sum is
  // the same whatever broadphase found the pairs, and no atomics are needed. Each body's contacts,
  // in contact order, as a = -impulse and b = +impulse (m_byBody: k x 2 + side).
  const int vessel = m_vesselId >= 0 ? vesselSlot() : -1;
  Vec2 vesselImpulse{0, 0};
  m_contactImpulseOfSlot.resize(n);
  m_contactForceId.resize(n);
  // A block whose bodies the last updates all left still, none with a contact now, is left out
  // while the run's solo and motion events are time invariant (m_stillness): most of a pack rests
  // ahead of the vessel, and reading each resting body's state every step made this phase bound by
  // memory. Whole blocks only: bodies are in curve order, so a resting stretch of the pack is a run
  // of blocks, and a block is tested in a few loads where single bodies took a slot list.
  // The blocks to update are listed first, from a flag a block (m_blockStill) and the blocks of
  // this step's contacts, and then shared out evenly: the few blocks around the vessel hold nearly
  // all the work, and ranges of slots gave one thread most of it while the others waited.
  m_stillness.resize(static_cast<size_t>(n), kMoving);
  const int blocks = (n + kBlock - 1) / kBlock;
  m_blockStill.resize(static_cast<size_t>(blocks), 0);
  const bool skip = m_skipStillBodies && m_stillnessKnown;
  m_blockTouched.assign(static_cast<size_t>(blocks), 0);
  for (const int i : m_byBody.bodies) m_blockTouched[static_cast<size_t>(i / kBlock)] = 1;
  m_blocksToUpdate.clear();
  for (int b = 0; b < blocks; ++b)
    if (!skip || !m_blockStill[static_cast<size_t>(b)] || m_blockTouched[static_cast<size_t>(b)]) m_blocksToUpdate.push_back(b);
  const int toUpdate = static_cast<int>(m_blocksToUpdate.size());
  std::atomic<int> updated{0};
  auto updateBlock = [&](int block) {
    const int begin = block * kBlock, end = std::min(n, begin + kBlock);
    // A thread's views of its current block (kBlock bodies at most): cache-sized, made once. Read
    // through plain pointers: each use of a thread_local in this shared library is a call to find
    // it (__tls_get_addr), which the loops below made 700 times a step at 824 floes.
    thread_local std::vector<SoloBody> soloRows;
    thread_local std::vector<VelocityChange> totalRows;
    thread_local std::vector<MotionBody> motionRows;
    soloRows.resize(kBlock), totalRows.resize(kBlock), motionRows.resize(kBlock);
    SoloBody* const solo = soloRows.data();
    VelocityChange* const total = totalRows.data();
    MotionBody* const motion = motionRows.data();
    const int count = end - begin;
    updated.fetch_add(count, std::memory_order_relaxed);
    for (int q = 0; q < count; ++q) {
      const int i = begin + q;
      const BodyKind kind = m_world.kind[i];
      solo[q] = SoloBody{kind,
                         degreesOfFreedom(kind, vesselDof),
                         m_world.position(i),
                         m_world.angle[i],
                         m_world.velocity(i),
                         m_world.omega[i],
                         m_world.mass[i],
                         m_world.area[i],
                         m_world.thickness[i]};
      total[q] = VelocityChange{{0, 0}, 0};
    }
    const SoloPhaseData soloData{solo, total, count, ctx};
    for (auto& e : m_events)
      if (e.phase == EventPhase::Solo) e.instance->runSolo(soloData);
    for (int q = 0; q < count; ++q) {
      const int i = begin + q;
      const int own = m_byBody.has(i) ? m_byBody.count[static_cast<size_t>(i)] : 0;
      if (own) {  // most bodies have no contact
        Vec2 onBody{0, 0};
        const int* entry = &m_byBody.entries[static_cast<size_t>(m_byBody.start[static_cast<size_t>(i)])];
        for (int c = 0; c < own; ++c) {
          const int k = entry[c] / 2, side = entry[c] % 2;
          const Vec2 j = m_slots[k].impulse;
          if (j.x == 0 && j.y == 0) continue;
          const Vec2 ji = side == 0 ? -j : j;
          onBody += ji;
          addContactImpulse(m_pairBodies[i], ji, m_contacts[k].geometry.point, total[q]);
        }
        if (i == vessel) vesselImpulse = onBody;
        // Kept for contactForces() by the slot the body has now (a break or a re-sort after the
        // gather moves bodies between slots), for the bodies of a contact only: m_byBody lists them.
        m_contactImpulseOfSlot[i] = onBody;
        m_contactForceId[i] = m_world.id[i];
      }
      motion[q] = MotionBody{
          solo[q].kind, solo[q].dof, solo[q].position, solo[q].angle, solo[q].velocity + total[q].dv, solo[q].omega + total[q].domega};
    }
    const MotionPhaseData motionData{motion, count, ctx};
    for (auto& e : m_events)
      if (e.phase == EventPhase::Motion) e.instance->runMotion(motionData);
    // The write-back, only where a bit changed: most floes of a pack rest, and storing their
    // unchanged state dirtied six cache lines per eight bodies, each written back to memory, in a
    // phase bound by memory on many threads. Compared as bits, so that -0 over +0 is stored, and
    // a body none of whose bits changed is still. One test a body, not one a value: a moving body
    // changes nearly all six, a resting one none.
    using Bits = std::conditional_t<sizeof(Real) == 8, std::uint64_t, std::uint32_t>;
    auto differ = [](Real a, Real b) { return std::bit_cast<Bits>(a) ^ std::bit_cast<Bits>(b); };
    for (int q = 0; q < count; ++q) {
      const int i = begin + q;
      const MotionBody& b = motion[q];
      const Bits changed = differ(m_world.x[i], b.position.x) | differ(m_world.y[i], b.position.y) | differ(m_world.angle[i], b.angle) |
                           differ(m_world.vx[i], b.velocity.x) | differ(m_world.vy[i], b.velocity.y) | differ(m_world.omega[i], b.omega);
      if (changed) {
        m_world.x[i] = b.position.x, m_world.y[i] = b.position.y, m_world.angle[i] = b.angle;
        m_world.vx[i] = b.velocity.x, m_world.vy[i] = b.velocity.y, m_world.omega[i] = b.omega;
      }
      // A body whose bits stay is still, and kStill (inactive in the next narrowphase) without a
      // contact, unless its pose differs from the one its vertices were made for: a NaN pose, which
      // equals nothing, is then taken for moving, as the narrowphase takes it.
      const bool inContact = m_byBody.has(i);
      const bool moved = refreshPose(i, inContact, false);
      const char now = changed || moved ? kMoving : inContact ? kStillInContact : kStill;
      char& flag = m_stillness[static_cast<size_t>(i)];
      if (flag != now) flag = now;
    }
    noteBlockStill(block);
  };
  // A block to update is a few microseconds of work (256 bodies' events, gather and write-back),
  // more than a round on the pool costs: two of them are worth sharing.
  const int tasks = m_pool && toUpdate >= 2 ? std::min(toUpdate, kTasksPerThread * m_pool->size()) : 1;
  auto updateShare = [&](int t) {
    for (int q = toUpdate * t / tasks; q < toUpdate * (t + 1) / tasks; ++q) updateBlock(m_blocksToUpdate[static_cast<size_t>(q)]);
  };
  if (tasks > 1)
    m_pool->run(tasks, updateShare);
  else
    updateShare(0);
  m_stillnessKnown = true;
  m_updatedBodies = updated.load(std::memory_order_relaxed);
  m_vesselIceForce = forceOfImpulse(vesselImpulse, m_scenario.dt);
  m_contactForcesBuilt = false;
}

}  // namespace gem
