// Runs a scenario to its end and writes every output of SCENARIO.md into the run folder (the
// observers, MODEL.md 8 phase 7). Files are written under temporary names and renamed, so a
// crash leaves only whole files; summary.json is written last, and only after a complete run.
#pragma once
#include <string>

#include "framework/scenario.hpp"
#include "framework/stepper.hpp"

namespace gem {

struct RunOptions {
  bool quiet = false;     // no progress line and no closing summary
  bool progress = false;  // show a progress line (set when stderr is a terminal)
};

struct Stats {
  double min = 0, mean = 0, max = 0;
  long count = 0;
};

struct RunSummary {
  long steps = 0;
  double simTime = 0, wallTime = 0;
  std::string backend, broadphase, device;
  int floesInitial = 0, floesFinal = 0;
  double iceMassInitial = 0, iceMassFinal = 0, rubbleMass = 0;
  long impacts = 0, floesBroken = 0;
  Stats shipSpeed, impactForce, netThrust;
  // Over the steady part of the transit: the whole hull within the domain's x range.
  Stats shipSpeedInIce, netThrustInIce;
  std::string outputDir;
};

RunSummary runScenario(const Scenario& scenario, const RunOptions& options);

std::string summaryJson(const RunSummary& s);

}  // namespace gem
