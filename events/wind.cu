// wind: the CUDA driver, the same evaluator as the CPU (docs/architecture.md "Writing an event").
#include "events/environmental_force.hpp"
#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_SOLO_EVENT(EnvironmentalForce, "wind");
}  // namespace gem
