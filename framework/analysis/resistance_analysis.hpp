// The resistance study's analysis (thesis 6.2.1.3, Figures 6.26 and 6.27): from a sweep's
// summary.csv whose cases are "FIELD,bollard_thrust=T", the mean resistance and speed in ice of
// each run, a power-law fit R = a V^b per field, and the plots of resistance against speed and
// against concentration. gem analyze calls it on every sweep folder that has such cases.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

struct ResistancePoint {
  std::string field;     // the case's field name, e.g. "random_35"
  double concentration;  // from the field name's trailing number, as a fraction
  double thrust;         // N
  double speed;          // mean ship speed in ice, m/s
  double resistance;     // mean net thrust in ice, N
};

// Reads DIR/summary.csv; empty when it is not a resistance sweep (no such columns or case names).
std::vector<ResistancePoint> readResistancePoints(const std::filesystem::path& sweepDir);

// Writes DIR/analysis/resistance.csv, resistance_fits.csv, resistance_vs_speed.svg and
// resistance_vs_concentration.svg. Returns false (writing nothing) when there are no points.
bool analyzeResistance(const std::filesystem::path& sweepDir, bool quiet);

}  // namespace gem
