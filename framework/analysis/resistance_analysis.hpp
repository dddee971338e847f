// The resistance study's analysis (thesis 6.2.1.3, Figures 6.26 and 6.27): from a sweep's
// summary.csv that varies vessel.bollard_thrust and holds the in-ice means, the mean resistance and
// speed in ice of each run, a power-law fit R = a V^b per field (a group of cases, as gem analyze
// groups them: sweep_cases.hpp), and the plots of resistance against speed and against
// concentration. Thrust and concentration come from each case's scenario.toml, not its name.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

struct ResistancePoint {
  std::string field;     // the case's group label, e.g. "random_35" (its base) or "concentration=0.4"
  double concentration;  // field.concentration of its scenario.toml; NaN when it gives none
  double thrust;         // N
  double speed;          // mean ship speed in ice, m/s
  double resistance;     // mean net thrust in ice, N
};

// Reads DIR/summary.csv and the case folders; empty when it is not a resistance sweep (no such columns).
std::vector<ResistancePoint> readResistancePoints(const std::filesystem::path& sweepDir);

// Writes DIR/analysis/resistance.csv, resistance_fits.csv, resistance_vs_speed.svg and
// resistance_vs_concentration.svg. Returns false (writing nothing) when there are no points.
bool analyzeResistance(const std::filesystem::path& sweepDir, bool quiet);

}  // namespace gem
