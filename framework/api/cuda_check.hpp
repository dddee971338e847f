// Every CUDA call is checked: a failure throws std::runtime_error naming the file, line and the
// runtime's message (docs/performance.md 1.3: check every CUDA call's status and the last error after each launch).
#pragma once
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace gem::cuda {

inline void check(cudaError_t status, const char* what, const char* file, int line) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " + cudaGetErrorString(status));
}

}  // namespace gem::cuda

#define GEM_CUDA_CHECK(call) ::gem::cuda::check((call), #call, __FILE__, __LINE__)
// After a kernel launch: launch-configuration errors show up here, not at the launch itself.
#define GEM_CUDA_CHECK_LAUNCH() ::gem::cuda::check(cudaGetLastError(), "kernel launch", __FILE__, __LINE__)
