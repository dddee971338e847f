// Checkpoints and frames on the CUDA backend (docs/reliability.md "Checkpoints and resume"), with each driver:
// a run killed, or stopped by Ctrl-C in the middle of a copy-back batch, resumes on the device to
// the very files of the run that was never stopped.
#include <gtest/gtest.h>

#include <algorithm>
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

namespace {

long summaryNumber(const std::string& summary, const std::string& key) {
  const size_t at = summary.find("\"" + key + "\": ");
  return at == std::string::npos ? -1 : std::stol(summary.substr(at + key.size() + 4));
}

// A stop rule that fires inside a copy-back batch (simulation.stop_when) ends a CUDA run at that
// batch's end, the first step whose state is on the host: the steps the device already ran are
// recorded, as after Ctrl-C, and the run exits 0 with the rule's reason. It used to fail there
// asking for the world in the middle of the batch, alone and in a sweep's cases run together.
TEST_P(CudaRunFolder, AStopRuleInsideABatchEndsTheRunAtTheBatchsEnd) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const std::string stop = " --quiet --no-plots --steps 2000 --set output.frame_every=0 --set simulation.stop_when=\\\"distance\\\"";
  const std::string cuda =
      std::string(" --backend cuda --set simulation.copy_back_every=16 --set simulation.cuda_driver=\\\"") + GetParam() + "\\\"";
  // The step the rule fires at: the same device run with a batch a step (the interval changes no
  // result: CudaBackend.CopyBackIntervalChangesNothing), where every step's state is on the host.
  ASSERT_EQ(runGem("run " + scenario.string() + stop + cuda + " --set simulation.copy_back_every=1 --set simulation.stop_distance=20.0" +
                       " --out " + (dir.path() / "reference").string(),
                   dir.path() / "log"),
            0)
      << readFile(dir.path() / "log");
  const long ruleStep = summaryNumber(readFile(dir.path() / "reference" / "summary.json"), "steps");
  ASSERT_GT(ruleStep, 16);
  ASSERT_NE(ruleStep % 16, 0) << "the rule fires at a batch's end already: it tests nothing";
  ASSERT_EQ(runGem("run " + scenario.string() + stop + cuda + " --set simulation.stop_distance=20.0 --out " + (dir.path() / "gpu").string(),
                   dir.path() / "log"),
            0)
      << readFile(dir.path() / "log");
  const std::string summary = readFile(dir.path() / "gpu" / "summary.json");
  EXPECT_NE(summary.find("\"stop_reason\": \"distance\""), std::string::npos) << summary;
  // Batches end at every 16th step, and earlier at a step the host's topology phase takes (the
  // device-wide driver's breaks): at the latest the 16th step the rule fired before.
  const long steps = summaryNumber(summary, "steps");
  EXPECT_GE(steps, ruleStep);
  EXPECT_LE(steps, (ruleStep + 15) / 16 * 16) << "past the end of the batch the rule fired in (it fires at step " << ruleStep << ")";
  // Every file stops at that step: timeseries.csv has a row a step.
  const std::string series = readFile(dir.path() / "gpu" / "timeseries.csv");
  EXPECT_EQ(static_cast<long>(std::count(series.begin(), series.end(), '\n')), steps + 1);

  // Two cases run together on the device, their rules firing in different batches.
  dir.write("stop.toml",
            "[sweep]\nname = \"stop\"\nbase = \"busy.toml\"\n[[cases]]\nname = \"near\"\nset = { \"simulation.stop_distance\" = 20.0 }\n"
            "[[cases]]\nname = \"far\"\nset = { \"simulation.stop_distance\" = 60.0 }\n");
  ASSERT_EQ(runGem("sweep " + (dir.path() / "stop.toml").string() + " --quiet --out " + (dir.path() / "sweep").string() + " --set " +
                       "simulation.steps=2000 --set output.frame_every=0 --set simulation.stop_when=\\\"distance\\\" --set " +
                       "simulation.backend=\\\"cuda\\\" --set simulation.copy_back_every=16 --set simulation.cuda_driver=\\\"" +
                       GetParam() + "\\\"",
                   dir.path() / "log"),
            0)
      << readFile(dir.path() / "log");
  const std::string near = readFile(dir.path() / "sweep" / "cases" / "near" / "summary.json"),
                    far = readFile(dir.path() / "sweep" / "cases" / "far" / "summary.json");
  EXPECT_NE(near.find("\"stop_reason\": \"distance\""), std::string::npos) << near;
  EXPECT_NE(far.find("\"stop_reason\": \"distance\""), std::string::npos) << far;
  EXPECT_GE(summaryNumber(near, "steps"), ruleStep);
  EXPECT_LE(summaryNumber(near, "steps"), (ruleStep + 15) / 16 * 16);
  EXPECT_LT(summaryNumber(near, "steps"), summaryNumber(far, "steps"));
}

}  // namespace

namespace {

// Ctrl-C stops a sweep whose cases run together on the device: each running case records the steps
// the device has already run (to the batch's end) and keeps whole files and a summary that says it
// did not complete, as a run alone does. It used to fail each case asking for the world in the
// middle of a batch, leaving no summary.
TEST_P(CudaRunFolder, CtrlCInsideABatchStopsCasesRunTogetherWhole) {
  GEM_SKIP_WITHOUT_CUDA();
  TempDir dir;
  dir.write("busy.toml", kBusyScene);
  const auto file = dir.write("long.toml",
                              "[sweep]\nname = \"long\"\nbase = \"busy.toml\"\n[[cases]]\nname = \"a\"\n"
                              "[[cases]]\nname = \"b\"\nset = { \"vessel.bollard_thrust\" = 500e3 }\n");
  const auto out = dir.path() / "out";
  // Both cases have started once the second's scenario.toml is written (its outputs appear only
  // at their end, through temporaries). Both drivers run them together on the grid.
  const std::string started = (out / "cases" / "b" / "scenario.toml").string();
  const int status =
      shell(gemBinary() + " sweep " + file.string() + " --out " + out.string() +
            " --set simulation.steps=2000000 --set output.frame_every=0 --set simulation.backend=\\\"cuda\\\"" +
            " --set simulation.broadphase=\\\"uniform_grid\\\"" + " --set simulation.copy_back_every=64 --set simulation.cuda_driver=\\\"" +
            GetParam() + "\\\" > " + (dir.path() / "log").string() + " 2>&1 & p=$!; for i in $(seq 600); do [ -s " + started +
            " ] && break; sleep 0.1; done; sleep 2; kill -INT $p; wait $p");
  ASSERT_EQ(status, 130) << readFile(dir.path() / "log");
  ASSERT_NE(readFile(dir.path() / "log").find("in 1 device run of several cases"), std::string::npos) << readFile(dir.path() / "log");
  long stepsOfA = -1;
  for (const char* name : {"a", "b"}) {
    SCOPED_TRACE(name);
    const std::string summary = readFile(out / "cases" / name / "summary.json");
    ASSERT_NE(summary.find("\"stop_reason\": \"SIGINT\""), std::string::npos) << summary << readFile(dir.path() / "log");
    EXPECT_NE(summary.find("\"completed\": false"), std::string::npos);
    const long steps = summaryNumber(summary, "steps");
    EXPECT_GT(steps, 0);
    const std::string series = readFile(out / "cases" / name / "timeseries.csv");
    EXPECT_EQ(static_cast<long>(std::count(series.begin(), series.end(), '\n')), steps + 1);  // a row a step, whole
    if (stepsOfA >= 0) {
      EXPECT_EQ(steps, stepsOfA);  // the cases stepped together stop at one step
    }
    stepsOfA = steps;
  }
}

}  // namespace
