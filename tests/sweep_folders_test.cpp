// Sweep case folders (names safe for shells and tools, unique) and gem analyze on a real sweep,
// grouping by the varied keys read from each case's scenario.toml.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <map>
#include <set>

#include "framework/analysis/analyze.hpp"
#include "framework/app/sweep.hpp"
#include "framework/output/csv.hpp"
#include "framework/scenario/sweep_file.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;
namespace fs = std::filesystem;

namespace {

const char* const kBase = test::kTinyChannel;

const char* const kProduct = test::kProductSweep;

int sweep(const fs::path& file, const fs::path& out) {
  SweepOptions o;
  o.sweepFile = file.string();
  o.outDir = out.string();
  o.jobs = 2;
  o.quiet = true;
  return runSweep(o);
}

}  // namespace

// A case keeps its name (summary.csv's row label) but its folder holds only [A-Za-z0-9._-]: no
// comma or '=' for a shell or a tool that splits on them; two cases never share a folder.
TEST(SweepFile, CaseFoldersAreSafeAndUnique) {
  EXPECT_EQ(caseFolderName("bollard_thrust=46000,concentration=0.25"), "bollard_thrust-46000_concentration-0.25");
  EXPECT_EQ(caseFolderName("groups#0,x=1e+06"), "groups-0_x-1e06");
  EXPECT_EQ(caseFolderName("=a"), "_-a");
  EXPECT_EQ(caseFolderName("@"), "_");
  TempDir dir;
  dir.write("base.toml", kBase);
  // "a,b" and "a_b" would both be folder a_b; "a_b_2" would be the clash's suffix.
  const SweepDefinition def = readSweepFile(dir.write("s.toml", R"([sweep]
base = "base.toml"
[[cases]]
name = "a,b"
[[cases]]
name = "a_b"
[[cases]]
name = "a_b_2"
[[cases]]
name = "x=1,y=2"
)"));
  ASSERT_EQ(def.cases.size(), 4u);
  std::set<std::string> folders;
  for (const SweepCase& c : def.cases) {
    EXPECT_TRUE(folders.insert(c.folder).second) << c.folder;
    EXPECT_EQ(c.folder.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789._-"), std::string::npos)
        << c.folder;
  }
  EXPECT_EQ(def.cases[0].folder, "a_b");
  EXPECT_EQ(def.cases[1].folder, "a_b_2");
  EXPECT_EQ(def.cases[2].folder, "a_b_2_2");
  EXPECT_EQ(def.cases[3].folder, "x-1_y-2");
  EXPECT_EQ(def.cases[3].name, "x=1,y=2");
}

// gem analyze on a real sweep of 2 concentrations x 2 thrusts: one group per concentration (the
// thrust does not group), each of its two cases; the inputs come from the cases' scenario.toml.
// A case folder whose summary.json or case.toml is a folder, a pipe or a link that loops is refused
// before any case runs (exit 2, naming it), not removed, re-run or failed after the run.
TEST(Sweep, ACaseFolderHoldingNoFileWhereItsSummaryGoesIsRefusedBeforeAnyCaseRuns) {
  for (const std::string name : {"summary.json", "case.toml"})
    for (const std::string kind : {"folder", "fifo", "loop"}) {
      SCOPED_TRACE(::testing::Message() << name << " as a " << kind);
      TempDir dir;
      dir.write("base.toml", kBase);
      const fs::path file = dir.write("study.toml", kProduct), out = dir.path() / "out";
      const fs::path caseDir = out / "cases" / "bollard_thrust-46000_concentration-0.25";
      fs::create_directories(caseDir);
      const fs::path place = caseDir / name;
      if (kind == "folder") fs::create_directories(place / "keep");
      if (kind == "fifo") {
        ASSERT_EQ(::mkfifo(place.c_str(), 0600), 0);
      }
      if (kind == "loop") fs::create_symlink(name, place);
      const auto log = dir.path() / "log";
      EXPECT_EQ(test::runGem("sweep " + file.string() + " --out " + out.string() + " --quiet", log), 2) << test::readFile(log);
      const std::string text = test::readFile(log);
      EXPECT_NE(text.find(place.string()), std::string::npos) << text;
      EXPECT_FALSE(fs::exists(out / "summary.csv"));       // nothing ran
      EXPECT_TRUE(fs::exists(fs::symlink_status(place)));  // left as it was
    }
}

TEST(Sweep, AnalyzeGroupsByTheVariedKeysButNotTheThrust) {
  TempDir dir;
  dir.write("base.toml", kBase);
  const fs::path out = dir.path() / "out";
  // kProduct with a small light vessel that is wholly in the field within the 30 steps: the in-ice
  // means of the resistance analysis.
  std::string product = kProduct;
  product.replace(product.find("set = {"), 7,
                  "set = { \"vessel.length\" = 4.0, \"vessel.beam\" = 2.0, \"vessel.mass\" = 2e4, \"vessel.position\" = [-2.5, 0.0],");
  ASSERT_EQ(sweep(dir.write("study.toml", product), out), 0);
  AnalyzeOptions options;
  options.dir = out.string();
  options.quiet = true;
  ASSERT_EQ(runAnalyze(options), 0);
  const CsvTable stats = readCsvTable(out / "analysis" / "statistics.csv");
  std::map<std::string, std::string> runs;
  for (const auto& row : stats.rows) runs[row[0]] = row[size_t(stats.column("runs"))];
  EXPECT_EQ(runs, (std::map<std::string, std::string>{{"all", "4"}, {"concentration=0.25", "2"}, {"concentration=0.3", "2"}}));
  // It varies the thrust and summary.csv has the in-ice means: the resistance analysis too, with
  // the concentration of each case from its scenario.
  const CsvTable resistance = readCsvTable(out / "analysis" / "resistance.csv");
  ASSERT_EQ(resistance.rows.size(), 4u);
  for (const auto& row : resistance.rows) EXPECT_EQ(row[0], "concentration=" + row[1]);
}
