// shear_current: the CUDA driver, the same evaluator struct as the CPU's (docs/plugins.md "On the GPU").
#include "shear_current.hpp"

#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_SOLO_EVENT(ShearCurrent, "shear_current");
}  // namespace gem
