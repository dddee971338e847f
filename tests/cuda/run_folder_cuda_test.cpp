// Checkpoints and frames on the CUDA backend (docs/reliability.md "Checkpoints and resume"), with each driver:
// a run killed, or stopped by Ctrl-C in the middle of a copy-back batch, resumes on the device to
// the very files of the run that was never stopped.
#include <gtest/gtest.h>

#include <string>

#include "cuda_test_support.hpp"
#include "framework/output/checkpoint.hpp"
#include "../run_compare.hpp"
#include "../test_support.hpp"

using namespace gem;
using namespace gem::test;

namespace {

class CudaRunFolder : public ::testing::TestWithParam<const char*> {};

TEST_P(CudaRunFolder, AKilledOrInterruptedRunResumesToTheFilesOfTheWholeRun) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto whole = dir.path() / "whole", killed = dir.path() / "killed", interrupted = dir.path() / "interrupted";
  // copy_back_every = 16 and frames every 500 steps: most steps are inside a device batch.
  const std::string options = std::string(" --backend cuda --quiet --no-plots --steps 6000 --set output.frame_every=500") +
                              " --set simulation.cuda_driver=\\\"" + GetParam() + "\\\"";
  ASSERT_EQ(shell(gemBinary() + " run " + scenario.string() + options + " --out " + whole.string() + " > /dev/null 2>&1"), 0);
  EXPECT_NE(readFile(whole / "summary.json").find(std::string("\"driver\": \"") + GetParam() + "\""), std::string::npos);

  const int status =
      shell(gemBinary() + " run " + scenario.string() + options + " --set output.checkpoint_every=700 --out " + killed.string() +
            " > /dev/null 2>&1 & p=$!; " + waitFor(killed / kCheckpointFile) + "sleep 0.05; kill -9 $p; wait $p");
  ASSERT_EQ(status, 137) << "the run ended before it was killed";
  ASSERT_EQ(runGem("run --resume " + killed.string() + " --quiet --no-plots", dir.path() / "log"), 0) << readFile(dir.path() / "log");
  expectSameRun(whole, killed);

  // Ctrl-C lands inside a batch: the run records the steps the device has run, then stops.
  ASSERT_EQ(shell(gemBinary() + " run " + scenario.string() + options + " --out " + interrupted.string() + " > /dev/null 2>&1 & p=$!; " +
                  waitFor(interrupted / "frames/frame_000002.vtp") + "kill -INT $p; wait $p"),
            130);
  ASSERT_EQ(runGem("run --resume " + interrupted.string() + " --quiet --no-plots", dir.path() / "log"), 0) << readFile(dir.path() / "log");
  expectSameRun(whole, interrupted);
}

INSTANTIATE_TEST_SUITE_P(Drivers, CudaRunFolder, ::testing::Values("device", "resident"));

}  // namespace

namespace {

// The frames of a CUDA run carry each body's contact force, as the CPU's do, with either driver.
TEST_P(CudaRunFolder, FramesCarryEachBodysContactForce) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const auto scenario = dir.write("push.toml", kContactForceScene);
  const auto out = dir.path() / "out";
  ASSERT_EQ(runGem("run " + scenario.string() + " --backend cuda --set simulation.cuda_driver=\\\"" + GetParam() +
                       "\\\" --quiet --no-plots --out " + out.string(),
                   dir.path() / "log"),
            0)
      << readFile(dir.path() / "log");
  expectContactForcesInFrames(out);
}

}  // namespace
