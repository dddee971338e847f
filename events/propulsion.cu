// propulsion: the CUDA driver, the same evaluator as the CPU (DESIGN.md "Writing an event").
#include "events/propulsion.hpp"
#include "framework/cuda/cuda_events.hpp"
#include "framework/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_SOLO_EVENT(Propulsion, "propulsion");
}  // namespace gem
