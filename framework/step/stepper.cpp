#include "framework/step/stepper.hpp"

#include <cmath>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "framework/api/errors.hpp"
#include "framework/step/cpu_stepper.hpp"

namespace gem {

static std::map<std::string, BackendEntry>& backends() {
  static std::map<std::string, BackendEntry> table = [] {
    std::map<std::string, BackendEntry> t;
    BackendEntry cpu;
    cpu.name = "cpu";
    cpu.available = [] { return true; };
    cpu.deviceName = [] { return std::string("cpu"); };
    cpu.make = [](const Scenario& s) -> std::unique_ptr<Stepper> { return std::make_unique<CpuStepper>(s); };
    // No useDeviceForWorker (the CPU backend's workers share the cores) and no batching.
    t["cpu"] = cpu;
    return t;
  }();
  return table;
}

StepperState Stepper::saveState() {
  throw BackendUnsupported(fmt::format("the {} backend ({} driver) cannot write a checkpoint of this run", backend(), driver()));
}

void Stepper::restoreState(const StepperState&) {
  throw BackendUnsupported(fmt::format("the {} backend ({} driver) cannot resume this run from a checkpoint", backend(), driver()));
}

void registerBackend(BackendEntry entry) { backends()[entry.name] = std::move(entry); }

const BackendEntry* findBackend(const std::string& name) {
  auto it = backends().find(name);
  return it == backends().end() ? nullptr : &it->second;
}

std::vector<std::string> backendNames() {
  std::vector<std::string> names;
  for (const auto& [name, entry] : backends()) names.push_back(name);
  return names;
}

std::string resolveBackend(const std::string& requested) {
  if (requested == "auto") {
    const BackendEntry* cuda = findBackend("cuda");
    return cuda && cuda->available() ? "cuda" : "cpu";
  }
  const BackendEntry* entry = findBackend(requested);
  if (!entry)
    throw InputError(fmt::format("simulation.backend = \"{}\": this build of GEM has no such backend (built: {})", requested,
                                 fmt::join(backendNames(), ", ")));
  if (!entry->available())
    throw InputError(fmt::format("simulation.backend = \"{}\": no device for it was found on this machine", requested));
  return requested;
}

std::unique_ptr<Stepper> makeStepper(const Scenario& scenario) {
  const std::string backend = resolveBackend(scenario.backend);
  try {
    return findBackend(backend)->make(scenario);
  } catch (const BackendUnsupported& e) {
    if (scenario.backend != "auto" || backend == "cpu") throw;
    std::fprintf(stderr, "gem: backend auto: %s; running on the cpu\n", e.what());
    return findBackend("cpu")->make(scenario);
  }
}

std::string nonFiniteState(const World& w, long step, double time) {
  auto finite = [](Real a) { return std::isfinite(a); };
  for (int i = 0; i < w.size(); ++i)
    if (!(finite(w.x[i]) && finite(w.y[i]) && finite(w.angle[i]) && finite(w.vx[i]) && finite(w.vy[i]) && finite(w.omega[i])))
      return fmt::format(
          "step {} (t = {:.6g} s): body {} ({}) has a state that is no longer finite (x {}, y {}, angle {}, vx {}, vy {}, omega {})", step,
          time, w.id[i], bodyKindName(w.kind[i]), w.x[i], w.y[i], w.angle[i], w.vx[i], w.vy[i], w.omega[i]);
  return "";
}

}  // namespace gem
