// Checkpoints and gem run --resume (docs/reliability.md "Checkpoints and resume"): a run killed or
// stopped by a signal, resumed, ends with the very files of the run that was never stopped.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "framework/analysis/sweep_summary.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/checkpoint.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "run_compare.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::kBusyScene;
using gem::test::readFile;
using gem::test::TempDir;
using namespace gem::test;

namespace {

constexpr const char* kRunOptions = " --quiet --no-plots --steps 20000 --set output.frame_every=500";

}  // namespace

// kill -9 mid-run: what the run left is whole (the checkpoint reads back, frames.pvd is a whole
// document, no summary claims a run), and the resumed run ends with the uninterrupted run's files,
// the frames, impacts, breaks and summary included.
TEST(Checkpoint, AKilledRunResumesToTheFilesOfTheWholeRun) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto whole = dir.path() / "whole", part = dir.path() / "part";
  ASSERT_EQ(test::runGem("run " + scenario.string() + kRunOptions + " --out " + whole.string(), dir.path() / "log"), 0)
      << readFile(dir.path() / "log");
  // Killed once a checkpoint exists and the run has gone on past it.
  const int killed =
      shell(gemBinary() + " run " + scenario.string() + kRunOptions + " --set output.checkpoint_every=700 --out " + part.string() +
            " > /dev/null 2>&1 & p=$!; " + waitFor(part / kCheckpointFile) + "sleep 0.1; kill -9 $p; wait $p");
  ASSERT_EQ(killed, 137) << "the run ended before it was killed";
  EXPECT_FALSE(std::filesystem::exists(part / "summary.json"));
  EXPECT_NO_THROW(readCheckpointFile(part / kCheckpointFile));
  const std::string pvd = readFile(part / "frames.pvd");
  EXPECT_NE(pvd.find("</VTKFile>"), std::string::npos) << pvd;

  // A kill -9 while a checkpoint or a frame was being written leaves its temporary: planted here,
  // so that the test does not hang on where the kill lands. The resume removes them.
  dir.write("part/checkpoint.gem.tmp-999999999", "half a checkpoint");
  dir.write("part/frames/frame_000003.vtp.tmp-999999999", "half a frame");
  ASSERT_EQ(test::runGem("run --resume " + part.string() + " --quiet --no-plots", dir.path() / "log"), 0) << readFile(dir.path() / "log");
  expectSameRun(whole, part);                                     // the same files: no temporary left
  EXPECT_FALSE(std::filesystem::exists(part / kCheckpointFile));  // a whole run keeps none
  const std::string log = readFile(part / "gem.log");
  EXPECT_NE(log.find("resumed from checkpoint.gem"), std::string::npos) << log;
}

// Ctrl-C writes a checkpoint where it stops; the run resumed, stopped again by SIGTERM and resumed
// once more ends as the run that was never stopped.
TEST(Checkpoint, ASignalLeavesACheckpointAndTwoResumesMakeTheWholeRun) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto whole = dir.path() / "whole", part = dir.path() / "part";
  ASSERT_EQ(test::runGem("run " + scenario.string() + kRunOptions + " --set output.vtk_encoding=\"binary\" --out " + whole.string(),
                         dir.path() / "log"),
            0);
  const std::string start = gemBinary() + " run " + scenario.string() + kRunOptions + " --set output.vtk_encoding=\\\"binary\\\" --out " +
                            part.string() + " > /dev/null 2>&1 & p=$!; ";
  ASSERT_EQ(shell(start + waitFor(part / "frames/frame_000003.vtp") + "kill -INT $p; wait $p"), 130);
  const auto stopped = readSummaryJson(part / "summary.json");
  EXPECT_EQ(stopped.at("completed"), "false");
  ASSERT_TRUE(std::filesystem::exists(part / kCheckpointFile));
  const int again = shell(gemBinary() + " run --resume " + part.string() + " --quiet --no-plots > /dev/null 2>&1 & p=$!; " +
                          waitFor(part / "frames/frame_000010.vtp") +
                          "kill -TERM $p; wait $p");  // frames past the checkpoint go at a resume: frame 10 is this part's
  ASSERT_EQ(again, 143);
  EXPECT_GT(std::stol(readSummaryJson(part / "summary.json").at("steps")), std::stol(stopped.at("steps")));
  ASSERT_EQ(test::runGem("run --resume " + part.string() + " --quiet --no-plots", dir.path() / "log"), 0) << readFile(dir.path() / "log");
  expectSameRun(whole, part);
}

// A resume killed outright (kill -9, a crash, a batch system's hard limit) before it wrote a
// checkpoint of its own had already taken the stopped run's files over under its own temporary
// names, which the checkpoint does not know: the next resume finds them there and still ends as
// the run that was never stopped (it once refused: "timeseries.csv is missing", for ever).
TEST(Checkpoint, AResumeKilledBeforeItsFirstCheckpointCanBeResumed) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto whole = dir.path() / "whole", part = dir.path() / "part";
  ASSERT_EQ(test::runGem("run " + scenario.string() + kRunOptions + " --out " + whole.string(), dir.path() / "log"), 0);
  ASSERT_EQ(shell(gemBinary() + " run " + scenario.string() + kRunOptions + " --out " + part.string() + " > /dev/null 2>&1 & p=$!; " +
                  waitFor(part / "frames/frame_000003.vtp") + "kill -TERM $p; wait $p"),
            143);
  ASSERT_EQ(shell(gemBinary() + " run --resume " + part.string() + " --quiet --no-plots > /dev/null 2>&1 & p=$!; " +
                  waitFor(part / "frames/frame_000010.vtp") + "kill -9 $p; wait $p"),
            137);
  ASSERT_EQ(test::runGem("run --resume " + part.string() + " --quiet --no-plots", dir.path() / "log"), 0) << readFile(dir.path() / "log");
  expectSameRun(whole, part);
}

// A run folder whose frames were deleted after the stop cannot be resumed: the resume once went on
// and wrote a frames.pvd listing thousands of frames that no longer existed.
TEST(Checkpoint, AResumeRefusesAFolderWhoseFramesAreGone) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto part = dir.path() / "part";
  ASSERT_EQ(shell(gemBinary() + " run " + scenario.string() + kRunOptions + " --out " + part.string() + " > /dev/null 2>&1 & p=$!; " +
                  waitFor(part / "frames/frame_000003.vtp") + "kill -INT $p; wait $p"),
            130);
  std::filesystem::remove_all(part / "frames");
  EXPECT_EQ(test::runGem("run --resume " + part.string() + " --quiet --no-plots", dir.path() / "log"), 2);
  const std::string text = readFile(dir.path() / "log");
  EXPECT_NE(text.find("cannot resume: " + (part / "frames/frame_000000.vtp").string() + " is missing"), std::string::npos) << text;
  // Refused before anything of the stopped run was touched: its summary still says it stopped.
  EXPECT_EQ(readSummaryJson(part / "summary.json").at("completed"), "false");
}

// A frame cut short after the stop is refused as a deleted one is (the resume once went on over a
// 50-byte frame and its frames.pvd still listed it).
TEST(Checkpoint, AResumeRefusesAFolderWithAFrameCutShort) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto part = dir.path() / "part";
  ASSERT_EQ(shell(gemBinary() + " run " + scenario.string() + kRunOptions + " --out " + part.string() + " > /dev/null 2>&1 & p=$!; " +
                  waitFor(part / "frames/frame_000003.vtp") + "kill -INT $p; wait $p"),
            130);
  const auto frame = part / "frames/frame_000001.vtp";
  std::filesystem::resize_file(frame, 50);
  EXPECT_EQ(test::runGem("run --resume " + part.string() + " --quiet --no-plots", dir.path() / "log"), 2);
  const std::string text = readFile(dir.path() / "log");
  EXPECT_NE(text.find("cannot resume: " + frame.string() + " is cut short"), std::string::npos) << text;
  EXPECT_EQ(readSummaryJson(part / "summary.json").at("completed"), "false");
}

// What cannot be resumed is refused with exit 2 and a message naming the file: no checkpoint, a
// damaged or cut one, a scenario.toml changed since, a folder that is no run's, and options that
// would make it another run.
TEST(Checkpoint, ResumeRefusesWhatItCannotContinue) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto run = dir.path() / "run";
  const auto log = dir.path() / "log";
  auto resume = [&](const std::string& more = "") { return test::runGem("run --resume " + run.string() + " --quiet" + more, log); };
  auto says = [&](const std::string& text) { return readFile(log).find(text) != std::string::npos; };

  ASSERT_EQ(test::runGem("run " + scenario.string() + " --quiet --no-plots --steps 20 --out " + run.string(), log), 0);
  EXPECT_EQ(resume(), 2);
  EXPECT_TRUE(says("no checkpoint here")) << readFile(log);

  ASSERT_EQ(shell(gemBinary() + " run " + scenario.string() +
                  " --quiet --no-plots --steps 20000 --set output.frame_every=0 --set output.checkpoint_every=1000 --out " + run.string() +
                  " > /dev/null 2>&1 & p=$!; " + waitFor(run / kCheckpointFile) + "kill -INT $p; wait $p"),
            130);
  const std::string checkpoint = readFile(run / kCheckpointFile);
  ASSERT_GT(checkpoint.size(), 100u);
  auto writeCheckpoint = [&](const std::string& bytes) { std::ofstream(run / kCheckpointFile, std::ios::binary) << bytes; };

  std::string damaged = checkpoint;
  damaged[damaged.size() / 2] ^= 0x5a;
  writeCheckpoint(damaged);
  EXPECT_EQ(resume(), 2);
  EXPECT_TRUE(says("checkpoint.gem: damaged")) << readFile(log);

  writeCheckpoint(checkpoint.substr(0, checkpoint.size() - 7));
  EXPECT_EQ(resume(), 2);
  EXPECT_TRUE(says("checkpoint.gem: cut short or damaged")) << readFile(log);

  writeCheckpoint("not a checkpoint at all");
  EXPECT_EQ(resume(), 2);
  EXPECT_TRUE(says("not a GEM checkpoint")) << readFile(log);

  // A folder where the checkpoint should be is said to be one (not "no checkpoint here").
  std::filesystem::remove(run / kCheckpointFile);
  std::filesystem::create_directory(run / kCheckpointFile);
  EXPECT_EQ(resume(), 2);
  EXPECT_TRUE(says("checkpoint.gem: a folder, not a checkpoint file")) << readFile(log);
  std::filesystem::remove(run / kCheckpointFile);

  writeCheckpoint(checkpoint);
  const std::string recorded = readFile(run / "scenario.toml");
  std::ofstream(run / "scenario.toml", std::ios::app) << "# edited\n";
  EXPECT_EQ(resume(), 2);
  EXPECT_TRUE(says("changed since the checkpoint was written")) << readFile(log);
  std::ofstream(run / "scenario.toml", std::ios::trunc) << recorded;

  EXPECT_EQ(resume(" --steps 5"), 2);
  EXPECT_EQ(test::runGem("run --resume " + (dir.path() / "nowhere").string(), log), 2);
  EXPECT_TRUE(says("not a folder")) << readFile(log);
  EXPECT_EQ(test::runGem("run --resume " + dir.path().string(), log), 2);
  EXPECT_TRUE(says("no scenario.toml there")) << readFile(log);

  // After all that, the checkpoint as written still resumes.
  EXPECT_EQ(test::runGem("run --resume " + run.string() + " --quiet --no-plots", log), 0) << readFile(log);
}

// A stepper restored from another's state steps on bit for bit as the one that saved it.
TEST(Checkpoint, ARestoredStepperStepsOnBitForBit) {
  TempDir dir;
  const Scenario scenario = test::scenarioFromToml(dir, kBusyScene);
  CpuStepper first(scenario);
  for (int k = 0; k < 150; ++k) first.step();
  BinaryWriter out;
  putStepperState(out, first.saveState());
  StepperState state;
  BinaryReader in(out.bytes(), "state");
  getStepperState(in, state);
  EXPECT_TRUE(in.atEnd());
  // A stepper that has stepped on its own first: nothing it kept may leak into the restored run.
  CpuStepper second(scenario);
  for (int k = 0; k < 37; ++k) second.step();
  second.restoreState(state);
  for (int k = 0; k < 150; ++k) first.step(), second.step();
  const World &a = first.world(), &b = second.world();
  EXPECT_EQ(second.stepIndex(), 300);
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.x, b.x);
  EXPECT_EQ(a.y, b.y);
  EXPECT_EQ(a.angle, b.angle);
  EXPECT_EQ(a.vx, b.vx);
  EXPECT_EQ(a.omega, b.omega);
  EXPECT_EQ(first.floesBroken(), second.floesBroken());
  EXPECT_GT(first.floesBroken(), 0);  // the scene breaks floes: the restored ids and pieces are tested too
}

// The file is read back only whole and only from this GEM: a cut, a flipped byte, a crafted count
// or a temporary's name that would reach outside the run folder are refused, never followed.
TEST(Checkpoint, OnlyAWholeFileOfThisGemIsReadBack) {
  TempDir dir;
  const auto file = dir.path() / kCheckpointFile;
  writeCheckpointFile(file, "payload bytes");
  EXPECT_EQ(readCheckpointFile(file), "payload bytes");
  const std::string bytes = readFile(file);
  for (size_t cut : {size_t(0), size_t(5), bytes.size() - 1}) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << bytes.substr(0, cut);
    EXPECT_THROW(readCheckpointFile(file), InputError) << cut;
  }
  std::string other = bytes;
  other.replace(other.find("gem "), 4, "GEM ");  // another writer
  std::ofstream(file, std::ios::binary | std::ios::trunc) << other;
  EXPECT_THROW(readCheckpointFile(file), InputError);

  BinaryWriter huge;
  huge.put(std::uint64_t(1) << 60);  // a count no file holds
  BinaryReader in(huge.bytes(), "crafted");
  std::vector<double> values;
  EXPECT_THROW(in.get(values), InputError);

  EXPECT_EQ(earlierTempPath(dir.path() / "timeseries.csv", "timeseries.csv.tmp-123"), dir.path() / "timeseries.csv.tmp-123");
  for (const char* crafted : {"../timeseries.csv.tmp-1", "timeseries.csv.tmp-", "timeseries.csv.tmp-1/../../x", "impacts.csv.tmp-4"})
    EXPECT_THROW(earlierTempPath(dir.path() / "timeseries.csv", crafted), InputError) << crafted;
}

// output.checkpoint_every takes a number of steps or a wall-clock interval; anything else is
// refused naming the key.
TEST(Checkpoint, CheckpointEveryTakesStepsOrAWallClockInterval) {
  TempDir dir;
  auto load = [&](const std::string& value) {
    return test::scenarioFromToml(dir, std::string(kBusyScene) + "[output]\ncheckpoint_every = " + value + "\n").output;
  };
  EXPECT_EQ(load("500").checkpointEverySteps, 500);
  EXPECT_EQ(load("\"90s\"").checkpointEverySeconds, 90);
  EXPECT_EQ(load("\"10min\"").checkpointEverySeconds, 600);
  EXPECT_EQ(load("\"1.5h\"").checkpointEverySeconds, 5400);
  for (const char* bad : {"0", "-3", "\"10 parsecs\"", "\"0s\"", "\"s\"", "true", "1.5"}) {
    try {
      load(bad);
      ADD_FAILURE() << bad << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("output.checkpoint_every"), std::string::npos) << e.what();
    }
  }
}
