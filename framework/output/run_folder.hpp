// A run folder that can be trusted: a run starts by removing what an earlier run of GEM left there
// (its summary, CSVs, frames, gem.log, temporaries: a re-run with frames off must not leave the old frames
// beside the new summary), and records the scenario it read, overrides applied, with its seed.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "framework/scenario/scenario.hpp"

namespace gem {

// The plots `gem plot` writes into RUN/plots/, each as NAME.svg and NAME.png (run_plots.hpp), and
// the movie `gem movie` writes by default: listed here so that a re-run removes them.
inline constexpr const char* kRunPlotNames[] = {"ship_speed",        "net_thrust",       "ice_force",           "contacts",
                                                "impact_force_hist", "impact_positions", "impact_force_vs_time"};
inline constexpr const char* kMovieFile = "movie.mp4";

// Removes GEM's own outputs of an earlier run from dir (never other files): summary.json,
// state.csv, timeseries.csv, the record streams' files (`recordFiles`), frames.pvd, frames.ice,
// frames/*.vtp (and frames/ when that leaves it empty), the plots (kRunPlotNames, and plots/ when
// that leaves it empty), movie.mp4, checkpoint.gem, and the temporaries of those files (NAME.tmp-PID,
// NAME one of them; never another name with .tmp- in it). Call it holding the
// folder's lock (RunFolderLock): no other run of GEM is writing there.
void clearEarlierRun(const std::filesystem::path& dir, const std::vector<std::string>& recordFiles);

// A resumed run (gem run --resume): removes what the stopped run wrote when it ended (summary.json,
// state.csv, the plots, the movie), which describe a run that is not over; its streaming files and
// frames stay, to be continued; and the temporaries the stopped run left (as clearEarlierRun).
void clearRunEnd(const std::filesystem::path& dir, const std::vector<std::string>& recordFiles);

// Writes dir/scenario.toml: the scenario as this run read it (every --set applied, every key of
// its tables resolved with the default it took where the file gave none, every event's table with
// whether it is on, its seed and step count, the field file and output folder by absolute path), so
// that `gem run dir/scenario.toml` repeats it and loading it gives the same scenario. Left out: a
// default hull's vertices (drawn from length and beam) and the broadphase settings not given (a
// setting written down is one a CUDA run must honour). Skipped when dir/scenario.toml is the
// scenario file itself. `morePlugins`: plugins the run had that the scenario does not list (those
// of GEM_PLUGIN_PATH), recorded as [[plugins]] entries so that the record runs without the variable.
void recordScenario(const std::filesystem::path& dir, const Scenario& scenario, const std::vector<std::filesystem::path>& morePlugins = {});

}  // namespace gem
