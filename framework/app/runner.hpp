// Runs a scenario to its end and writes every output of docs/scenario.md into the run folder (the
// observers, docs/model.md 8 phase 7). Files are written under temporary names and renamed, so a
// crash leaves only whole files; summary.json is written last, and only after a complete run.
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "framework/scenario/scenario.hpp"
#include "framework/step/stepper.hpp"

namespace gem {

struct RunOptions {
  bool quiet = false;     // no progress line and no closing summary
  bool progress = false;  // show a progress line (set when stderr is a terminal)
  // Called once, when everything is checked (the events' tables, the world, the run folder) and the
  // run is about to take its first step: gem run announces the run here, so that bad input is
  // refused before any line of a run that never starts. It gets the stepper, whose backend is the
  // one that runs (auto may have fallen back to the cpu).
  std::function<void(Stepper&)> started;
  // A sweep's case (false): a stopped sweep runs its incomplete cases again from their start, so
  // the case writes no checkpoint.gem, neither every output.checkpoint_every nor at Ctrl-C (one was
  // left in its folder until the case ran again whole).
  bool checkpoints = true;
};

struct Stats {
  double min = 0, mean = 0, max = 0;
  long count = 0;
};

// A record stream's totals for summary.json, under the keys its output declares (ship_impact:
// "impacts", "impact_force_n").
struct RecordTotals {
  std::string countKey, statisticKey;
  long count = 0;
  Stats statistic;
  // Over the transit only (the in-ice window of shipSpeedInIce), under these keys when not empty.
  std::string countInIceKey, statisticInIceKey;
  long countInIce = 0;
  Stats statisticInIce;
};

struct RunSummary {
  long steps = 0;  // the steps run: fewer than the scenario's when a stop rule or a signal ended it
  // false when a signal (Ctrl-C, SIGTERM) stopped the run: its files are whole but it is not the
  // scenario's run (a sweep runs such a case again).
  bool completed = true;
  // Why the run ended: "duration" (every step), "vessel_left_field", "distance", "SIGINT", "SIGTERM".
  std::string stopReason = "duration";
  double simTime = 0, wallTime = 0;
  std::string backend, driver, broadphase, device;
  int floesInitial = 0, floesFinal = 0;
  double iceMassInitial = 0, iceMassFinal = 0, rubbleMass = 0;
  long floesBroken = 0;
  Stats shipSpeed, netThrust;
  std::vector<RecordTotals> records;  // per record stream written to the run folder (impacts.csv)
  // Over the steady part of the transit: the whole hull within the domain's x range.
  Stats shipSpeedInIce, netThrustInIce;
  std::string outputDir;
  int casesOnDevice = 1;  // > 1: run together with other cases in one device state (wallTime is theirs together)
};

RunSummary runScenario(const Scenario& scenario, const RunOptions& options);

// gem run --resume (docs/reliability.md "Checkpoints and resume"): the run of scenario (read from
// the run folder's scenario.toml, output.dir that folder) goes on from the folder's checkpoint, on
// the backend that wrote it, and ends with the files the run would have written uninterrupted.
// InputError (exit 2) when there is no checkpoint, it is damaged or foreign, scenario.toml changed
// since it was written, or its backend is not here.
RunSummary resumeScenario(Scenario scenario, const RunOptions& options);

// Scenarios whose steppers share one device state (a sweep's batch on a GPU, made by the backend's
// makeTogether): stepped together, every one's step k before any one's step k + 1, each writing its
// own outputs exactly as runScenario does (wall_time_s is the batch's). They must have the same
// number of steps. Returns, per scenario, "" when it completed, else why it failed; a failure of
// the shared stepping fails every case still running, and each keeps what it wrote.
// progress(step, steps), when given, is called after each step.
std::vector<std::string> runScenariosTogether(const std::vector<const Scenario*>& scenarios, std::vector<std::unique_ptr<Stepper>> steppers,
                                              const std::function<void(long step, long steps)>& progress = {});

std::string summaryJson(const RunSummary& s);

// gem check's work on a loaded scenario (docs/reliability.md "What gem check promises"), for a
// scenario file and for each case of a sweep file: its backend found, its world built (every body,
// no overlap), every event table parsed, and one step taken on the CPU, written nowhere, that
// leaves every body's state finite. Throws InputError where gem run would fail, a first step that
// is not finite with gem run's words ("FILE: step 1 ...; gem run stops there").
struct ScenarioCheck {
  int bodies = 0, floes = 0;
  size_t events = 0;  // enabled
};
ScenarioCheck checkScenarioFirstStep(const Scenario& scenario);

}  // namespace gem
