// Deprecated include path, kept for one release so that plugins written against GEM 0.1's
// layout still build: include "framework/step/cpu_stepper.hpp" instead (docs/architecture.md "Rooms").
#pragma once
#pragma message("\"framework/simulation.hpp\" is deprecated: include \"framework/step/cpu_stepper.hpp\"")
#include "framework/step/cpu_stepper.hpp"

namespace gem {
// GEM 0.1's name of the CPU stepper.
using Simulation [[deprecated("gem::Simulation is now gem::CpuStepper (framework/step/cpu_stepper.hpp)")]] = CpuStepper;
}  // namespace gem
