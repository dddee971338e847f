// gem bench: times a backend per step on the thesis fields (456 hexagons, 824 random floes) and on
// 10^4, 10^5 and 10^6 random floes at 40 %, each with the vessel, and prints a table with the device.
// --table intersection | triangulation runs the geometry tables instead (framework/geometry_bench.hpp).
#pragma once
#include <string>
#include <vector>

namespace gem {

struct BenchOptions {
  std::string table = "step";      // "step" (time per step), "intersection", "triangulation"
  std::vector<long> sizes;         // geometry tables: N per row (empty: the thesis's sizes)
  int reps = 50;                   // geometry tables: timed repetitions (median)
  long steps = 2000;               // timed steps per case (after a warm-up)
  std::string csv;                 // also write the table here when not empty
  std::vector<std::string> cases;  // "456", "824", "10000", "100000", "1000000"; empty: the first three
  std::vector<std::string> broadphases{"variable_radius"};
  std::vector<std::string> backends{"cpu"};  // "cpu", "cuda"
};

int runBench(const BenchOptions& options);

// "model name" of the first CPU in /proc/cpuinfo.
std::string cpuName();

}  // namespace gem
