// impact: the CUDA driver, the same evaluator as the CPU (docs/architecture.md "Writing an event").
#include "events/impact.hpp"
#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_PAIR_EVENT(Impact, "impact");
}  // namespace gem
