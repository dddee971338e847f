// gem calibrate: the impact algorithm check of thesis 6.2.2.1. A 10 m x 10 m floe is placed in
// front of each of four starboard bow edges, corner-first or face-first, and struck at two speeds
// and two thicknesses (32 cases). The force GEM logs at contact onset is compared with a direct
// evaluation of docs/model.md 5 from the case's own inputs: the hull edge's normal, frame angle and
// midpoint, the floe's apex angle and mass properties, and the ship's speed (the thesis's
// spreadsheet). The direct evaluation is written out here on its own, not through ShipImpact.
#pragma once
#include <string>
#include <vector>

#include "events/ship_impact.hpp"
#include "framework/api/event_api.hpp"
#include "framework/scenario/scenario.hpp"

namespace gem {

struct CalibrationCase {
  std::string name;
  int edge;        // hull edge index (body frame, the hull's own order)
  bool corner;     // corner-first (apex 90 deg) or face-first (face parallel to the hull edge)
  Real speed;      // m/s
  Real thickness;  // m
};

struct CalibrationResult {
  CalibrationCase input;
  bool logged = false;    // an impact was logged
  ImpactRecord record{};  // what GEM logged
  Real directForce = 0;   // min(F_n, F_lim) evaluated directly, N
  Real directLimit = 0;   // F_lim evaluated directly, N
  Real apexDeg = 0, frameAngleDeg = 0;
};

std::vector<CalibrationCase> calibrationCases(const Scenario& base);
CalibrationResult runCalibrationCase(const Scenario& base, const CalibrationCase& c);
// Runs every case, prints the table, writes DIR/calibration.csv; returns the largest |relative
// difference| between the logged and the direct force.
double runCalibration(const std::string& scenarioFile, const std::string& outDir, bool quiet);

}  // namespace gem
