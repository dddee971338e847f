// Nothing changes in behaviour on the device: every golden scene (tests/golden_scenes.hpp) steps on
// the CUDA backend to the very hashes recorded in tests/golden/cuda.txt (on an H200) before the code
// was reorganised into rooms, with either CUDA driver: the device-wide one the hashes were recorded
// with, and the resident one (a world's whole step in one thread block), which runs the same phase
// functions and event evaluators in the same order of every sum, so its trajectories, contact
// counts and records are bit for bit the device-wide driver's. Skipped, visibly, where no device
// exists.
#include <gtest/gtest.h>

#include "tests/cuda/cuda_test_support.hpp"
#include "tests/golden_scenes.hpp"

namespace gem {
namespace {

class GoldenCuda : public ::testing::TestWithParam<test::GoldenScene> {};

TEST_P(GoldenCuda, StepsToTheRecordedHashOnTheDeviceWideDriver) {
  GEM_SKIP_WITHOUT_CUDA();
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt", {"simulation.cuda_driver=\"device\""});
}

TEST_P(GoldenCuda, StepsToTheRecordedHashOnTheResidentDriver) {
  GEM_SKIP_WITHOUT_CUDA();
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt", {"simulation.cuda_driver=\"resident\""});
}

INSTANTIATE_TEST_SUITE_P(Scenes, GoldenCuda, ::testing::ValuesIn(test::goldenScenes()), [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace gem
