// Nothing changes in behaviour on the device: every golden scene (tests/golden_scenes.hpp) steps on
// the CUDA backend to the very hashes recorded in tests/golden/cuda.txt (on an H200) before the code
// was reorganised into rooms. Skipped, visibly, where no device exists.
#include <gtest/gtest.h>

#include "tests/cuda/cuda_test_support.hpp"
#include "tests/golden_scenes.hpp"

namespace gem {
namespace {

class GoldenCuda : public ::testing::TestWithParam<test::GoldenScene> {};

TEST_P(GoldenCuda, StepsToTheRecordedHash) {
  GEM_SKIP_WITHOUT_CUDA();
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt");
}

INSTANTIATE_TEST_SUITE_P(Scenes, GoldenCuda, ::testing::ValuesIn(test::goldenScenes()), [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace gem
