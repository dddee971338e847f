// One registry of events and broadphases by name: built-ins register themselves at load time
// with the macros below; plugins use the very same macros (docs/architecture.md "Plugins", plugin_api.hpp).
#pragma once
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "framework/api/broadphase.hpp"
#include "framework/api/event_api.hpp"
#include "framework/api/step_records.hpp"
#if defined(GEM_BUILDING_PLUGIN)
#include "framework/api/plugin_api.hpp"
#endif

namespace gem {

class TableReader;
struct Scenario;
struct World;

enum class EventPhase { Pair, Solo, Motion, Topology };
const char* eventPhaseName(EventPhase phase);

// What the scheduler hands a pair event each step: every body's view (by slot) and the contacts.
struct PairPhaseData {
  const PairBody* bodies;
  const int* contactA;  // slot of body a of contact k
  const int* contactB;
  const PairContact* contacts;
  PairSlot* slots;
  int count;
  StepContext ctx;
  RecordSink sink;
  int event;  // the event's place among the phase's events: stamped on its records (RecordTag)
};

struct SoloPhaseData {
  const SoloBody* bodies;
  VelocityChange* changes;
  int count;
  StepContext ctx;
};

struct MotionPhaseData {
  MotionBody* bodies;
  int count;
  StepContext ctx;
};

// Topology events run on the host after motion (docs/model.md 8, phase 6), in a step whose records
// call for them. The contract, which lets the CUDA backend keep its world on the device: an event
// declares the streams whose rows call for it (streamsRead) and the bodies a step's rows name
// (bodiesRead), reads the state of those bodies only (the CUDA backend fetches just those rows),
// and changes the bodies only through World::removeBodies and World::addBody (the device then
// replays the edit).
struct TopologyData {
  struct World* world;
  const StepRecords* records;  // the step's rows, in the CPU's order
  Real time;
  // Outputs: what the event did, for the summary and the broadphase.
  double rubbleMass = 0;  // kg removed as rubble this step
  int floesBroken = 0;
  bool changed = false;  // bodies were added or removed
};

class EventInstance {
 public:
  virtual ~EventInstance() = default;
  virtual void runPairs(const PairPhaseData&) {}
  virtual void runSolo(const SoloPhaseData&) {}
  virtual void runMotion(const MotionPhaseData&) {}
  virtual void runTopology(TopologyData&) {}
  // Topology events: the streams whose rows call for the phase, and the bodies a step's rows name.
  virtual std::vector<int> streamsRead() const { return {}; }
  virtual std::vector<std::int64_t> bodiesRead(const StepRecords&) const { return {}; }
  // The parsed Params, so that a device driver of the same event is made from the very same values.
  virtual const void* params() const = 0;
  // Solo and motion events: whether the event declares itself time invariant (eventIsTimeInvariant).
  virtual bool timeInvariant() const { return false; }
};

// What an event's factory gets: its parameter table (strict) and the whole scenario
// (propulsion and autopilot read the vessel from it).
struct EventConfig {
  TableReader& params;
  const Scenario& scenario;
  RecordStreams& records;  // the run's record streams: open the ones the event writes or reads
  // Whether the run uses the event. Every registered event is parsed, off or on, so that a table
  // given for it is checked either way; an event with a parameter that has no default should
  // require it only when enabled (a disabled event's instance is dropped).
  bool enabled = true;
};

struct EventEntry {
  std::string name, description, origin;
  EventPhase phase;
  bool enabledByDefault;
  std::function<std::unique_ptr<EventInstance>(EventConfig&)> makeCpu;
  int order = event_order::kDefault;  // within the phase: lower first, ties by name
};

// The order an event declares (static constexpr int kOrder), else event_order::kDefault.
template <class Event>
constexpr int eventOrderOf() {
  if constexpr (requires { Event::kOrder; })
    return Event::kOrder;
  else
    return event_order::kDefault;
}

// Whether a solo or motion event declares `static constexpr bool kTimeInvariant = true`: its apply
// reads neither ctx.time nor ctx.step and keeps no state of its own, so a body in the same state
// gets the same change at every step. While every such event of the run declares it, the CPU
// stepper leaves out a block of 256 bodies whose last update left each exactly as it was and none of
// which touches anything (docs/plugins.md "Time-invariant solo and motion events"). Undeclared is
// the safe default: every body every step.
template <class Event>
constexpr bool eventIsTimeInvariant() {
  if constexpr (requires { Event::kTimeInvariant; })
    return Event::kTimeInvariant;
  else
    return false;
}

struct BroadphaseEntry {
  std::string name, description, origin;
  std::function<std::unique_ptr<Broadphase>(const BroadphaseSettings&)> make;
  std::vector<std::string> settings;  // the keys of BroadphaseSettings it reads (its kSettings)
};

// A file of the run folder written from a record stream, one CSV row per record, registered by the
// event that owns the record type (ship_impact: impacts.csv). countKey and statisticKey, when not
// empty, add to summary.json the number of rows and the statistics of statisticValue over them.
struct RecordOutputEntry {
  std::string stream;                                      // the stream's name
  std::string file;                                        // in the run folder
  std::string header;                                      // the CSV header line, without its newline
  void (*writeRow)(const void* record, std::string& row);  // the row, with its newline
  std::string countKey, statisticKey;
  double (*statisticValue)(const void* record);
  // When not empty: the same count and statistics over the vessel's transit of the field only (the
  // steps with the whole hull inside the domain's x range, as ship_speed_in_ice; ship_impact:
  // "impacts_in_ice", "impact_force_in_ice_n").
  std::string countInIceKey = {}, statisticInIceKey = {};
};

// What GEM writes itself, which no plugin's record output may take: file names of a run folder
// (besides the record streams' files) and the keys of summary.json (besides the record totals).
// runner.cpp's summaryJson writes exactly these keys (a test keeps the two equal).
inline constexpr const char* kGemRunFiles[] = {"summary.json", "state.csv",      "timeseries.csv", "frames.pvd",   "frames.ice",
                                               "frames",       "gem.log",        "scenario.toml",  "gem-run.toml", "plots",
                                               "movie.mp4",    "checkpoint.gem", ".gem-run.lock",  "case.toml",    "summary.csv"};
inline constexpr const char* kGemSummaryKeys[] = {"gem_version",
                                                  "completed",
                                                  "stop_reason",
                                                  "steps",
                                                  "sim_time_s",
                                                  "wall_time_s",
                                                  "real_time_factor",
                                                  "backend",
                                                  "driver",
                                                  "broadphase",
                                                  "device",
                                                  "floes_initial",
                                                  "floes_final",
                                                  "floes_broken",
                                                  "ice_mass_initial_kg",
                                                  "ice_mass_final_kg",
                                                  "rubble_mass_kg",
                                                  "cases_on_device",
                                                  "ship_speed",
                                                  "net_thrust_n",
                                                  "resistance_mean_n",
                                                  "ship_speed_in_ice",
                                                  "resistance_in_ice_n"};

class Registry {
 public:
  static Registry& global();
  void addEvent(EventEntry entry);
  void addBroadphase(BroadphaseEntry entry);
  // Throw InputError listing the valid names when `name` is unknown.
  const EventEntry& event(const std::string& name) const;
  const BroadphaseEntry& broadphase(const std::string& name) const;
  const EventEntry* findEvent(const std::string& name) const;
  // By phase (pair, solo, motion, topology), then each event's declared order, then name: the
  // order in which every driver runs them.
  std::vector<const EventEntry*> events() const;
  // The run folder's writers of record streams (impacts.csv), in registration order. A built-in
  // entry for a file already written replaces its writer. A plugin's entry is staged and checked at
  // commitPlugin: its file a plain name that is not one of GEM's own (kGemRunFiles) nor another
  // entry's (unless the plugin may override, which replaces that entry), its summary keys none of
  // GEM's (kGemSummaryKeys) nor another entry's.
  void addRecordOutput(RecordOutputEntry entry);
  std::vector<const RecordOutputEntry*> recordOutputs() const;
  std::vector<const BroadphaseEntry*> broadphases() const;
  std::vector<std::string> eventNames() const;
  std::vector<std::string> broadphaseNames() const;

  // The plugin loader's side (framework/app/plugin_loader.cpp). Between beginPlugin and commitPlugin,
  // added entries are held back and stamped with the plugin's origin; commitPlugin then enters
  // them all, or none when a name clashes (InputError naming both origins) and the plugin may not
  // override. abortPlugin drops them.
  void beginPlugin(const std::string& origin, bool allowOverride);
  void commitPlugin();
  void abortPlugin();
  // The origin of the plugin registering now (between beginPlugin and commit/abort), else
  // "built-in". A plugin's CUDA drivers are keyed by it (framework/api/cuda_events.hpp).
  std::string pluginOrigin() const;

 private:
  std::map<std::string, EventEntry> m_events;
  std::map<std::string, BroadphaseEntry> m_broadphases;
  std::vector<RecordOutputEntry> m_recordOutputs;
  std::vector<std::string> m_recordOutputOrigins;  // beside m_recordOutputs: "built-in" or the plugin's
  struct Staging {
    std::string origin;
    bool allowOverride = false;
    std::vector<EventEntry> events;
    std::vector<BroadphaseEntry> broadphases;
    std::vector<RecordOutputEntry> recordOutputs;
  };
  void checkRecordOutputs(const Staging& staging) const;
  void enterRecordOutput(RecordOutputEntry entry, const std::string& origin);
  std::unique_ptr<Staging> m_staging;  // non-null while a plugin registers
};

// The CPU drivers: the only loops over bodies and contacts (docs/architecture.md "Rooms").
template <class Event>
class CpuPairDriver final : public EventInstance {
 public:
  using Params = typename Event::Params;
  static_assert(std::is_trivially_copyable_v<Params>,
                "an event's Params must be trivially copyable: it is copied to the GPU as a kernel argument");
  explicit CpuPairDriver(const Params& p) : m_params(p) {}
  void runPairs(const PairPhaseData& d) override {
    for (int k = 0; k < d.count; ++k)
      Event::apply(m_params, d.bodies[d.contactA[k]], d.bodies[d.contactB[k]], d.contacts[k], d.slots[k], d.ctx, d.sink.at(d.event, k, 0));
  }
  const void* params() const override { return &m_params; }

 private:
  Params m_params;
};

template <class Event>
class CpuSoloDriver final : public EventInstance {
 public:
  using Params = typename Event::Params;
  static_assert(std::is_trivially_copyable_v<Params>,
                "an event's Params must be trivially copyable: it is copied to the GPU as a kernel argument");
  explicit CpuSoloDriver(const Params& p) : m_params(p) {}
  void runSolo(const SoloPhaseData& d) override {
    for (int i = 0; i < d.count; ++i) Event::apply(m_params, d.bodies[i], d.changes[i], d.ctx);
  }
  const void* params() const override { return &m_params; }
  bool timeInvariant() const override { return eventIsTimeInvariant<Event>(); }

 private:
  Params m_params;
};

template <class Event>
class CpuMotionDriver final : public EventInstance {
 public:
  using Params = typename Event::Params;
  static_assert(std::is_trivially_copyable_v<Params>,
                "an event's Params must be trivially copyable: it is copied to the GPU as a kernel argument");
  explicit CpuMotionDriver(const Params& p) : m_params(p) {}
  void runMotion(const MotionPhaseData& d) override {
    for (int i = 0; i < d.count; ++i) Event::apply(m_params, d.bodies[i], d.ctx);
  }
  const void* params() const override { return &m_params; }
  bool timeInvariant() const override { return eventIsTimeInvariant<Event>(); }

 private:
  Params m_params;
};

// Topology events work on the host World directly.
template <class Event>
class TopologyDriver final : public EventInstance {
 public:
  using Params = typename Event::Params;
  explicit TopologyDriver(const Params& p) : m_params(p) {}
  void runTopology(TopologyData& d) override { Event::apply(m_params, d); }
  std::vector<int> streamsRead() const override {
    if constexpr (requires { Event::streamsRead(m_params); })
      return Event::streamsRead(m_params);
    else
      return {};
  }
  std::vector<std::int64_t> bodiesRead(const StepRecords& records) const override {
    if constexpr (requires { Event::bodiesRead(m_params, records); })
      return Event::bodiesRead(m_params, records);
    else
      return {};
  }
  const void* params() const override { return &m_params; }

 private:
  Params m_params;
};

// Plugin libraries: a scenario names them ([[plugins]]) and GEM_PLUGIN_PATH lists folders of them.
// The scenario parser only asks for them here, before it checks event and broadphase names; the
// application's plugin loader (framework/app/plugin_loader.cpp, Boost.DLL) installs itself as the
// one that loads them, so parsing never reaches up to the code that opens libraries.
struct PluginLibraryLoader {
  void (*load)(const std::filesystem::path& path, bool allowOverride);  // throws InputError
  void (*loadEnvironment)();                                            // GEM_PLUGIN_PATH, once
};
void setPluginLibraryLoader(PluginLibraryLoader loader);
// Both throw InputError when no loader is installed (a program without the plugin loader).
void requirePluginLibrary(const std::filesystem::path& path, bool allowOverride);
void requireEnvironmentPluginLibraries();

// A built-in's registration, run when GEM's library loads.
struct RegisterNow {
  explicit RegisterNow(void (*add)(Registry&)) { add(Registry::global()); }
};

#ifndef GEM_ORIGIN
#define GEM_ORIGIN "built-in"
#endif

#define GEM_CONCAT_INNER(a, b) a##b
#define GEM_CONCAT(a, b) GEM_CONCAT_INNER(a, b)

// One macro body for built-ins and plugins: ADD is a statement using `registry`. A built-in runs
// it when GEM's library loads; a plugin (GEM_BUILDING_PLUGIN defined) only links it into its own
// list, which the loader runs through gem_plugin_register once the descriptor has been accepted
// (plugin_api.hpp).
#if defined(GEM_BUILDING_PLUGIN)
#define GEM_REGISTRATION(KIND, ADD)                                                                      \
  static void GEM_CONCAT(GEM_CONCAT(gem_register_, KIND), __LINE__)(::gem::Registry & registry) { ADD; } \
  static ::gem::PluginRegistrationNode GEM_CONCAT(GEM_CONCAT(gem_registration_, KIND), __LINE__) {       \
    &GEM_CONCAT(GEM_CONCAT(gem_register_, KIND), __LINE__)                                               \
  }
#else
#define GEM_REGISTRATION(KIND, ADD)                                                                      \
  static void GEM_CONCAT(GEM_CONCAT(gem_register_, KIND), __LINE__)(::gem::Registry & registry) { ADD; } \
  static const ::gem::RegisterNow GEM_CONCAT(GEM_CONCAT(gem_registration_, KIND), __LINE__) {            \
    &GEM_CONCAT(GEM_CONCAT(gem_register_, KIND), __LINE__)                                               \
  }
#endif

// Registers an event: EVENT is the evaluator struct, PARSE a function EventConfig& -> EVENT::Params.
#define GEM_REGISTER_EVENT(DRIVER, PHASE, EVENT, NAME, DESCRIPTION, ENABLED, PARSE)                                                      \
  GEM_REGISTRATION(event_, registry.addEvent(::gem::EventEntry{NAME, DESCRIPTION, GEM_ORIGIN, PHASE, ENABLED,                            \
                                                               [](::gem::EventConfig& config) -> std::unique_ptr<::gem::EventInstance> { \
                                                                 return std::make_unique<DRIVER<EVENT>>(PARSE(config));                  \
                                                               },                                                                        \
                                                               ::gem::eventOrderOf<EVENT>()}))
#define GEM_REGISTER_PAIR_EVENT(EVENT, NAME, DESCRIPTION, ENABLED, PARSE) \
  GEM_REGISTER_EVENT(::gem::CpuPairDriver, ::gem::EventPhase::Pair, EVENT, NAME, DESCRIPTION, ENABLED, PARSE)
#define GEM_REGISTER_SOLO_EVENT(EVENT, NAME, DESCRIPTION, ENABLED, PARSE) \
  GEM_REGISTER_EVENT(::gem::CpuSoloDriver, ::gem::EventPhase::Solo, EVENT, NAME, DESCRIPTION, ENABLED, PARSE)
#define GEM_REGISTER_MOTION_EVENT(EVENT, NAME, DESCRIPTION, ENABLED, PARSE) \
  GEM_REGISTER_EVENT(::gem::CpuMotionDriver, ::gem::EventPhase::Motion, EVENT, NAME, DESCRIPTION, ENABLED, PARSE)
#define GEM_REGISTER_TOPOLOGY_EVENT(EVENT, NAME, DESCRIPTION, ENABLED, PARSE) \
  GEM_REGISTER_EVENT(::gem::TopologyDriver, ::gem::EventPhase::Topology, EVENT, NAME, DESCRIPTION, ENABLED, PARSE)

// Registers the writer of a record stream to a file of the run folder (RecordOutputEntry).
#define GEM_REGISTER_RECORD_OUTPUT(STREAM, FILE, HEADER, WRITE_ROW, COUNT_KEY, STATISTIC_KEY, STATISTIC_VALUE)                   \
  GEM_REGISTRATION(record_output_, registry.addRecordOutput(::gem::RecordOutputEntry{STREAM, FILE, HEADER, WRITE_ROW, COUNT_KEY, \
                                                                                     STATISTIC_KEY, STATISTIC_VALUE}))

// The same, with the keys of the in-ice totals (RecordOutputEntry::countInIceKey).
#define GEM_REGISTER_RECORD_OUTPUT_IN_ICE(STREAM, FILE, HEADER, WRITE_ROW, COUNT_KEY, STATISTIC_KEY, STATISTIC_VALUE, COUNT_IN_ICE_KEY, \
                                          STATISTIC_IN_ICE_KEY)                                                                         \
  GEM_REGISTRATION(record_output_,                                                                                                      \
                   registry.addRecordOutput(::gem::RecordOutputEntry{STREAM, FILE, HEADER, WRITE_ROW, COUNT_KEY, STATISTIC_KEY,         \
                                                                     STATISTIC_VALUE, COUNT_IN_ICE_KEY, STATISTIC_IN_ICE_KEY}))

// Registers a broadphase class constructible from BroadphaseSettings; its kSettings, if any, name
// the settings it reads.
#define GEM_REGISTER_BROADPHASE(CLASS, NAME, DESCRIPTION)                                                                      \
  GEM_REGISTRATION(                                                                                                            \
      broadphase_,                                                                                                             \
      registry.addBroadphase(::gem::BroadphaseEntry{                                                                           \
          NAME, DESCRIPTION, GEM_ORIGIN,                                                                                       \
          [](const ::gem::BroadphaseSettings& s) -> std::unique_ptr<::gem::Broadphase> { return std::make_unique<CLASS>(s); }, \
          ::gem::declaredBroadphaseSettings<CLASS>()}))

}  // namespace gem
