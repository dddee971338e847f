// A scenario: everything one run needs, read from a TOML file (docs/scenario.md) with --set overrides.
// Loading validates every key, type and range; errors are InputError with file:line:column.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "framework/api/broadphase.hpp"
#include "framework/field/field_generator.hpp"
#include "framework/world/vessel.hpp"
#include "framework/world/world.hpp"

namespace gem {

struct OutputSpec {
  std::filesystem::path dir;  // absolute
  int frameEvery = 10;        // steps between frames; 0 = no frames
  int timeseriesEvery = 1;    // steps between time-series rows
  std::vector<std::string> formats{"vtk", "ice"};
  bool vtkBinary = false;  // output.vtk_encoding = "binary": zlib-compressed appended arrays
  // output.checkpoint_every (docs/reliability.md "Checkpoints and resume"): a checkpoint every so
  // many steps, or every so many wall-clock seconds; both 0: none but the one a signal writes.
  long checkpointEverySteps = 0;
  double checkpointEverySeconds = 0;
};

struct PluginSpec {
  std::filesystem::path path;
  bool override = false;
};

struct Scenario {
  std::filesystem::path file;  // the scenario file (absolute)
  std::string fileName;        // as given, for messages
  toml::table root;            // the parsed document, overrides applied (a copy: no source lines)
  // The same document as read, with its source lines and columns (toml++ drops them when a table
  // is copied), shared by every copy of this Scenario: eventTable() reads it.
  std::shared_ptr<const toml::table> document;
  // The keys the scenario left out, with the defaults they took: its tables' when it is loaded,
  // the events' parameters' when a stepper parses them (DefaultsRecorder); written into the run's
  // scenario.toml; shared by every copy of this Scenario.
  std::shared_ptr<toml::table> defaultsTaken = std::make_shared<toml::table>();
  std::vector<std::string> overrides;  // the --set (and sweep) overrides, "key=VALUE", as applied

  // [simulation]
  Real dt = Real(0.1);
  Real duration = 600;
  long steps = 0;  // total steps (from duration / dt, or simulation.steps)
  std::string backend = "auto";
  std::string broadphase = "variable_radius";
  BroadphaseSettings broadphaseSettings;
  std::uint64_t seed = 1;
  bool mortonSort = true;  // re-sort bodies along a space-filling curve at each list rebuild
  // CUDA backend only (thesis 5.7): steps run on the device between two copies of results to the
  // host (frames, re-sorts, breaks and the run's end still come exactly on time), and the threads
  // per block of the per-body and per-contact kernels.
  int copyBackEvery = 16;
  int cudaBlockSize = 128;
  // The CUDA driver (docs/performance.md "CUDA drivers"): "resident" runs each world's whole step
  // in one thread block, "device" each phase as kernels over the whole field, "auto" picks by size.
  std::string cudaDriver = "auto";
  // CPU backend: threads stepping one field (0: every core; a sweep running cases in parallel
  // gives each case 1). Results are bit for bit those of one thread.
  int threads = 0;
  // When a run stops before its last step (docs/scenario.md "Stop rules"): "duration" runs every
  // step; "vessel_left_field" stops once the vessel, having reached the field, is clear of it again;
  // "distance" once the vessel has travelled stop_distance metres (its path, not its displacement).
  std::string stopWhen = "duration";
  Real stopDistance = 0;  // m, stop_when = "distance" only

  // [domain]
  bool hasDomain = false;
  Domain domain{0, 500, -100, 100};
  bool walls = false;
  Real wallThickness = 5;  // m: the wall polygons' width outside the domain

  // [field] and [[floes]]
  std::string fieldKind = "none";  // none | random_convex | hexagons | file
  RandomFieldSpec randomField;
  HexagonFieldSpec hexagonField;
  std::filesystem::path fieldFile;
  std::vector<BodySpec> floes;  // explicit [[floes]]

  VesselSpec vessel;

  // [events.NAME] given in the scenario: its enabled flag. Its table is looked up in document by
  // eventTable(), never stored as a pointer, so a copied Scenario stays self-contained.
  struct EventSetting {
    bool enabled;
  };
  std::map<std::string, EventSetting> events;

  std::vector<PluginSpec> plugins;
  OutputSpec output;

  // The [events.NAME] table of this scenario's root, or null when absent.
  const toml::table* eventTable(const std::string& name) const;
};

// Reads and validates a scenario. overrides are "dotted.key=VALUE" (VALUE in TOML syntax; a bare
// word is taken as a string). outDir, when not empty, replaces output.dir.
Scenario loadScenario(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

// Refuses a generated field (random_convex, hexagons) that could not fit in this machine's memory,
// with the estimate (loadScenario calls it).
void checkFieldMemory(const Scenario& s);
// The memory a run of `floes` floes needs, bytes: about 3 KB a floe (its polygon and state, and the
// step's per-body and per-contact buffers); against machineMemory() (framework/api/input_size.hpp).
double fieldMemoryNeed(double floes);

// The thesis's open-water speed for a bollard thrust (interpolated in log-log), m/s.
Real openWaterSpeedFor(Real bollardThrust);

}  // namespace gem
