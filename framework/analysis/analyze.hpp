// gem analyze: impact-load statistics of a run folder or a sweep folder (issue 5, item 5; thesis
// 6.2.2.4 to 6.2.2.6). Writes CSV tables and SVG plots into DIR/analysis/:
//   statistics.csv   one row per group of runs: impacts, mean/max force, Weibull fit of fn (Figure
//                    6.38), lognormal fit of the masses of the floes struck (Figure 6.32), Weibull
//                    fit of apex angles (Figure 6.31), power laws fn = a x^b against distance from
//                    the stem, closing speed vn and ship speed (Figures 6.35, 6.36)
//   across_bow.csv   impacts per metre of breadth per run, in 1 m bins of y_from_centerline (the
//                    shadowing of Figure 6.34)
//   force_cdf.svg, floe_mass_hist.svg, apex_hist.svg, across_bow.svg,
//   force_vs_stem_distance.svg, force_vs_speed.svg, force_vs_ship_speed.svg (when timeseries.csv
//   gives the ship speed)
#pragma once
#include <string>
#include <vector>

namespace gem {

struct AnalyzeOptions {
  std::string dir;  // a run folder (impacts.csv) or a sweep folder (cases/*/impacts.csv)
  bool quiet = false;
  // Sweep only: the groups to analyse, each by its label ("concentration=0.4": the values of the
  // varied keys other than vessel.bollard_thrust and simulation.seed, sweep_cases.hpp) or by the
  // name of one of its cases ("121_46" for the load study's ice mix 121, thesis Figure 6.38).
  // Empty: every group. The group "all" is the union of the chosen groups.
  std::vector<std::string> groups;
};

// Returns 0. Throws InputError when DIR holds neither impacts.csv nor cases/*/impacts.csv, when an
// impacts.csv is malformed (file:line), or when a requested group has no case.
int runAnalyze(const AnalyzeOptions& options);

}  // namespace gem
