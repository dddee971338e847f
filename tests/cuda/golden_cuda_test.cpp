// Nothing changes in behaviour on the device: every golden scene (tests/golden_scenes.hpp) steps on
// the CUDA backend to the very hashes recorded in tests/golden/cuda.txt (on an H200) before the code
// was reorganised into rooms, with either CUDA driver: the device-wide one the hashes were recorded
// with, and the resident one (a world's whole step in one thread block), which runs the same phase
// functions and event evaluators in the same order of every sum, and cuts broken floes in its
// kernel with the host's arithmetic (events/flexural_cut.hpp, geometry/portable_trig.hpp), so its
// trajectories, contact counts and records are bit for bit the device-wide driver's. Skipped,
// visibly, where no device exists.
#include <gtest/gtest.h>

#include <cstdlib>

#include "tests/cuda/cuda_test_support.hpp"
#include "tests/golden_scenes.hpp"

namespace gem {
namespace {

class GoldenCuda : public ::testing::TestWithParam<test::GoldenScene> {};

// The resident driver re-sorts along the curve inside its launches, so only copy_back_every (and
// frames, breaks past a world's room, the end) ends one. Launches of 125 steps end at the golden
// scenes' 1,000th step, where the fingerprint reads the whole world (the host has it only between
// launches), while the re-sorts at steps 200, 400, 600 and 800 fall inside launches. The interval
// changes no result (CudaBackend.CopyBackIntervalChangesNothing).
const std::vector<std::string> kResident = {"simulation.cuda_driver=\"resident\"", "simulation.copy_back_every=125"};
static_assert(test::kGoldenSteps % 125 == 0, "a resident launch must end where the fingerprint reads the world");

TEST_P(GoldenCuda, StepsToTheRecordedHashOnTheDeviceWideDriver) {
  GEM_SKIP_WITHOUT_CUDA();
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt", {"simulation.cuda_driver=\"device\""});
}

TEST_P(GoldenCuda, StepsToTheRecordedHashOnTheResidentDriver) {
  GEM_SKIP_WITHOUT_CUDA();
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt", kResident);
}

// The resident kernel breaks floes itself (resident_kernel.cuh breakFloes) while a world has room
// for the pieces; a step that needs more ends the launch, and the host's topology phase breaks
// them as the device-wide driver's does. Either way, and mixed within a run, the same bits: with
// room for no piece (every break on the host) and for two a launch (most launches end at a break
// that passes the room, after breaks in the kernel).
class SpareRoom {
 public:
  explicit SpareRoom(const char* pieces) { setenv("GEM_RESIDENT_SPARE", pieces, 1); }
  ~SpareRoom() { unsetenv("GEM_RESIDENT_SPARE"); }
};

TEST_P(GoldenCuda, StepsToTheRecordedHashOnTheResidentDriverBreakingOnTheHost) {
  GEM_SKIP_WITHOUT_CUDA();
  SpareRoom none("0");
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt", kResident);
}

TEST_P(GoldenCuda, StepsToTheRecordedHashOnTheResidentDriverWithRoomForTwoPieces) {
  GEM_SKIP_WITHOUT_CUDA();
  SpareRoom two("2");
  test::expectGoldenHash(GetParam(), "cuda", "tests/golden/cuda.txt", kResident);
}

INSTANTIATE_TEST_SUITE_P(Scenes, GoldenCuda, ::testing::ValuesIn(test::goldenScenes()), [](const auto& info) { return info.param.name; });

}  // namespace
}  // namespace gem
