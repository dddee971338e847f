// autopilot: the CUDA driver, the same evaluator as the CPU (docs/architecture.md "Writing an event").
#include "events/autopilot.hpp"
#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_SOLO_EVENT(Autopilot, "autopilot");
}  // namespace gem
