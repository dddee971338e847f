// `gem plot RUN` (docs/scenario.md "Plots and movie"): one run folder's figures at a glance, each as
// SVG and PNG in RUN/plots/: the time series (ship speed, net thrust, ice force, contacts against
// t) and, when impacts.csv has rows, the impact loads (force histogram, where along the hull the
// hull was struck and how hard, force against time).
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

struct RunPlots {
  std::vector<std::filesystem::path> files;  // written, in order
  std::vector<std::string> notes;            // what was not drawn, and why
};

// Throws InputError naming the folder when it is not a run folder (no timeseries.csv), or naming
// the file and line when a CSV is malformed.
RunPlots writeRunPlots(const std::filesystem::path& runDir);

}  // namespace gem
