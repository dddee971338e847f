#include "framework/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <fmt/format.h>

#include "framework/atomic_file.hpp"
#include "framework/errors.hpp"
#include "framework/simulation.hpp"

namespace gem {

std::string cpuName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

namespace {

struct BenchCase {
  std::string name;
  Scenario scenario;
};

Scenario thesisField(const char* file) {
  const std::filesystem::path path = std::filesystem::path(GEM_SOURCE_DIR) / "scenarios" / "thesis" / file;
  Scenario s = loadScenario(path);
  s.output.frameEvery = 0;
  return s;
}

// 10,000 random floes at 40 % in a 1000 m wide channel, the vessel entering it.
Scenario largeField() {
  Scenario s = thesisField("random_35.toml");
  s.domain = Domain{0, 1600, -500, 500};
  s.randomField.domain = s.domain;
  s.randomField.count = 10000;
  s.randomField.concentration = Real(0.4);
  return s;
}

}  // namespace

int runBench(const BenchOptions& options) {
  std::vector<BenchCase> cases;
  auto wanted = [&](const char* c) {
    return options.cases.empty() || std::find(options.cases.begin(), options.cases.end(), c) != options.cases.end();
  };
  if (wanted("456")) cases.push_back({"456 hexagons (46 %)", thesisField("hexagons_46.toml")});
  if (wanted("824")) cases.push_back({"824 random (50 %)", thesisField("random_50.toml")});
  if (wanted("10000")) cases.push_back({"10,000 random (40 %)", largeField()});
  if (cases.empty()) throw InputError("gem bench --cases: valid cases are 456, 824 and 10000");

  const std::string device = cpuName();
  std::printf("gem bench: CPU backend, one thread, on %s; %ld timed steps per case after 100 warm-up steps\n",
              device.c_str(), options.steps);
  std::printf("%-22s %-16s %7s %10s %10s %14s %12s\n", "case", "broadphase", "bodies", "ms/step", "steps/s",
              "floe-steps/s", "x real time");
  std::string csv = "case,broadphase,bodies,floes,ms_per_step,steps_per_s,floe_steps_per_s,real_time_factor,device\n";
  for (BenchCase& c : cases) {
    for (const std::string& broadphase : options.broadphases) {
      c.scenario.broadphase = broadphase;
      Simulation sim(c.scenario);
      for (int k = 0; k < 100; ++k) sim.step();
      // Five chunks; the median chunk is the figure (robust to a stray interruption).
      std::vector<double> perStep;
      const long chunk = std::max<long>(1, options.steps / 5);
      for (int r = 0; r < 5; ++r) {
        const auto start = std::chrono::steady_clock::now();
        for (long k = 0; k < chunk; ++k) sim.step();
        perStep.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / chunk);
      }
      std::sort(perStep.begin(), perStep.end());
      const double t = perStep[perStep.size() / 2];
      const int floes = sim.world().count(BodyKind::Floe);
      const double realTime = c.scenario.dt / t;
      std::printf("%-22s %-16s %7d %10.4f %10.0f %14.3g %12.0f\n", c.name.c_str(), broadphase.c_str(), sim.world().size(),
                  t * 1e3, 1 / t, floes / t, realTime);
      csv += fmt::format("\"{}\",{},{},{},{:.6f},{:.1f},{:.6g},{:.1f},\"{}\"\n", c.name, broadphase, sim.world().size(),
                         floes, t * 1e3, 1 / t, floes / t, realTime, device);
    }
  }
  if (!options.csv.empty()) writeFileAtomically(options.csv, csv);
  return 0;
}

}  // namespace gem
