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
  if (oneLine) {
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
  }
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

// The hostile audit of 2026-12-04's open classes, closed afterwards.

// A vessel the [domain] says can never reach the field (`vessel.position = [1e6, 0]` beside x = [0,
// 500]) was taken. The vessel sails forward along its heading (a 3-DOF one along the autopilot's set
// heading), so that line must come within the hull's reach of the domain, and with walls the vessel
// starts between them. Refused by gem run and gem check alike, naming the file, the key's line and
// column, the value and the domain; the legitimate starts are still taken.
TEST(HostileCli, AVesselThatCanNeverReachTheDomainIsRefused) {
  TempDir dir;
  const std::string head = "[simulation]\ndt = 0.1\nsteps = 3\n[domain]\nx = [0.0, 500.0]\ny = [-100.0, 100.0]\n";
  const std::string out = " --quiet --no-plots --out " + (dir.path() / "run").string();
  const struct {
    std::string vessel, expected;
  } refusedCases[] = {
      {"position = [1e6, 0.0]", "vessel.position: [1000000, 0], sailing at heading 0 deg"},        // past the field
      {"position = [-300.0, 0.0]\nheading_deg = 180.0", "[-300, 0], sailing at heading 180 deg"},  // facing away
      {"position = [100.0, 400.0]", "[100, 400], sailing at heading 0 deg"},                       // beside it
      {"position = [-60.0, 0.0]\nheading_deg = 90.0", "[-60, 0], sailing at heading 90 deg"},      // across, before it
      {"position = [1e6, 0.0]\ndof = 3\n[events.autopilot]\nheading_deg = 90.0", "heading 0 deg or the autopilot's 90 deg"},
  };
  for (const auto& c : refusedCases) {
    const auto scenario = dir.write("case.toml", head + "[vessel]\n" + c.vessel + "\n");
    for (const std::string command : {"run ", "check "}) {
      const std::string text = refused(dir, command + scenario.string() + (command == "run " ? out : ""));
      EXPECT_TRUE(holds(text, scenario.string() + ":8:12: vessel.position: ")) << text;
      EXPECT_TRUE(holds(text, c.expected)) << text;
      EXPECT_TRUE(holds(text, "[domain] x = [0, 500], y = [-100, 100]")) << text;
      EXPECT_TRUE(holds(text, "can never reach the field")) << text;
      EXPECT_FALSE(std::filesystem::exists(dir.path() / "run" / "summary.json")) << text;
    }
  }
  // With walls the vessel cannot cross one: outside the channel it is refused, even heading along it.
  auto scenario = dir.write("case.toml", head + "walls = true\n[vessel]\nposition = [-60.0, 140.0]\n");
  std::string text = refused(dir, "check " + scenario.string());
  EXPECT_TRUE(holds(text, "case.toml:9:12: vessel.position: [-60, 140] lies outside the channel between the walls")) << text;
  // A --set that moves it is named, and so is a sweep's case.
  scenario = dir.write("case.toml", head + "[vessel]\n");
  text = refused(dir, "check " + scenario.string() + " --set 'vessel.position=[2e3, 0.0]'");
  EXPECT_TRUE(holds(text, "--set vessel.position=[2e3, 0.0]: vessel.position: [2000, 0]")) << text;
  const auto sweep =
      dir.write("study.toml", "[sweep]\nbase = \"case.toml\"\n[parameters]\n\"vessel.position\" = [[-60.0, 0.0], [2e3, 0.0]]\n");
  text = refused(dir, "check " + sweep.string(), false);
  EXPECT_TRUE(holds(text, "study.toml:4:")) << text;
  EXPECT_TRUE(holds(text, "case 1")) << text;
  EXPECT_TRUE(holds(text, "[2000, 0], sailing at heading 0 deg")) << text;

  // Taken: before the field facing it (the thesis's start), in it, past it facing back, a 3-DOF
  // vessel whose autopilot turns it towards the field, no [domain] at all, and explicit floes
  // outside the domain (it bounds the generated field and the statistics, not the bodies).
  const std::string takenCases[] = {
      head + "[vessel]\n",
      head + "[vessel]\nposition = [250.0, 50.0]\nheading_deg = 135.0\n",
      head + "[vessel]\nposition = [1e6, 0.0]\nheading_deg = 180.0\n",
      head + "[vessel]\nposition = [-60.0, 0.0]\nheading_deg = 180.0\ndof = 3\n[events.autopilot]\nheading_deg = 0.0\n",
      head + "walls = true\n[vessel]\nposition = [-60.0, 90.0]\nbeam = 10.0\n",
      "[simulation]\ndt = 0.1\nsteps = 3\n[vessel]\nposition = [1e6, 0.0]\n",
      head + "[vessel]\n[[floes]]\nvertices = [[1e4, 1e4], [1.001e4, 1e4], [1.001e4, 1.001e4]]\n",
  };
  for (const std::string& toml : takenCases) {
    scenario = dir.write("case.toml", toml);
    EXPECT_EQ(gem::test::runGem("check --quiet " + scenario.string(), dir.path() / "log.txt"), 0)
        << toml << gem::test::readFile(dir.path() / "log.txt");
  }

  // A plugin's event may steer the vessel in ways the check cannot foresee: beside the field, the
  // vessel is taken while a plugin's event is enabled, and refused again once it is disabled.
  const std::string plugin = std::string("[[plugins]]\npath = \"") + GEM_TEST_PLUGIN_DIR + "/libold_layout.so\"\n";
  scenario = dir.write("case.toml", head + plugin + "[events.sideways_push]\naccel = 1.0\n[vessel]\nposition = [100.0, 400.0]\n");
  EXPECT_EQ(gem::test::runGem("check --quiet " + scenario.string(), dir.path() / "log.txt"), 0)
      << gem::test::readFile(dir.path() / "log.txt");
  scenario = dir.write("case.toml", head + plugin + "[events.sideways_push]\nenabled = false\n[vessel]\nposition = [100.0, 400.0]\n");
  text = refused(dir, "check " + scenario.string());
  EXPECT_TRUE(holds(text, "[100, 400], sailing at heading 0 deg")) << text;
}

// A .ice file holding more than its one document: a second root element after </iceFloeSim> (two
// files joined), text, CDATA, a second XML declaration or a doctype after it, or text before it,
// was taken (pugixml reads the first root and drops the rest, or keeps a second root beside it).
// Each is refused naming the file and the line and column where it starts; comments and processing
// instructions around the root are still taken, and a missing root or one of another name is refused.
TEST(HostileCli, AnIceFileWithContentOutsideItsRootIsRefused) {
  TempDir dir;
  const auto scenario = dir.write("s.toml", "[simulation]\ndt = 0.1\nsteps = 3\n[field]\nkind = \"file\"\nfile = \"f.ice\"\n");
  const std::string document =
      "<?xml version=\"1.0\"?>\n<iceFloeSim numFrames=\"1\"><frame index=\"0\">\n<object index=\"4\"><coordinates>80 0 82 0 82 2 80 2"
      "</coordinates><thickness>0.5</thickness></object></frame></iceFloeSim>\n";
  const struct {
    std::string before, after, place, expected;
  } cases[] = {
      {"", document, ":4:1:", "an XML declaration <?xml ...?> after the root element </iceFloeSim>"},  // two files joined
      {"", "<iceFloeSim/>\n", ":4:1:", "a second root element <iceFloeSim> after the root element </iceFloeSim>"},
      {"", "\n  <extra/>\n", ":5:3:", "a second root element <extra>"},
      {"", "junk\n", ":4:1:", "text 'junk' after the root element"},
      {"", "<!-- fine -->\n<![CDATA[x]]>\n", ":5:1:", "a CDATA section 'x' after the root element"},
      {"", "<!DOCTYPE iceFloeSim>\n", ":4:1:", "a <!DOCTYPE> after the root element"},
      {"lead\n", "", ":1:1:", "text 'lead' before the root element <iceFloeSim>"},
  };
  for (const auto& c : cases) {
    const auto ice = dir.write("f.ice", c.before + document + c.after);
    for (const std::string command : {"check ", "run "}) {
      const std::string text =
          refused(dir, command + scenario.string() + (command == "run " ? " --quiet --out " + (dir.path() / "run").string() : ""));
      EXPECT_TRUE(holds(text, ice.string() + c.place + " " + c.expected)) << text;
    }
  }
  // No root, or a root of another name.
  for (const std::string& text : {std::string(""), std::string("<!-- nothing -->\n"), std::string("<?xml version=\"1.0\"?>\n")}) {
    dir.write("f.ice", text);
    EXPECT_TRUE(holds(refused(dir, "check " + scenario.string()), "expected the root element <iceFloeSim>, found no element")) << text;
  }
  dir.write("f.ice", "<floes><frame index=\"0\"/></floes>\n");
  EXPECT_TRUE(holds(refused(dir, "check " + scenario.string()), "expected the root element <iceFloeSim>, found <floes>"));
  // Comments and processing instructions may stand around the root, as XML allows.
  dir.write("f.ice", "<!-- a -->\n" + document + "<!-- written by hand -->\n<?editor saved?>\n\n");
  EXPECT_EQ(gem::test::runGem("check --quiet " + scenario.string(), dir.path() / "log.txt"), 0)
      << gem::test::readFile(dir.path() / "log.txt");
}

// `--set simulation={dt=1}` replaced the whole [simulation] table (TOML's meaning of an inline
// table), dropping its other keys silently: here steps = 5 went, and the run took 600 s of steps. A
// table value now merges into the table there, key by key (as a sweep's set table does); an array,
// or any other value, still replaces the key's value whole.
TEST(HostileCli, ASetOfATableMergesIntoTheTableThere) {
  TempDir dir;
  const auto scenario = dir.write("s.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 5\nseed = 7\n[events.drag]\ncd = 0.2\n[events.wind]\nforce = 1.0\n"
                                  "[[floes]]\nvertices = [[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]]\n[output]\nframe_every = 0\n");
  const auto run = dir.path() / "run";
  const auto log = dir.path() / "log.txt";
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() +
                                  " --quiet --no-plots --set 'simulation={dt=0.2}' --set 'events={drag={linear=0.5}}' --set "
                                  "'floes=[{vertices=[[5.0, 0.0], [7.0, 0.0], [7.0, 2.0]]}]' --out " +
                                  run.string(),
                              log),
            0)
      << gem::test::readFile(log);
  const std::string recorded = gem::test::readFile(run / "scenario.toml");
  for (const char* kept : {"steps = 5", "seed = 7", "dt = 0.2", "cd = 0.2", "linear = 0.5", "force = 1.0", "[ 5.0, 0.0 ]"})
    EXPECT_TRUE(holds(recorded, kept)) << kept << " in\n" << recorded;
  EXPECT_FALSE(holds(recorded, "[ 2.0, 2.0 ]")) << "the array is replaced whole:\n" << recorded;
  EXPECT_TRUE(holds(gem::test::readFile(run / "summary.json"), "\"steps\": 5")) << gem::test::readFile(run / "summary.json");
  // A bad key or value inside the table is blamed on the --set.
  std::string text = refused(dir, "check " + scenario.string() + " --set 'simulation={dtt=1}'");
  EXPECT_TRUE(holds(text, "--set simulation={dtt=1}: unknown key \"simulation.dtt\"")) << text;
  text = refused(dir, "check " + scenario.string() + " --set 'simulation={dt=1e9}'");
  EXPECT_TRUE(holds(text, "--set simulation={dt=1e9}: simulation.dt: must be from 1e-06 to 3600")) << text;
}
