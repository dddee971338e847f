// rafting_onset: the CUDA driver, the same evaluator struct as the CPU's; its LogRecords come back
// with the step's other records and are written on the host (framework/api/log_channel.hpp).
#include "rafting_onset.hpp"

#include "framework/api/cuda_events.hpp"
#include "framework/api/registry.hpp"

namespace gem {
GEM_REGISTER_CUDA_PAIR_EVENT(RaftingOnset, "rafting_onset");
}  // namespace gem
