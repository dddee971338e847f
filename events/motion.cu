// motion: the CUDA driver, the same evaluator as the CPU (docs/architecture.md "Writing an event").
#include "events/motion.hpp"
#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_MOTION_EVENT(Motion, "motion");
}  // namespace gem
