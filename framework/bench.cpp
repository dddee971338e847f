#include "framework/bench.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>

#include <fmt/format.h>

#include "framework/atomic_file.hpp"
#include "framework/errors.hpp"
#include "framework/geometry_bench.hpp"
#include "framework/simulation.hpp"
#include "framework/stepper.hpp"

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

// N random floes at 40 % in a square-ish channel, the vessel entering it. The domain's area holds
// N floes of the thesis's size statistics (E[s^2] = 6.9^2 + 3.9^2 m^2).
Scenario largeField(int floes) {
  Scenario s = thesisField("random_35.toml");
  const Real area = floes * Real(6.9 * 6.9 + 3.9 * 3.9) / Real(0.4);
  const Real width = std::max<Real>(200, std::round(std::sqrt(area) / 100) * 100);
  s.domain = Domain{0, std::ceil(area / width), -width / 2, width / 2};
  s.randomField.domain = s.domain;
  s.randomField.count = floes;
  s.randomField.concentration = Real(0.4);
  return s;
}

}  // namespace

int runBench(const BenchOptions& options) {
  if (options.table != "step") return runGeometryBench(GeometryBenchOptions{options.table, options.sizes, options.csv, options.reps});
  std::vector<BenchCase> cases;
  auto wanted = [&](const char* c, bool byDefault) {
    return options.cases.empty() ? byDefault : std::find(options.cases.begin(), options.cases.end(), c) != options.cases.end();
  };
  if (wanted("456", true)) cases.push_back({"456 hexagons (46 %)", thesisField("hexagons_46.toml")});
  if (wanted("824", true)) cases.push_back({"824 random (50 %)", thesisField("random_50.toml")});
  if (wanted("10000", true)) cases.push_back({"10^4 random (40 %)", largeField(10000)});
  if (wanted("100000", false)) cases.push_back({"10^5 random (40 %)", largeField(100000)});
  if (wanted("1000000", false)) cases.push_back({"10^6 random (40 %)", largeField(1000000)});
  if (cases.empty()) throw InputError("gem bench --cases: valid cases are 456, 824, 10000, 100000 and 1000000");
  for (const std::string& b : options.backends) resolveBackend(b);  // a backend without a device is an error now

  std::printf("gem bench: %ld timed steps per case (fewer for large fields) after a warm-up; median of 5 chunks\n",
              options.steps);
  std::printf("%-20s %-7s %-16s %8s %10s %10s %14s %12s  %s\n", "case", "backend", "broadphase", "bodies", "ms/step",
              "steps/s", "floe-steps/s", "x real time", "device");
  std::string csv = "case,backend,broadphase,bodies,floes,ms_per_step,steps_per_s,floe_steps_per_s,real_time_factor,device\n";
  for (BenchCase& c : cases) {
    for (const std::string& backend : options.backends) {
      for (const std::string& broadphase : options.broadphases) {
        c.scenario.broadphase = broadphase;
        c.scenario.backend = backend;
        std::unique_ptr<Stepper> sim = makeStepper(c.scenario);
        const int bodies = sim->hostWorld().size();
        const int floes = sim->hostWorld().count(BodyKind::Floe);
        // Large fields get fewer steps, so that one case stays within a minute on a slow backend.
        const long steps = std::clamp<long>(options.steps * 1000 / std::max(bodies, 1), 10, options.steps);
        for (long k = 0; k < std::min<long>(100, steps); ++k) sim->step();
        std::vector<double> perStep;
        const long chunk = std::max<long>(1, steps / 5);
        for (int r = 0; r < 5; ++r) {
          const auto start = std::chrono::steady_clock::now();
          for (long k = 0; k < chunk; ++k) sim->step();  // step() returns once the step is done (device synced)
          perStep.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() / chunk);
        }
        std::sort(perStep.begin(), perStep.end());
        const double t = perStep[perStep.size() / 2];
        const double realTime = c.scenario.dt / t;
        const std::string device = backend == "cpu" ? cpuName() + " (one core)" : sim->device();
        std::printf("%-20s %-7s %-16s %8d %10.4f %10.0f %14.3g %12.0f  %s\n", c.name.c_str(), backend.c_str(),
                    broadphase.c_str(), bodies, t * 1e3, 1 / t, floes / t, realTime, device.c_str());
        std::fflush(stdout);
        csv += fmt::format("\"{}\",{},{},{},{},{:.6f},{:.1f},{:.6g},{:.1f},\"{}\"\n", c.name, backend, broadphase, bodies,
                           floes, t * 1e3, 1 / t, floes / t, realTime, device);
      }
    }
  }
  if (!options.csv.empty()) writeFileAtomically(options.csv, csv);
  return 0;
}

}  // namespace gem
