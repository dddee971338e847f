// gem bench: times the CPU backend per step on the thesis fields (456 hexagons, 824 random floes)
// and on 10,000 random floes, each with the vessel, and prints a table with the machine's name.
#pragma once
#include <string>
#include <vector>

namespace gem {

struct BenchOptions {
  long steps = 2000;               // timed steps per case (after a warm-up)
  std::string csv;                 // also write the table here when not empty
  std::vector<std::string> cases;  // "456", "824", "10000"; empty: all
  std::vector<std::string> broadphases{"variable_radius"};
};

int runBench(const BenchOptions& options);

// "model name" of the first CPU in /proc/cpuinfo.
std::string cpuName();

}  // namespace gem
