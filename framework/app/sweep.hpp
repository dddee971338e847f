// gem sweep: a parameter study (issue 5). A sweep file names a base scenario and the parameters to
// vary; each case gets its own folder with its full scenario and outputs, cases run in parallel,
// finished cases are skipped when run again, and one summary.csv gathers them.
//
// The sweep file (TOML; unknown keys are errors, like a scenario's):
//
//   [sweep]
//   name = "resistance"                 # optional; default: the sweep file's stem
//   base = "random_35.toml"             # the base scenario, relative to the sweep file
//   set = { "simulation.duration" = 300.0 }   # optional: overrides for every case (not a column)
//
//   [parameters]                        # optional: lists; every combination is a case
//   "vessel.bollard_thrust" = [46e3, 92e3, 370e3]
//   "field.concentration" = [0.35, 0.5]
//
//   [[cases]]                           # optional: explicit cases
//   name = "001_46"                     # required; letters, digits and . _ - + = , @ #
//   base = "other.toml"                 # optional: this case's own base scenario
//   set = { "vessel.bollard_thrust" = 46e3, "field.groups" = [{ coverage = 0.1, thickness = 1.2 }] }
//
// Keys of [parameters] and of the set tables are dotted scenario keys, exactly those of
// `gem run --set`; a quoted "a.b" and a TOML dotted key a.b mean the same. Values keep their TOML
// type (46e3 is a float, 40 an integer); a value that is itself a table is walked into, so a leaf
// is always set on its own (to replace a whole [[...]] list, give the array).
//
// Which cases: [parameters] alone gives its product; [[cases]] alone gives the cases; both give
// every case combined with every combination (e.g. 8 fields as cases x 5 thrusts as parameters).
// The product varies the first parameter (in file order) slowest, like nested loops. Case order
// is: for each [[cases]] entry in file order, the combinations in that order. That order is the
// one of --case-index and of the rows of summary.csv. Overrides apply in the order sweep.set, the
// case's set, the parameters; a key given both by a case's set and by [parameters] is an error.
//
// Case names: an explicit case keeps its name. A combination is named "KEY=VALUE,KEY=VALUE" with
// KEY the last part of the dotted key (the full dotted key where two parameters share a last
// part) and VALUE the number in shortest form (46000, 0.35, 1e-05), a string or boolean as is; an
// array or table value gives "KEY#I", I its 0-based index in the list. Characters other than
// letters, digits and . _ - + become _. With [[cases]] too, the name is "CASE,KEY=VALUE,...".
//
// Outputs (DIR: --out, default "<sweep file folder>/runs/<name>"):
//   DIR/cases/<name>/scenario.toml  the full scenario of the case (base + overrides), runnable as
//                                   `gem run DIR/cases/<name>/scenario.toml`: output.dir = "." (the
//                                   case folder) and field.file made absolute
//   DIR/cases/<name>/...            the run's outputs (summary.json, timeseries.csv, ...)
//   DIR/summary.csv                 one row per complete case, in case order: name, one column per
//                                   varied key (the dotted key; empty where a case does not set
//                                   it), impacts, ship_speed_min, ship_speed_mean, ship_speed_max,
//                                   impact_force_min, impact_force_mean, impact_force_max (N),
//                                   resistance_mean (N: the mean net thrust), wall_time_s,
//                                   ship_speed_in_ice_mean, resistance_in_ice_mean (N: the means
//                                   while the hull is in the field); empty cells where
//                                   summary.json has null
//
// Resume: a case is complete when its folder holds summary.json (written last by a run). A complete
// case is skipped when the sweep runs again, unless its scenario.toml differs from the scenario
// the sweep now gives it (the sweep file or base changed): then its results are stale and it runs
// again. --case-index I runs case I only (job arrays) and gathers summary.csv from whatever is
// complete, so the last task to finish writes the full table (or run the sweep once more: all
// complete cases are skipped and the table is gathered).
//
// On a GPU (backend cuda, or auto with a device), cases that differ only in what their worlds hold
// (the field, the ice, the vessel's thrust: not dt, steps, outputs' frames, the events enabled or
// the broadphase, which must be uniform_grid) run together in one device state, a world each, so
// that a sweep of small cases fills the device: up to 128 per state, or --batch N; --batch 1 runs
// one case at a time. Each case's results are bit for bit those of its run alone; its summary's
// wall_time_s is the batch's and cases_on_device says how many shared it.
//
// Every case's scenario is loaded and validated before any runs, so a typo fails fast: the error
// names the sweep file's line and column of the offending key. Then every case to run is checked
// as gem check checks a scenario (its world built, so no overlap; its events parsed; one CPU step),
// about 0.3 s for the 70 cases of the thesis's load study. A case that fails while running is
// reported with its message, the others go on, and the exit status is 1.
#pragma once
#include <string>
#include <vector>

namespace gem {

struct SweepOptions {
  std::string sweepFile;
  std::string outDir;   // default: beside the sweep file, "runs/<sweep name>"
  int jobs = 0;         // parallel cases; 0 = the number of cores
  long caseIndex = -1;  // run only this case (job arrays); -1 = all
  int batch = 0;        // on a GPU, the most cases run together in one device state; 0 = automatic, 1 = none
  bool quiet = false;
  std::vector<std::string> set;  // --set KEY=VALUE: applied to every case, after the sweep's own
  std::string backend;           // --backend: simulation.backend of every case ("" = as the cases say)
};

// Returns the exit status: 0 when every case selected is complete, 1 when one failed at run time.
// Throws InputError for a bad sweep file, a bad base scenario or a varied key a scenario rejects.
int runSweep(const SweepOptions& options);

// gem check SWEEP.toml: the sweep file, then every case's scenario as runSweep loads it, then each
// case as gem check checks a scenario (its world built, its events parsed, one CPU step; nothing
// written). Uses sweepFile, set, backend and quiet; prints "FILE: ok (N cases; base BASE)" unless
// quiet. Returns 0; throws InputError naming the sweep file, the case and, where known, the line of
// the case's entry or of the override at fault.
int checkSweep(const SweepOptions& options);

}  // namespace gem
