// The hostile audit of the command line (2026-12-04, second round): each test holds one class of
// input that GEM took silently, or refused in words that named neither the option nor the key, to
// exit 2 with one message naming what is at fault (docs/reliability.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <string>

#include "test_support.hpp"

using gem::test::TempDir;

namespace {

// The one line gem wrote for `arguments`, which must exit with status 2.
// (CLI11's own refusals add a line: "Run with --help for more information.")
std::string refused(const TempDir& dir, const std::string& arguments, bool oneLine = true) {
  const auto log = dir.path() / "log.txt";
  EXPECT_EQ(gem::test::runGem(arguments, log), 2) << arguments << ": " << gem::test::readFile(log);
  const std::string text = gem::test::readFile(log);
  if (oneLine) EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
  return text;
}

bool holds(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

// A folder that access() calls writable but that can hold no file (/proc, for root or not): `gem run
// --out /proc` said "cannot open the run folder's lock" without naming the option; every --out is
// now tried with a file made and removed.
TEST(HostileCli, AnOutputFolderThatCanHoldNoFileNamesItsOption) {
  TempDir dir;
  const auto scenario = dir.write("s.toml", gem::test::kTinyChannel);
  const auto sweep = dir.write("study.toml", "[sweep]\nbase = \"s.toml\"\n[[cases]]\nname = \"a\"\n");
  const struct {
    std::string arguments, option;
  } cases[] = {
      {"run " + scenario.string() + " --steps 2 --out /proc", "gem run --out /proc"},
      {"sweep " + sweep.string() + " --out /proc", "gem sweep --out /proc"},
      {"calibrate --out /proc", "gem calibrate --out /proc"},
  };
  for (const auto& c : cases) {
    const std::string text = refused(dir, c.arguments);
    EXPECT_TRUE(holds(text, c.option)) << text;
    // As root the probe file fails; as anyone else access() already says no.
    EXPECT_TRUE(holds(text, "cannot make a file in the folder /proc") || holds(text, "cannot write in the folder /proc")) << text;
  }
  // A file where the run folder goes: the option is named too (it said "the run folder").
  const auto file = dir.write("a_file", "x");
  EXPECT_TRUE(holds(refused(dir, "run " + scenario.string() + " --steps 2 --out " + file.string()), "gem run --out")) << file;
  // A folder that holds files is taken, and the probe leaves nothing behind.
  const auto out = dir.path() / "out";
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() + " --steps 2 --quiet --no-plots --out " + out.string(), dir.path() / "log.txt"),
            0);
  for (const auto& e : std::filesystem::directory_iterator(out)) EXPECT_FALSE(holds(e.path().filename().string(), "probe")) << e.path();
  // A run refused for its input makes no run folder (the --out check makes nothing).
  const auto refusedOut = dir.path() / "never_made";
  EXPECT_EQ(gem::test::runGem("run " + scenario.string() + " --steps 2 --set simulation.dt=-1 --out " + refusedOut.string(),
                              dir.path() / "log.txt"),
            2);
  EXPECT_FALSE(std::filesystem::exists(refusedOut)) << gem::test::readFile(dir.path() / "log.txt");
}

// gem analyze --groups: an empty group (`--groups ''`, 'a;;b') meant every group, and a run folder
// took any name at all, analysing the whole run under "all" with exit 0.
TEST(HostileCli, AnalyzeGroupsThatNameNoGroupAreRefused) {
  TempDir dir;
  const auto scenario = dir.write("s.toml", gem::test::kTinyChannel);
  const auto run = dir.path() / "run";
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() + " --quiet --no-plots --out " + run.string(), dir.path() / "log.txt"), 0);
  EXPECT_TRUE(holds(refused(dir, "analyze " + run.string() + " --groups ''", false), "--groups")) << run;
  EXPECT_TRUE(holds(refused(dir, "analyze " + run.string() + " --groups 'all;;all'", false), "--groups")) << run;
  const std::string text = refused(dir, "analyze " + run.string() + " --groups concentration=0.4");
  EXPECT_TRUE(holds(text, "--groups concentration=0.4")) << text;
  EXPECT_TRUE(holds(text, "a run folder, one group")) << text;
  // "all" is its group.
  EXPECT_EQ(gem::test::runGem("analyze " + run.string() + " --quiet --groups all", dir.path() / "log.txt"), 0)
      << gem::test::readFile(dir.path() / "log.txt");
}

// --batch above 1024 was taken, though a device state holds at most 1024 cases.
TEST(HostileCli, ABatchBeyondADeviceStatesCasesIsRefused) {
  TempDir dir;
  dir.write("s.toml", gem::test::kTinyChannel);
  const auto sweep = dir.write("study.toml", "[sweep]\nbase = \"s.toml\"\n[[cases]]\nname = \"a\"\n");
  const std::string text = refused(dir, "sweep " + sweep.string() + " --batch 1025 --out " + (dir.path() / "o").string(), false);
  EXPECT_TRUE(holds(text, "--batch")) << text;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "o" / "summary.csv"));
}

// A hand-edited .ice object: an element GEM reads given twice took the first silently (a second
// <coordinates>, <thickness>, <velocity>), and a misspelt velocity attribute (vx="1") left the
// velocity zero. Each is refused naming the file, its line and column, and the object.
TEST(HostileCli, AnIceObjectWithAnElementTwiceOrAStrayVelocityAttributeIsRefused) {
  TempDir dir;
  dir.write("s.toml", "[simulation]\ndt = 0.1\nsteps = 5\n[field]\nkind = \"file\"\nfile = \"f.ice\"\n");
  const std::string square = "<coordinates>80 0 82 0 82 2 80 2</coordinates>";
  const struct {
    std::string object, expected;
  } cases[] = {
      {square + "<coordinates>50 0 52 0 52 2</coordinates><thickness>0.5</thickness>", "a second <coordinates>"},
      {square + "<thickness>0.5</thickness><thickness>7</thickness>", "a second <thickness>"},
      {square + "<velocity x=\"1\"/><velocity x=\"5\"/><thickness>0.5</thickness>", "a second <velocity>"},
      {square + "<velocity vx=\"1\"/><thickness>0.5</thickness>", "velocity vx="},
  };
  for (const auto& c : cases) {
    const auto ice =
        dir.write("f.ice", "<iceFloeSim><frame index=\"0\">\n<object index=\"4\">" + c.object + "</object></frame></iceFloeSim>\n");
    const std::string text = refused(dir, "check " + (dir.path() / "s.toml").string());
    EXPECT_TRUE(holds(text, ice.string() + ":2:")) << text;
    EXPECT_TRUE(holds(text, "object 4")) << text;
    EXPECT_TRUE(holds(text, c.expected)) << text;
  }
  // Elements GEM does not read stay a reader's to ignore (the format's promise).
  dir.write("f.ice", "<iceFloeSim><frame index=\"0\"><object index=\"4\">" + square +
                         "<thickness>0.5</thickness><note>x</note></object></frame></iceFloeSim>\n");
  EXPECT_EQ(gem::test::runGem("check --quiet " + (dir.path() / "s.toml").string(), dir.path() / "log.txt"), 0)
      << gem::test::readFile(dir.path() / "log.txt");
}

// A sweep or case name past 200 characters was refused as if it held a bad character.
TEST(HostileCli, ANameTooLongSaysItsLengthAndTheLimit) {
  TempDir dir;
  dir.write("s.toml", gem::test::kTinyChannel);
  const std::string longName(300, 'a');
  const auto sweep = dir.write("study.toml", "[sweep]\nbase = \"s.toml\"\n[[cases]]\nname = \"" + longName + "\"\n");
  std::string text = refused(dir, "check " + sweep.string());
  EXPECT_TRUE(holds(text, "study.toml:4:")) << text;
  EXPECT_TRUE(holds(text, "300 characters; at most 200")) << text;
  EXPECT_FALSE(holds(text, "may hold letters")) << text;
  dir.write("study.toml", "[sweep]\nname = \"" + longName + "\"\nbase = \"s.toml\"\n[[cases]]\nname = \"a\"\n");
  text = refused(dir, "check " + sweep.string());
  EXPECT_TRUE(holds(text, "a sweep name of 300 characters")) << text;
  dir.write("study.toml", "[sweep]\nbase = \"s.toml\"\n[[cases]]\nname = \".hidden\"\n");
  EXPECT_TRUE(holds(refused(dir, "check " + sweep.string()), "may not start with '.' or '-'"));
}

// gem view on a run folder whose summary.json was damaged advised "the sweep runs that case again".
TEST(HostileCli, ViewOfADamagedSummaryGivesAViewersAdvice) {
  TempDir dir;
  const auto scenario = dir.write("s.toml", gem::test::kTinyChannel);
  const auto run = dir.path() / "run";
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() + " --quiet --no-plots --set output.frame_every=10 --out " + run.string(),
                              dir.path() / "log.txt"),
            0)
      << gem::test::readFile(dir.path() / "log.txt");
  dir.write("run/summary.json", "{\"completed\": tru");
  const std::string text = refused(dir, "view " + run.string());
  EXPECT_TRUE(holds(text, "summary.json: malformed JSON")) << text;
  EXPECT_FALSE(holds(text, "sweep")) << text;
}

// An error found after the tables are read (the field generator's checks) named the scenario file
// alone, with no line, also when a --set had made the value.
TEST(HostileCli, AFieldGeneratorsErrorNamesTheSetOrTheLine) {
  TempDir dir;
  const auto scenario = dir.write("s.toml", gem::test::kTinyChannel);
  std::string text = refused(dir, "check " + scenario.string() + " --set field.concentration=0.95");
  EXPECT_TRUE(holds(text, "--set field.concentration=0.95: field.concentration")) << text;
  text = refused(dir, "check " + scenario.string() + " --set field.size_min=50");
  EXPECT_TRUE(holds(text, "--set field.size_min=50: field.size_max")) << text;
  // From the file: its line and column (concentration is on line 13 of kTinyChannel).
  std::string channel = gem::test::kTinyChannel;
  channel.replace(channel.find("concentration = 0.3"), 19, "concentration = 0.95");
  dir.write("s.toml", channel);
  text = refused(dir, "check " + scenario.string());
  EXPECT_TRUE(holds(text, scenario.string() + ":13:")) << text;
  // An unknown table made by a --set names the --set, not the file.
  dir.write("s.toml", gem::test::kTinyChannel);
  text = refused(dir, "check " + scenario.string() + " --set bogus.b.c=1");
  EXPECT_TRUE(holds(text, "--set bogus.b.c=1: unknown key \"bogus\"")) << text;
}
