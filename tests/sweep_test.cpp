// gem sweep (issue 5, item 1): expansion of a sweep file into cases, the run folders and their
// scenarios, resume, --case-index, the gathered summary.csv, bad sweep files and failing cases.
#include <gtest/gtest.h>

#include <fstream>
#include <functional>
#include <sstream>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "framework/api/errors.hpp"
#include "framework/app/runner.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"
#include "framework/app/sweep.hpp"
#include "framework/scenario/sweep_file.hpp"
#include "framework/analysis/sweep_summary.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;
namespace fs = std::filesystem;

namespace {

// A run with no progress line and no closing summary (the other options as a run has them).
RunOptions quietRun() {
  RunOptions options;
  options.quiet = true;
  return options;
}

const char* const kBase = test::kTinyChannel;

const char* const kProduct = test::kProductSweep;

std::vector<std::string> lines(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> out;
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

using test::csvCells;

int sweep(const fs::path& file, const fs::path& out, int jobs = 2, long caseIndex = -1) {
  SweepOptions o;
  o.sweepFile = file.string();
  o.outDir = out.string();
  o.jobs = jobs;
  o.caseIndex = caseIndex;
  o.quiet = true;
  return runSweep(o);
}

const std::string kHeaderTail =
    "impacts,ship_speed_min,ship_speed_mean,ship_speed_max,impact_force_min,impact_force_mean,impact_force_max,"
    "resistance_mean,wall_time_s,ship_speed_in_ice_mean,resistance_in_ice_mean,impacts_in_ice,impact_force_in_ice_mean";

}  // namespace

TEST(SweepFile, ProductExpandsFirstParameterSlowest) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const SweepDefinition def = readSweepFile(dir.write("study.toml", kProduct));
  EXPECT_EQ(def.name, "study");
  EXPECT_EQ(def.columns, (std::vector<std::string>{"vessel.bollard_thrust", "field.concentration"}));
  ASSERT_EQ(def.cases.size(), 4u);
  EXPECT_EQ(def.cases[0].name, "bollard_thrust=46000,concentration=0.25");
  EXPECT_EQ(def.cases[1].name, "bollard_thrust=46000,concentration=0.3");
  EXPECT_EQ(def.cases[2].name, "bollard_thrust=92000,concentration=0.25");
  EXPECT_EQ(def.cases[3].name, "bollard_thrust=92000,concentration=0.3");
  EXPECT_EQ(sweepCell(def.cases[2], "vessel.bollard_thrust"), "92000");
  EXPECT_EQ(sweepCell(def.cases[2], "simulation.steps"), "");  // sweep.set is common, not a column
  ASSERT_EQ(def.cases[3].overrides.size(), 3u);
  EXPECT_EQ(def.cases[3].overrides[0].key, "simulation.steps");
  EXPECT_EQ(def.cases[3].overrides[0].toml, "30");  // integers stay integers
  EXPECT_EQ(def.cases[3].base, fs::absolute(dir.path() / "base.toml").lexically_normal());
}

// Parameter values of thousands of characters make names the file system cannot hold as folders:
// each case's folder is cut short (and still unique), its name kept whole.
TEST(SweepFile, LongParameterValuesGiveShortUniqueFolders) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const std::string a(3000, 'a'), b = std::string(2999, 'a') + "b";
  const SweepDefinition def = readSweepFile(
      dir.write("long.toml", "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"output.movie_title\" = [\"" + a + "\", \"" + b + "\"]\n"));
  ASSERT_EQ(def.cases.size(), 2u);
  EXPECT_GT(def.cases[0].name.size(), 3000u);
  EXPECT_LE(def.cases[0].folder.size(), 125u);
  EXPECT_LE(def.cases[1].folder.size(), 125u);
  EXPECT_NE(def.cases[0].folder, def.cases[1].folder);
}

TEST(SweepFile, CasesTimesParametersAndNonScalarValues) {
  TempDir dir;
  dir.write("base.toml", kBase);
  dir.write("other.toml", kBase);
  const SweepDefinition def = readSweepFile(dir.write("s.toml", R"([sweep]
name = "mix"
base = "base.toml"
[parameters]
"events.wind.force" = [1.0, 2.0]
"events.current.force" = [0.5]
"field.groups" = [[{ coverage = 0.1, thickness = 1.2 }], [{ coverage = 0.2, thickness = 0.5 }]]
[[cases]]
name = "001_46"
set = { "vessel.bollard_thrust" = 46e3 }
[[cases]]
name = "b"
base = "other.toml"
)"));
  EXPECT_EQ(def.name, "mix");
  ASSERT_EQ(def.cases.size(), 8u);
  // Two parameters end in "force": their full keys name them.
  EXPECT_EQ(def.cases[0].name, "001_46,events.wind.force=1,events.current.force=0.5,groups#0");
  EXPECT_EQ(def.cases[7].name, "b,events.wind.force=2,events.current.force=0.5,groups#1");
  EXPECT_EQ(def.cases[7].base.filename(), "other.toml");
  EXPECT_EQ(def.columns.back(), "vessel.bollard_thrust");
  EXPECT_EQ(sweepCell(def.cases[0], "vessel.bollard_thrust"), "46000");
  EXPECT_EQ(sweepCell(def.cases[7], "vessel.bollard_thrust"), "");
}

TEST(Sweep, RunsEveryCaseWritesScenariosAndGathers) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct);
  const fs::path out = dir.path() / "out";
  ASSERT_EQ(sweep(file, out), 0);

  const fs::path caseDir = out / "cases" / "bollard_thrust-46000_concentration-0.3";
  ASSERT_TRUE(fs::exists(caseDir / "summary.json"));
  // The case as the sweep wrote it (case.toml) is the whole base with its overrides, and runs where
  // it lies; the run's own record (scenario.toml) repeats it.
  const toml::table written = toml::parse_file((caseDir / "case.toml").string());
  EXPECT_EQ(written["vessel"]["bollard_thrust"].value<double>(), 46e3);
  EXPECT_EQ(written["field"]["concentration"].value<double>(), 0.3);
  EXPECT_EQ(written["simulation"]["steps"].value<int64_t>(), 30);
  EXPECT_EQ(written["vessel"]["mass"].value<double>(), 5e5);
  EXPECT_EQ(loadScenario(caseDir / "case.toml").output.dir.lexically_normal(), fs::absolute(caseDir).lexically_normal() / "");
  const Scenario reloaded = loadScenario(caseDir / "scenario.toml");
  EXPECT_TRUE(fs::equivalent(reloaded.output.dir, caseDir));
  EXPECT_EQ(reloaded.steps, 30);

  const std::vector<std::string> csv = lines(out / "summary.csv");
  ASSERT_EQ(csv.size(), 5u);
  EXPECT_EQ(csv[0], "name,vessel.bollard_thrust,field.concentration," + kHeaderTail);
  const std::vector<std::string> row = csvCells(csv[2]);
  ASSERT_EQ(row.size(), 16u);
  EXPECT_EQ(row[0], "bollard_thrust=46000,concentration=0.3");
  EXPECT_EQ(row[1], "46000");
  EXPECT_EQ(row[2], "0.3");
  const auto summary = readSummaryJson(caseDir / "summary.json");
  EXPECT_EQ(row[3], summary.at("impacts"));
  EXPECT_EQ(row[5], summary.at("ship_speed.mean"));
  EXPECT_EQ(row[10], summary.at("resistance_mean_n"));
  EXPECT_GT(std::stod(row[10]), 0);  // the ice slows the vessel: a positive mean net thrust
  EXPECT_EQ(row[13], summary.at("resistance_in_ice_n"));
  EXPECT_EQ(row[14], summary.at("impacts_in_ice"));
}

TEST(Sweep, ThreadsDoNotChangeResults) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct);
  ASSERT_EQ(sweep(file, dir.path() / "one", 1), 0);
  ASSERT_EQ(sweep(file, dir.path() / "four", 4), 0);
  const auto a = lines(dir.path() / "one" / "summary.csv"), b = lines(dir.path() / "four" / "summary.csv");
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    auto ca = csvCells(a[i]), cb = csvCells(b[i]);
    ca.erase(ca.begin() + 11), cb.erase(cb.begin() + 11);  // wall_time_s differs
    EXPECT_EQ(ca, cb);
  }
}

TEST(Sweep, ResumeRunsOnlyIncompleteOrChangedCases) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct);
  const fs::path out = dir.path() / "out";
  ASSERT_EQ(sweep(file, out), 0);
  std::vector<fs::path> summaries;
  for (const auto& entry : fs::directory_iterator(out / "cases")) summaries.push_back(entry.path() / "summary.json");
  std::sort(summaries.begin(), summaries.end());
  ASSERT_EQ(summaries.size(), 4u);
  std::vector<fs::file_time_type> times;
  for (const auto& s : summaries) times.push_back(fs::last_write_time(s));
  fs::remove(summaries[1]);
  fs::remove(out / "summary.csv");
  // A case a signal stopped (its summary says "completed": false) is not complete either.
  std::string stopped = test::readFile(summaries[2]);
  ASSERT_NE(stopped.find("\"completed\": true"), std::string::npos) << stopped;
  stopped.replace(stopped.find("\"completed\": true"), 17, "\"completed\": false");
  dir.write(fs::relative(summaries[2], dir.path()).string(), stopped);
  times[2] = fs::last_write_time(summaries[2]);

  ASSERT_EQ(sweep(file, out), 0);
  EXPECT_EQ(readSummaryJson(summaries[2]).at("completed"), "true");
  for (size_t i = 0; i < summaries.size(); ++i) {
    ASSERT_TRUE(fs::exists(summaries[i]));
    if (i != 1 && i != 2) {
      EXPECT_EQ(fs::last_write_time(summaries[i]), times[i]) << summaries[i] << " ran again";
    }
  }
  EXPECT_EQ(lines(out / "summary.csv").size(), 5u);

  // A changed sweep makes the complete cases stale: they run again with the new scenario.
  std::string text = kProduct;
  text.replace(text.find("= 30"), 4, "= 31");
  dir.write("study.toml", text);
  ASSERT_EQ(sweep(file, out), 0);
  for (const auto& s : summaries) EXPECT_EQ(readSummaryJson(s).at("steps"), "31");
}

// gem sweep takes --set and --backend as gem run does, for every case (after the sweep's own keys).
TEST(Sweep, SetAndBackendApplyToEveryCase) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct);
  const fs::path out = dir.path() / "out", log = dir.path() / "log.txt";
  ASSERT_EQ(test::runGem("sweep " + file.string() + " --out " + out.string() + " --quiet --backend cpu --set simulation.steps=3", log), 0)
      << test::readFile(log);
  int cases = 0;
  for (const auto& entry : fs::directory_iterator(out / "cases")) {
    ++cases;
    const std::string summary = test::readFile(entry.path() / "summary.json");
    EXPECT_NE(summary.find("\"steps\": 3,"), std::string::npos) << entry.path() << ": " << summary;
    EXPECT_NE(summary.find("\"backend\": \"cpu\""), std::string::npos) << summary;
  }
  EXPECT_EQ(cases, 4);
  EXPECT_EQ(test::runGem("sweep " + file.string() + " --out " + out.string() + " --set simulation.dtt=0.1", log), 2);
  EXPECT_NE(test::readFile(log).find("did you mean \"dt\""), std::string::npos) << test::readFile(log);
}

TEST(Sweep, CaseIndexRunsExactlyOne) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct);
  const fs::path out = dir.path() / "out", log = dir.path() / "log.txt";
  ASSERT_EQ(test::runGem("sweep " + file.string() + " --out " + out.string() + " --case-index 2", log), 0) << test::readFile(log);
  EXPECT_NE(test::readFile(log).find("bollard_thrust=92000,concentration=0.25"), std::string::npos);
  int complete = 0;
  for (const auto& entry : fs::directory_iterator(out / "cases")) complete += fs::exists(entry.path() / "summary.json");
  EXPECT_EQ(complete, 1);
  EXPECT_TRUE(fs::exists(out / "cases" / "bollard_thrust-92000_concentration-0.25" / "summary.json"));
  // Unlike gem run, a sweep's case makes no plots: they would slow a large sweep for figures
  // nobody looks at case by case (gem plot draws one when wanted).
  EXPECT_FALSE(fs::exists(out / "cases" / "bollard_thrust-92000_concentration-0.25" / "plots"));
  EXPECT_EQ(lines(out / "summary.csv").size(), 2u);
  EXPECT_EQ(test::runGem("sweep " + file.string() + " --out " + out.string() + " --case-index 4", log), 2);
}

TEST(Sweep, DefaultFolderIsBesideTheSweepFile) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", R"([sweep]
name = "named"
base = "base.toml"
[[cases]]
name = "only"
set = { "simulation.steps" = 5 }
)");
  ASSERT_EQ(sweep(file, ""), 0);
  EXPECT_TRUE(fs::exists(dir.path() / "runs" / "named" / "cases" / "only" / "summary.json"));
  EXPECT_EQ(lines(dir.path() / "runs" / "named" / "summary.csv")[0], "name,simulation.steps," + kHeaderTail);
}

TEST(Sweep, FieldFileStaysValidInTheCaseScenario) {
  TempDir dir;
  // A .ice field beside a base in a sub-folder: the case's scenario.toml must still find it.
  fs::create_directories(dir.path() / "fields");
  {
    Scenario s = loadScenario(dir.write("gen.toml", kBase), {"simulation.steps=1", "output.frame_every=1", "output.formats=[\"ice\"]"});
    s.output.dir = dir.path() / "gen";
    runScenario(s, quietRun());
  }
  fs::copy_file(dir.path() / "gen" / "frames.ice", dir.path() / "fields" / "pack.ice");
  dir.write("fields/base.toml",
            "[simulation]\ndt = 0.1\nsteps = 5\n[field]\nkind = \"file\"\nfile = \"pack.ice\"\n"
            "[vessel]\nlength = 30.0\nbeam = 8.0\nmass = 5e5\nposition = [-16.0, 0.0]\n[output]\nframe_every = 0\n");
  const fs::path file = dir.write("s.toml", "[sweep]\nbase = \"fields/base.toml\"\n[[cases]]\nname = \"a\"\n");
  ASSERT_EQ(sweep(file, dir.path() / "out"), 0);
  const fs::path scenario = dir.path() / "out" / "cases" / "a" / "scenario.toml";
  const toml::table written = toml::parse_file(scenario.string());
  EXPECT_EQ(fs::path(*written["field"]["file"].value<std::string>()), (dir.path() / "fields" / "pack.ice").lexically_normal());
  EXPECT_NO_THROW(loadScenario(scenario));
}

// Three cases; "bad" loads a test plugin whose event throws at step 5: input that every check
// passes (a sweep checks one step of each case before any runs), a case that fails while running.
const std::string kCasesOneFailsWhileRunning = std::string(R"([[cases]]
name = "good"
[[cases]]
name = "bad"
set = { plugins = [{ path = ")") + GEM_TEST_PLUGIN_DIR +
                                               R"(/libfail_midway.so" }], "events.fail_midway.at_step" = 5 }
[[cases]]
name = "also_good"
set = { "vessel.bollard_thrust" = 46e3 }
)";

TEST(Sweep, FailingCaseExitsOneAndOthersAreGathered) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write(
      "study.toml", std::string("[sweep]\nbase = \"base.toml\"\nset = { \"simulation.steps\" = 10 }\n") + kCasesOneFailsWhileRunning);
  const fs::path out = dir.path() / "out", log = dir.path() / "log.txt";
  ASSERT_EQ(test::runGem("sweep " + file.string() + " --out " + out.string() + " --jobs 2", log), 1);
  EXPECT_NE(test::readFile(log).find("case bad failed"), std::string::npos) << test::readFile(log);
  const auto csv = lines(out / "summary.csv");
  ASSERT_EQ(csv.size(), 3u);
  EXPECT_EQ(csvCells(csv[1])[0], "good");
  EXPECT_EQ(csvCells(csv[2])[0], "also_good");
  EXPECT_FALSE(fs::exists(out / "cases" / "bad" / "summary.json"));
}

TEST(SweepSummary, ReadsGemJson) {
  TempDir dir;
  const auto s = readSummaryJson(dir.write("summary.json", R"({"steps": 3, "backend": "cpu", "ship_speed": {"min": 1.5, "mean": null},
 "list": [1, {"a": 2}], "ok": true})"));
  EXPECT_EQ(s.at("steps"), "3");
  EXPECT_EQ(s.at("backend"), "cpu");
  EXPECT_EQ(s.at("ship_speed.min"), "1.5");
  EXPECT_EQ(s.at("ship_speed.mean"), "");
  EXPECT_EQ(s.at("ok"), "true");
  // Escapes read as JSON says (a device name may hold any character).
  const auto escaped = readSummaryJson(dir.write("escaped.json", R"({"device": "A\u00e9\r\"b\"", "n": 1e3})"));
  EXPECT_EQ(escaped.at("device"), "A\u00e9\r\"b\"");
  EXPECT_EQ(std::stod(escaped.at("n")), 1000.0);
  EXPECT_THROW(readSummaryJson(dir.write("bad.json", "{\"a\": }")), InputError);  // bad input: exit 2
  EXPECT_THROW(readSummaryJson(dir.write("empty.json", "")), InputError);
  // A value of summary.csv that is not a number: not GEM's summary (it once reached the CSV).
  try {
    readSummaryJson(dir.write("tampered.json", R"({"completed": true, "impacts": "lots"})"));
    ADD_FAILURE() << "\"impacts\": \"lots\" was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"impacts\" is \"lots\", not a number"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readSummaryJson(dir.write("nested.json", R"({"ship_speed": {"min": [1]}})")), InputError);
  // Nested 50,000 deep (a damaged file in a sweep being resumed): refused, not a stack overflow.
  std::string deep = "{\"a\": ";
  for (int k = 0; k < 50000; ++k) deep += "{\"a\": ";
  deep += "1" + std::string(50001, '}');
  try {
    readSummaryJson(dir.write("deep.json", deep));
    ADD_FAILURE() << "a summary nested 50,000 deep was read";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nested more than 64 deep"), std::string::npos) << e.what();
  }
}

// Bad sweep files: exit 2 through the real binary, naming the sweep file's line and column.
struct BadSweep {
  const char* name;
  std::string toml;
  std::vector<std::string> expected;
};
void PrintTo(const BadSweep& b, std::ostream* os) { *os << b.name; }

class SweepBadInput : public ::testing::TestWithParam<BadSweep> {};

// gem check of the sweep file refuses each with the same words as gem sweep.
TEST_P(SweepBadInput, ExitsTwoNamingTheLine) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("bad_sweep.toml", GetParam().toml), log = dir.path() / "log.txt";
  for (const std::string command : {"sweep", "check"}) {
    SCOPED_TRACE(command);
    EXPECT_EQ(test::runGem(command + " " + file.string() + (command == "sweep" ? " --out " + (dir.path() / "out").string() : ""), log), 2);
    const std::string message = test::readFile(log);
    for (const std::string& e : GetParam().expected)
      EXPECT_NE(message.find(e), std::string::npos) << "missing \"" << e << "\" in: " << message;
    EXPECT_FALSE(fs::exists(dir.path() / "out" / "cases"));  // nothing ran
  }
}

INSTANTIATE_TEST_SUITE_P(
    SweepFiles, SweepBadInput,
    ::testing::Values(
        BadSweep{"missing_base",
                 "[sweep]\nname = \"x\"\n[parameters]\n\"vessel.bollard_thrust\" = [1.0]\n",
                 {"bad_sweep.toml:1:1", "sweep.base: missing"}},
        BadSweep{"no_such_base",
                 "[sweep]\nbase = \"nope.toml\"\n[parameters]\n\"vessel.bollard_thrust\" = [1.0]\n",
                 {"bad_sweep.toml:2:8", "nope.toml"}},
        // A base that is there but no file is named for what it is ("no such scenario file" once).
        BadSweep{"base_is_a_folder",
                 "[sweep]\nbase = \".\"\n[parameters]\n\"vessel.bollard_thrust\" = [1.0]\n",
                 {"bad_sweep.toml:2:8", "a folder, not a scenario file"}},
        BadSweep{"base_is_a_device",
                 "[sweep]\nbase = \"/dev/null\"\n[parameters]\n\"vessel.bollard_thrust\" = [1.0]\n",
                 {"bad_sweep.toml:2:8", "/dev/null: not a regular file"}},
        BadSweep{"unknown_sweep_key",
                 "[sweep]\nbase = \"base.toml\"\njobs = 3\n[parameters]\n\"vessel.bollard_thrust\" = [1.0]\n",
                 {"bad_sweep.toml:3:", "sweep.jobs"}},
        BadSweep{"unknown_top_key",
                 "[sweep]\nbase = \"base.toml\"\n[parameter]\n\"vessel.bollard_thrust\" = [1.0]\n",
                 {"bad_sweep.toml:3:", "parameter"}},
        BadSweep{
            "empty_list", "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"vessel.bollard_thrust\" = []\n", {"bad_sweep.toml:4:", "empty"}},
        BadSweep{"not_a_list",
                 "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"vessel.bollard_thrust\" = 5.0\n",
                 {"bad_sweep.toml:4:", "expected a list"}},
        BadSweep{"typo_in_varied_key",
                 "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"field.concentration\" = [0.2]\n\"vessel.bolard_thrust\" = [1.0, 2.0]\n",
                 {"bad_sweep.toml:5:", "vessel.bolard_thrust", "unknown key"}},
        BadSweep{"value_out_of_range",
                 "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"field.concentration\" = [0.2, -0.1]\n",
                 {"bad_sweep.toml:4:", "case 1", "must be positive"}},
        BadSweep{
            "bad_case_set",
            "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n[[cases]]\nname = \"b\"\nset = { \"simulation.dt\" = \"fast\" }\n",
            {"bad_sweep.toml:7:", "case 1 \"b\"", "simulation.dt"}},
        BadSweep{
            "unknown_key_in_a_case",
            "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n[[cases]]\nname = \"b\"\nset = { \"vessel.bolard_thrust\" = 1.0 }\n",
            {"bad_sweep.toml:7:", "case 1 \"b\"", "vessel.bolard_thrust", "unknown key"}},
        // An event's table is read when the case's world is built: gem sweep once ran the others
        // and failed this case (exit 1); gem check once refused the file's [sweep] table.
        BadSweep{"unknown_event_key_in_a_case",
                 "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n[[cases]]\nname = \"b\"\nset = { \"events.drag.cdd\" = 0.1 }\n",
                 {"bad_sweep.toml:7:", "case 1 \"b\"", "events.drag.cdd", "did you mean \"cd\""}},
        // The second position puts the hull on the floe every case has: refused before any case
        // runs, naming the parameter's line, where gem sweep once ran case 0 and failed case 1.
        BadSweep{"parameter_puts_the_vessel_on_a_floe",
                 "[sweep]\nbase = \"base.toml\"\nset = { floes = [{ vertices = [[-60.0, -2.0], [-50.0, -2.0], [-50.0, 2.0], [-60.0, "
                 "2.0]] }] }\n[parameters]\n\"vessel.position\" = [[-16.0, 0.0], [-55.0, 0.0]]\n",
                 {"bad_sweep.toml:5:", ": case 1 \"position#1\": vessel.position = [ -55.0, 0.0 ]: ", "bodies overlap at the start",
                  "and vessel"}},
        BadSweep{"case_without_name",
                 "[sweep]\nbase = \"base.toml\"\n[[cases]]\nset = { \"simulation.dt\" = 0.05 }\n",
                 {"bad_sweep.toml:3:", "name"}},
        BadSweep{"duplicate_case",
                 "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n[[cases]]\nname = \"a\"\n",
                 {"bad_sweep.toml:5:", "two cases"}},
        BadSweep{"unsafe_case_name", "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"../x\"\n", {"bad_sweep.toml:4:", "name"}},
        BadSweep{"nothing_to_run", "[sweep]\nbase = \"base.toml\"\n", {"bad_sweep.toml", "[parameters]"}},
        BadSweep{"toml_syntax", "[sweep]\nbase = \"base.toml\"\n[parameters]\nx = [1\n", {"bad_sweep.toml:4:"}},
        BadSweep{"a_billion_cases",
                 std::string("[sweep]\nbase = \"base.toml\"\n[parameters]\n") +
                     [] {
                       std::string lists;
                       for (const char* key : {"\"simulation.dt\"", "\"simulation.seed\"", "\"vessel.bollard_thrust\""}) {
                         lists += std::string(key) + " = [";
                         for (int k = 1; k <= 1000; ++k) lists.append(k > 1 ? ", " : "").append(std::to_string(k)).append(".0");
                         lists += "]\n";
                       }
                       return lists;
                     }(),
                 {"bad_sweep.toml:4:", "1000000000 cases", "at most 100000"}},
        // Each [[cases]] entry runs every combination of [parameters]: 400 x 400 cases, each
        // part under the cap, once made 160,000 cases (10^6 of them grew past 7 GB).
        BadSweep{"cases_times_parameters",
                 std::string("[sweep]\nbase = \"base.toml\"\n[parameters]\n\"simulation.seed\" = [") +
                     [] {
                       std::string seeds;
                       for (int k = 0; k < 400; ++k) seeds.append(k ? "," : "").append(std::to_string(k));
                       return seeds;
                     }() +
                     "]\n" +
                     [] {
                       std::string cases;
                       for (int k = 0; k < 400; ++k) cases.append("[[cases]]\nname = \"c").append(std::to_string(k)).append("\"\n");
                       return cases;
                     }(),
                 {"bad_sweep.toml:5:", "400 x 400 = 160000 cases", "at most 100000"}},
        BadSweep{"varied_in_set_and_parameters",
                 "[sweep]\nbase = \"base.toml\"\n[parameters]\n\"vessel.bollard_thrust\" = [1.0]\n[[cases]]\nname = \"a\"\nset = { "
                 "vessel.bollard_thrust = 2.0 }\n",
                 {"bad_sweep.toml:7:", "also varied"}}),
    [](const auto& info) { return std::string(info.param.name); });

// A case's override that the scenario refuses is named once, at its line in the sweep file: the
// message once also quoted it as a command-line "--set KEY=VALUE" and repeated its key. An
// override given to gem sweep itself is named as its --set.
TEST(SweepMessages, AnOverrideIsNamedOnceAtItsLine) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file =
      dir.write("study.toml", "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\nset = { \"vessel.mass\" = \"heavy\" }\n");
  const fs::path log = dir.path() / "log.txt";
  EXPECT_EQ(test::runGem("check " + file.string(), log), 2);
  const std::string message = test::readFile(log);
  EXPECT_NE(message.find("study.toml:5:25: case 0 \"a\": vessel.mass = 'heavy': expected a number"), std::string::npos) << message;
  EXPECT_EQ(message.find("--set"), std::string::npos) << message;
  dir.write("study.toml", "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n");
  EXPECT_EQ(test::runGem("check " + file.string() + " --set vessel.mass=-5", log), 2);
  const std::string fromTheCommandLine = test::readFile(log);
  EXPECT_NE(fromTheCommandLine.find("case 0 \"a\": --set vessel.mass=-5: must be"), std::string::npos) << fromTheCommandLine;
  EXPECT_EQ(fromTheCommandLine.find("vessel.mass: "), std::string::npos) << fromTheCommandLine;
}

// gem check takes a sweep file (one with a top-level [sweep] table; it once refused "sweep" as an
// unknown scenario key): every case loaded as gem sweep loads it, then built and stepped once as
// gem check does a scenario. It writes nothing and names the cases and the base.
TEST(SweepCheck, AValidSweepPassesNamingItsCasesAndBase) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct), log = dir.path() / "log.txt";
  ASSERT_EQ(test::runGem("check " + file.string(), log), 0) << test::readFile(log);
  EXPECT_EQ(test::readFile(log), file.string() + ": ok (4 cases; base base.toml)\n");
  ASSERT_EQ(test::runGem("check --quiet " + file.string(), log), 0) << test::readFile(log);
  EXPECT_EQ(test::readFile(log), "");
  EXPECT_FALSE(fs::exists(dir.path() / "runs"));  // no sweep folder
  const std::string thesis = std::string(GEM_SOURCE_DIR) + "/scenarios/thesis/";
  ASSERT_EQ(test::runGem("check " + thesis + "load_study.toml", log), 0) << test::readFile(log);
  EXPECT_EQ(test::readFile(log), thesis + "load_study.toml: ok (70 cases; base load_study_field.toml)\n");
  ASSERT_EQ(test::runGem("check " + thesis + "resistance_study.toml", log), 0) << test::readFile(log);
  EXPECT_EQ(test::readFile(log),
            thesis + "resistance_study.toml: ok (40 cases; 8 bases: random_35.toml, random_39.toml, random_41.toml, ...)\n");
}

// gem check SWEEP takes gem sweep's options: --set and --backend reach every case (an overlap that
// --set makes is blamed on it); --steps and the others gem sweep lacks are refused by name.
TEST(SweepCheck, TakesTheOptionsOfGemSweep) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path file = dir.write("study.toml", kProduct), log = dir.path() / "log.txt";
  EXPECT_EQ(test::runGem("check " + file.string() + " --set simulation.dtt=0.05", log), 2);
  EXPECT_NE(test::readFile(log).find("simulation.dtt"), std::string::npos) << test::readFile(log);
  // The base's floes lie in x = 0 to 60: a hull at x = 30 is on one of them.
  EXPECT_EQ(test::runGem("check " + file.string() + " --set 'vessel.position=[30.0, 0.0]'", log), 2);
  EXPECT_NE(test::readFile(log).find("study.toml: case 0 \"bollard_thrust=46000,concentration=0.25\": --set vessel.position=[30.0, 0.0]: "),
            std::string::npos)
      << test::readFile(log);
  EXPECT_NE(test::readFile(log).find("bodies overlap at the start"), std::string::npos) << test::readFile(log);
  EXPECT_EQ(test::runGem("check " + file.string() + " --backend cpu", log), 0) << test::readFile(log);
  for (const char* option : {"--steps 5", "--duration 3", "--threads 2", "--broadphase all_pairs"}) {
    EXPECT_EQ(test::runGem("check " + file.string() + " " + option, log), 2) << option;
    EXPECT_NE(test::readFile(log).find(std::string("not ") + std::string(option).substr(0, std::string(option).find(' '))),
              std::string::npos)
        << test::readFile(log);
  }
}

namespace {

// A stand-in for a device backend that runs cases together in one state (CUDA's
// CudaStepper::together needs a GPU; its own tests run there): CPU simulations registered under
// "cuda" while the test runs, each checking that the cases of its batch are stepped in lockstep.
struct Batch {
  std::vector<Stepper*> members;
  bool outOfStep = false;
};

class LockstepStepper final : public Stepper {
 public:
  LockstepStepper(const Scenario& s, std::shared_ptr<Batch> batch) : m_sim(s), m_batch(std::move(batch)) {}
  void step() override {
    // Every case's step k before any case's step k + 1: no case is behind this one.
    for (Stepper* other : m_batch->members)
      if (other->stepIndex() < m_sim.stepIndex()) m_batch->outOfStep = true;
    m_sim.step();
  }
  long stepIndex() const override { return m_sim.stepIndex(); }
  Real time() const override { return m_sim.time(); }
  const World& hostWorld() override { return m_sim.hostWorld(); }
  VesselSample vessel() override { return m_sim.vessel(); }
  const StepRecords& records() const override { return m_sim.records(); }
  int contactCount() const override { return m_sim.contactCount(); }
  Vec2 vesselIceForce() const override { return m_sim.vesselIceForce(); }
  double rubbleMass() const override { return m_sim.rubbleMass(); }
  long floesBroken() const override { return m_sim.floesBroken(); }
  std::string device() const override { return m_sim.device(); }
  std::string backend() const override { return m_sim.backend(); }

 private:
  CpuStepper m_sim;
  std::shared_ptr<Batch> m_batch;
};

struct TogetherBackend {
  std::vector<std::shared_ptr<Batch>> batches;
  bool refuse = false;                   // makeTogether throws BackendUnsupported, as CUDA's does for a state too full
  std::function<void()> beforeTogether;  // called as makeTogether starts
  const BackendEntry* previous;
  BackendEntry saved;
  TogetherBackend() : previous(findBackend("cuda")) {
    if (previous) saved = *previous;
    registerBackend(BackendEntry{"cuda", [] { return true; }, [] { return std::string("stand-in"); },
                                 [](const Scenario& s) -> std::unique_ptr<Stepper> { return std::make_unique<CpuStepper>(s); }, nullptr,
                                 [](const Scenario& s) { return "steps=" + std::to_string(s.steps); },
                                 [this](const std::vector<const Scenario*>& scenarios) {
                                   if (beforeTogether) beforeTogether();
                                   if (refuse) throw BackendUnsupported("these cases cannot share a state");
                                   auto batch = std::make_shared<Batch>();
                                   std::vector<std::unique_ptr<Stepper>> steppers;
                                   for (const Scenario* s : scenarios) {
                                     steppers.push_back(std::make_unique<LockstepStepper>(*s, batch));
                                     batch->members.push_back(steppers.back().get());
                                   }
                                   batches.push_back(batch);
                                   return steppers;
                                 },
                                 [] { return 1; }});
  }
  ~TogetherBackend() {
    // Put back what was there (the real CUDA backend in a CUDA build), or one that is never available.
    if (previous)
      registerBackend(saved);
    else {
      BackendEntry none;
      none.name = "cuda";
      none.available = [] { return false; };
      none.deviceName = [] { return std::string("none"); };
      registerBackend(none);
    }
  }
};

}  // namespace

// Cases that a device backend runs together (one state, stepped in lockstep by
// runScenariosTogether) must write what single runs write; --batch caps a state's cases and
// --batch 1 runs each alone.
TEST(Sweep, CasesRunTogetherWriteTheOutputsOfSingleRuns) {
  TempDir dir;
  dir.write("base.toml", kBase);
  // Frames too: a device state's cases write theirs from the shared state.
  std::string withFrames = kProduct;
  withFrames.replace(withFrames.find("set = {"), 7, "set = { \"output.frame_every\" = 10, \"output.formats\" = [\"ice\"], ");
  const fs::path cpu = dir.write("cpu.toml", withFrames);
  std::string together = withFrames;
  together.replace(together.find("set = {"), 7, "set = { \"simulation.backend\" = \"cuda\", ");
  const fs::path file = dir.write("together.toml", together);
  ASSERT_EQ(sweep(cpu, dir.path() / "cpu"), 0);
  TogetherBackend backend;
  auto run = [&](const std::string& name, int batch) {
    SweepOptions o;
    o.sweepFile = file.string();
    o.outDir = (dir.path() / name).string();
    o.jobs = 2;
    o.batch = batch;
    o.quiet = true;
    return runSweep(o);
  };
  ASSERT_EQ(run("all", 0), 0);
  ASSERT_EQ(backend.batches.size(), 1u);
  EXPECT_EQ(backend.batches[0]->members.size(), 4u);
  ASSERT_EQ(run("pairs", 2), 0);
  ASSERT_EQ(backend.batches.size(), 3u);
  EXPECT_EQ(backend.batches[1]->members.size(), 2u);
  ASSERT_EQ(run("alone", 1), 0);
  EXPECT_EQ(backend.batches.size(), 3u);  // no case ran together with another
  backend.refuse = true;                  // the backend turns the group down: its cases run one at a time
  ASSERT_EQ(run("refused", 0), 0);
  EXPECT_EQ(backend.batches.size(), 3u);
  for (const auto& batch : backend.batches) EXPECT_FALSE(batch->outOfStep);

  for (const auto& entry : fs::directory_iterator(dir.path() / "cpu" / "cases")) {
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    EXPECT_FALSE(test::readFile(entry.path() / "frames.ice").empty());
    for (const char* run : {"all", "pairs", "alone", "refused"})
      for (const char* file : {"timeseries.csv", "impacts.csv", "state.csv", "frames.ice"})
        EXPECT_EQ(test::readFile(entry.path() / file), test::readFile(dir.path() / run / "cases" / name / file)) << run << " " << file;
    EXPECT_EQ(readSummaryJson(dir.path() / "all" / "cases" / name / "summary.json").at("cases_on_device"), "4");
    EXPECT_EQ(readSummaryJson(dir.path() / "pairs" / "cases" / name / "summary.json").at("cases_on_device"), "2");
    EXPECT_EQ(readSummaryJson(dir.path() / "alone" / "cases" / name / "summary.json").at("cases_on_device"), "1");
    EXPECT_EQ(readSummaryJson(dir.path() / "refused" / "cases" / name / "summary.json").at("cases_on_device"), "1");
  }
}

// A case whose world cannot be built when its unit runs (its field file changed after the sweep
// checked every case), in a unit of cases that run together, fails alone as it would in a run of
// its own: the others still run together and are gathered (a device sweep once failed the whole
// unit with that one case's message).
TEST(Sweep, ACaseThatCannotBeBuiltFailsAloneAndTheOthersStillRunTogether) {
  TempDir dir;
  dir.write("base.toml", kBase);
  auto writeField = [&](double x0, double x1) {
    dir.write("pack.ice",
              fmt::format("<iceFloeSim numFrames=\"1\">\n<frame index=\"0\" time=\"0\">\n<object index=\"0\"><coordinates>{0} -2 "
                          "{1} -2 {1} 2 {0} 2</coordinates><thickness>1</thickness></object>\n</frame>\n</iceFloeSim>\n",
                          x0, x1));
  };
  writeField(30, 40);  // clear of the vessel, which reaches from x = -31 to -1
  dir.write("file_base.toml",
            "[simulation]\ndt = 0.1\nsteps = 40\n[field]\nkind = \"file\"\nfile = \"pack.ice\"\n"
            "[vessel]\nlength = 30.0\nbeam = 8.0\nmass = 5e5\nposition = [-16.0, 0.0]\n[output]\nframe_every = 0\n");
  const fs::path file = dir.write("study.toml",
                                  "[sweep]\nbase = \"base.toml\"\nset = { \"simulation.steps\" = 10, \"simulation.backend\" = \"cuda\" }\n"
                                  "[[cases]]\nname = \"good\"\n[[cases]]\nname = \"bad\"\nbase = \"file_base.toml\"\n"
                                  "[[cases]]\nname = \"also_good\"\nset = { \"vessel.bollard_thrust\" = 46e3 }\n");
  TogetherBackend backend;
  backend.beforeTogether = [&] { writeField(-20, -10); };  // now on the vessel
  SweepOptions o;
  o.sweepFile = file.string();
  o.outDir = (dir.path() / "out").string();
  o.jobs = 1;
  o.quiet = true;
  EXPECT_EQ(runSweep(o), 1);
  ASSERT_EQ(backend.batches.size(), 1u);
  EXPECT_EQ(backend.batches[0]->members.size(), 2u);
  EXPECT_FALSE(backend.batches[0]->outOfStep);
  const auto csv = lines(dir.path() / "out" / "summary.csv");
  ASSERT_EQ(csv.size(), 3u);
  EXPECT_EQ(csvCells(csv[1])[0], "good");
  EXPECT_EQ(csvCells(csv[2])[0], "also_good");
  EXPECT_FALSE(fs::exists(dir.path() / "out" / "cases" / "bad" / "summary.json"));
  EXPECT_EQ(readSummaryJson(dir.path() / "out" / "cases" / "good" / "summary.json").at("cases_on_device"), "2");
}
