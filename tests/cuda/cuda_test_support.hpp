// What the CUDA tests share beyond ../test_support.hpp: the visible skip where no device exists
// (CI), and the test plugins' paths.
#pragma once
#include <cstdlib>
#include <string>

#include "framework/cuda/cuda_stepper.hpp"

#define GEM_SKIP_WITHOUT_CUDA() \
  if (!::gem::cudaAvailable()) GTEST_SKIP() << "no CUDA device"

namespace gem::test {

// A test plugin built with its CUDA part: $GEM_TEST_CUDA_PLUGIN_DIR when set (a staged copy on the
// GPU machine), else the build's.
inline std::string cudaTestPlugin(const std::string& file) {
  const char* dir = std::getenv("GEM_TEST_CUDA_PLUGIN_DIR");
  return std::string(dir ? dir : GEM_TEST_CUDA_PLUGIN_DIR) + "/" + file;
}

}  // namespace gem::test
