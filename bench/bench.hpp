// gem bench: the thesis's Chapter 5 experiments as tables, printed and written as CSV, each row with
// its device. Time-per-step tables (this file's runBench):
//   step      the thesis fields (456 hexagons, 824 random floes) and 10^4..10^6 random floes at 40 %
//   fields    456 and 824, cpu and cuda, every built-in broadphase (fixed vs variable radius; uniform
//             grid, triangulation mesh and all pairs against variable radius)
//   blocks    CUDA threads per block (simulation.cuda_block_size) on 3584 and 7168 random floes
//   copyback  CUDA steps between copies to the host (simulation.copy_back_every) on 824 and 10^5
//   scaling   10^4, 10^5, 10^6 random floes per built-in broadphase on CUDA, the CPU at 10^4 and 10^5
//   resident  456 and 824 as one world on each CUDA driver (and the CPU), then ensembles of 456-floe
//             worlds run together on the resident driver, with date and commit (not in "all")
//   cpu       456, 824, 10^4, 10^5 floes on the CPU at 1, 2, 4, 8 and every core's threads (not in "all")
// and the geometry tables intersection | triangulation (bench/geometry_bench.hpp); "all" runs
// fields, blocks, copyback, scaling, intersection and triangulation one after another.
#pragma once
#include <filesystem>
#include <string>
#include <vector>

namespace gem {

struct BenchOptions {
  std::string table = "step";  // see above
  std::vector<long> sizes;     // geometry tables: N per row (empty: the thesis's sizes); resident: world counts
  int reps = 50;               // geometry tables: timed repetitions (median)
  long steps = 2000;           // timed steps per case (after a warm-up); fewer for large fields
  // A CSV file for one table; a directory (TABLE.csv in it) for "all", or when it names an existing
  // directory or ends in '/'. Empty: no CSV.
  std::string csv;
  // Cases: "456", "824", or a floe count N (a random field at 40 %); empty: the table's own.
  std::vector<std::string> cases;
  std::vector<std::string> broadphases;  // empty: the table's own
  std::vector<std::string> backends;     // "cpu", "cuda"; empty: the table's own
  std::vector<int> blockSizes;           // blocks: empty = 32, 64, 128, 256, 512, 1024
  std::vector<int> copyBackEvery;        // copyback: empty = 1, 2, 4, ..., 128
  int threads = 1;                       // the CPU rows' threads (simulation.threads)
};

// The table names runBench accepts, in the order "all" runs them (after "step", not in "all").
const std::vector<std::string>& benchTables();

int runBench(const BenchOptions& options);

// "model name" of the first CPU in /proc/cpuinfo.
std::string cpuName();

// The folder of the scenes gem bench times: $GEM_SCENARIOS, else PREFIX/share/gem/scenarios or
// scenarios/ beside the gem binary (installed or copied), else the source tree it was built from.
// Throws InputError naming the places it looked.
std::filesystem::path benchScenariosDir();

}  // namespace gem
