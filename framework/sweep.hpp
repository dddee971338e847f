// gem sweep: a parameter study (issue 5). A sweep file names a base scenario and the parameters to
// vary; each case gets its own folder with its full scenario and outputs, cases run in parallel,
// finished cases are skipped when run again, and one summary.csv gathers them.
#pragma once
#include <string>

namespace gem {

struct SweepOptions {
  std::string sweepFile;
  std::string outDir;      // default: beside the sweep file, "runs/<sweep name>"
  int jobs = 0;            // parallel cases; 0 = the number of cores
  long caseIndex = -1;     // run only this case (job arrays); -1 = all
  bool quiet = false;
};

// Returns the exit status (0 all cases done; throws InputError for a bad sweep file).
int runSweep(const SweepOptions& options);

}  // namespace gem
