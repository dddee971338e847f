// gem analyze (issue 5, item 5): synthetic run folders drawn from known distributions come back
// with their parameters in statistics.csv, every SVG is well-formed XML with something drawn,
// sweep folders group their cases by the values of their varied keys read from each case's
// scenario.toml (thesis Figure 6.38), the tables stay valid CSV whatever the names hold, and
// folders without impacts are refused with an InputError naming the folder.
#include <gtest/gtest.h>

#include <tuple>

#include <cmath>
#include <map>
#include <random>
#include <sstream>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "framework/analysis/analyze.hpp"
#include "framework/api/errors.hpp"
#include "framework/output/csv.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;
namespace fs = std::filesystem;

namespace {

// The distributions the synthetic impacts are drawn from.
constexpr double kForceK = 1.4, kForceLambda = 2.0e5;  // Weibull fn [N]
constexpr double kApexK = 5.0, kApexLambda = 120.0;    // Weibull apex [deg]
constexpr double kMassMu = 10.0, kMassSigma = 0.8;     // lognormal floe mass [kg]

// An impacts.csv of n rows (each row its own floe), y_from_centerline uniform in [yLo, yHi).
void writeImpacts(const fs::path& dir, int n, unsigned seed, double yLo = -5.0, double yHi = 5.0) {
  fs::create_directories(dir);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> z(0.0, 1.0);
  std::ostringstream out;
  out << "t,floe_id,floe_mass,thickness,apex_deg,frame_angle_deg,x,y,nx,ny,x_from_stem,y_from_centerline,vn,fn,flim,broke\n";
  for (int i = 0; i < n; ++i) {
    const double fn = kForceLambda * std::pow(-std::log1p(-u(rng)), 1.0 / kForceK);
    const double apex = kApexLambda * std::pow(-std::log1p(-u(rng)), 1.0 / kApexK);
    const double mass = std::exp(kMassMu + kMassSigma * z(rng));
    const double xStem = 0.5 + 30.0 * u(rng), y = yLo + (yHi - yLo) * u(rng), vn = 0.2 + 2.0 * u(rng);
    out << fmt::format("{:.6g},{},{:.9g},0.7,{:.6g},10,{:.6g},{:.6g},0,1,{:.6g},{:.6g},{:.6g},{:.9g},inf,0\n", 0.1 * i, i, mass, apex,
                       xStem, y, xStem, y, vn, fn);
  }
  std::ofstream(dir / "impacts.csv") << out.str();
}

// A finished sweep case in cases/FOLDER: case.toml's header as gem sweep writes it (the name, and
// base/BASE.toml), its scenario.toml, and n impacts.
void writeCase(const fs::path& sweep, const std::string& folder, const std::string& name, const std::string& scenario, int n, unsigned seed,
               const std::string& base = "base") {
  const fs::path dir = sweep / "cases" / folder;
  writeImpacts(dir, n, seed, 0.0, 1.0);
  std::ofstream(dir / "case.toml") << "# Case \"" << name << "\" of the sweep /x/s.toml (gem sweep)\n# base: /x/" << base << ".toml\n\n"
                                   << scenario;
  std::ofstream(dir / "scenario.toml") << scenario;
}

// statistics.csv as group -> column -> text.
std::map<std::string, std::map<std::string, std::string>> readStatistics(const fs::path& file) {
  const CsvTable table = readCsvTable(file);  // quoted labels hold commas; a short row throws
  std::map<std::string, std::map<std::string, std::string>> rows;
  for (const std::vector<std::string>& cells : table.rows)
    for (size_t i = 0; i < cells.size(); ++i) rows[cells[0]][table.header[i]] = cells[i];
  return rows;
}

double num(const std::string& s) { return s.empty() ? NAN : std::stod(s); }

const std::vector<std::string> kPlots = {"force_cdf.svg",  "floe_mass_hist.svg",         "apex_hist.svg",
                                         "across_bow.svg", "force_vs_stem_distance.svg", "force_vs_speed.svg"};

void expectDrawnSvg(const fs::path& file) {
  pugi::xml_document doc;
  const pugi::xml_parse_result parsed = doc.load_file(file.c_str());
  ASSERT_TRUE(parsed) << file << ": " << parsed.description();
  EXPECT_STREQ(doc.document_element().name(), "svg") << file;
  EXPECT_FALSE(doc.select_nodes("//path | //circle").empty()) << file << " draws nothing";
}

AnalyzeOptions quietOptions(const fs::path& dir) {
  AnalyzeOptions o;
  o.dir = dir.string();
  o.quiet = true;
  return o;
}

}  // namespace

TEST(Analyze, RunFolderRecoversTheDistributions) {
  TempDir tmp;
  writeImpacts(tmp.path(), 600, 11);
  // A timeseries gives the ship speed at each impact (force against ship speed, Figure 6.36).
  tmp.write("timeseries.csv", "t,ship_speed\n0,1.0\n100,2.0\n");
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);

  const fs::path out = tmp.path() / "analysis";
  for (const std::string& plot : kPlots) expectDrawnSvg(out / plot);
  expectDrawnSvg(out / "force_vs_ship_speed.svg");
  auto rows = readStatistics(out / "statistics.csv");
  ASSERT_EQ(rows.size(), 1u);
  auto& all = rows.at("all");
  EXPECT_EQ(all["runs"], "1");
  EXPECT_EQ(all["impacts"], "600");
  EXPECT_EQ(all["struck_floes"], "600");
  // 600 samples: standard errors of a few per cent; the seed is fixed, the margins generous.
  EXPECT_NEAR(num(all["force_weibull_k"]), kForceK, 0.12 * kForceK);
  EXPECT_NEAR(num(all["force_weibull_lambda_n"]), kForceLambda, 0.08 * kForceLambda);
  EXPECT_NEAR(num(all["apex_weibull_k"]), kApexK, 0.12 * kApexK);
  EXPECT_NEAR(num(all["apex_weibull_lambda_deg"]), kApexLambda, 0.05 * kApexLambda);
  EXPECT_NEAR(num(all["mass_lognormal_mu"]), kMassMu, 0.1);
  EXPECT_NEAR(num(all["mass_lognormal_sigma"]), kMassSigma, 0.08 * kMassSigma);
  // Force is drawn independently of the speed and of the position: exponents near zero.
  EXPECT_NEAR(num(all["force_vs_vn_b"]), 0.0, 0.2);
  EXPECT_NEAR(num(all["force_vs_stem_b"]), 0.0, 0.2);
  EXPECT_FALSE(all["force_vs_ship_speed_b"].empty());
  EXPECT_GT(num(all["force_max_n"]), num(all["force_mean_n"]));

  // across_bow.csv: 1 m bins over [-5, 5) whose counts add up to the impacts.
  std::ifstream bow(out / "across_bow.csv");
  std::string line;
  std::getline(bow, line);
  EXPECT_EQ(line, "group,y_min_m,y_max_m,impacts,impacts_per_m_per_run");
  int bins = 0, total = 0;
  for (const std::vector<std::string>& c : readCsvTable(out / "across_bow.csv").rows) {
    ASSERT_EQ(c.size(), 5u);
    EXPECT_DOUBLE_EQ(num(c[2]) - num(c[1]), 1.0);
    EXPECT_DOUBLE_EQ(num(c[4]), num(c[3]));  // one run, 1 m bins
    total += std::stoi(c[3]);
    ++bins;
  }
  EXPECT_EQ(bins, 10);
  EXPECT_EQ(total, 600);
}

TEST(Analyze, SweepFolderGroupsCasesByVariedKeys) {
  TempDir tmp;
  // Two runs at 40 % (two thrusts), one at 10 %: the thrust does not group, the concentration does.
  // The names say nothing (the groups come from scenario.toml).
  writeCase(tmp.path(), "p", "p", "[field]\nconcentration = 0.4\n[vessel]\nbollard_thrust = 46e3\n", 100, 1);
  writeCase(tmp.path(), "q", "q", "[field]\nconcentration = 0.4\n[vessel]\nbollard_thrust = 92e3\n", 140, 2);
  writeCase(tmp.path(), "r", "r", "[field]\nconcentration = 0.1\n[vessel]\nbollard_thrust = 46e3\n", 60, 3);
  fs::create_directories(tmp.path() / "cases" / "s");  // not finished: skipped
  tmp.write("summary.csv", "name,field.concentration,vessel.bollard_thrust,impacts\n");
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);

  const fs::path out = tmp.path() / "analysis";
  for (const std::string& plot : kPlots) expectDrawnSvg(out / plot);
  EXPECT_FALSE(fs::exists(out / "force_vs_ship_speed.svg"));  // no timeseries.csv
  auto rows = readStatistics(out / "statistics.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows["concentration=0.4"]["runs"], "2");
  EXPECT_EQ(rows["concentration=0.4"]["impacts"], "240");
  EXPECT_EQ(rows["concentration=0.1"]["runs"], "1");
  EXPECT_EQ(rows["concentration=0.1"]["impacts"], "60");
  EXPECT_EQ(rows["all"]["runs"], "3");
  EXPECT_EQ(rows["all"]["impacts"], "300");
  // Every impact in [0, 1) m: one bin per group, normalised by the runs of the group.
  const std::string bow = gem::test::readFile(out / "across_bow.csv");
  EXPECT_NE(bow.find("concentration=0.4,0,1,240,120\n"), std::string::npos) << bow;
  EXPECT_NE(bow.find("concentration=0.1,0,1,60,60\n"), std::string::npos) << bow;
  EXPECT_NE(bow.find("all,0,1,300,100\n"), std::string::npos) << bow;
}

// Case names and group labels with commas, quotes and '=': statistics.csv still has one cell per
// column on every row, for GEM's reader and (when there is one) Python's csv module.
TEST(Analyze, NastyNamesAndLabelsGiveValidCsv) {
  TempDir tmp;
  writeCase(tmp.path(), "a", "r35,bollard_thrust=92000", "[field]\nnote = 'say \"hi\", x=1'\n[vessel]\nbollard_thrust = 92e3\n", 40, 1);
  writeCase(tmp.path(), "b", "r40,bollard_thrust=92000", "[field]\nnote = \"plain\"\n[vessel]\nbollard_thrust = 92e3\n", 30, 2);
  tmp.write("summary.csv", "name,field.note,vessel.bollard_thrust,impacts\n");
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);
  const fs::path file = tmp.path() / "analysis" / "statistics.csv";
  const CsvTable table = readCsvTable(file);
  ASSERT_EQ(table.rows.size(), 3u);
  for (const auto& row : table.rows) EXPECT_EQ(row.size(), table.header.size());
  auto rows = readStatistics(file);
  EXPECT_EQ(rows["note=say \"hi\", x=1"]["impacts"], "40");
  EXPECT_EQ(rows["note=plain"]["impacts"], "30");
  for (const char* name : {"statistics.csv", "across_bow.csv"}) {
    SCOPED_TRACE(name);
    const std::string path = (tmp.path() / "analysis" / name).string();
    if (std::system("command -v python3 > /dev/null 2>&1") != 0) {
      std::printf("[  SKIPPED ] python3 is not on PATH: %s not checked with Python's csv module\n", name);
      continue;
    }
    const std::string command =
        "python3 -c 'import csv,sys; r=list(csv.reader(open(sys.argv[1], newline=\"\"))); "
        "sys.exit(0 if len(r) > 1 and all(len(x) == len(r[0]) for x in r) else 1)' " +
        path;
    EXPECT_EQ(std::system(command.c_str()), 0) << gem::test::readFile(path);
  }
}

TEST(Analyze, ChosenGroupsOnly) {
  TempDir tmp;
  writeCase(tmp.path(), "c121", "121_46", "[field]\nconcentration = 0.4\n", 50, 1);
  writeCase(tmp.path(), "c004", "004_46", "[field]\nconcentration = 0.1\n", 50, 2);
  writeCase(tmp.path(), "c400", "400_46", "[field]\nconcentration = 0.2\n", 50, 3);
  tmp.write("summary.csv", "name,field.concentration,impacts\n");
  AnalyzeOptions options = quietOptions(tmp.path());
  options.groups = {"concentration=0.4", "400_46"};  // a label, and a group by one of its cases
  runAnalyze(options);
  auto rows = readStatistics(tmp.path() / "analysis" / "statistics.csv");
  EXPECT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows.count("concentration=0.1"), 0u);
  EXPECT_EQ(rows.count("concentration=0.2"), 1u);
  EXPECT_EQ(rows["all"]["impacts"], "100");
  options.groups = {"999"};
  try {
    runAnalyze(options);
    FAIL() << "an unknown group must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"999\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("concentration=0.1"), std::string::npos) << e.what();  // lists the groups
  }
}

// Without varied keys (no summary.csv, or one that names none) a sweep's cases are one group.
TEST(Analyze, SweepWithoutVariedKeysIsOneGroup) {
  TempDir tmp;
  writeImpacts(tmp.path() / "cases" / "121_46", 20, 1);
  writeImpacts(tmp.path() / "cases" / "004_46", 30, 2);
  runAnalyze(quietOptions(tmp.path()));
  auto rows = readStatistics(tmp.path() / "analysis" / "statistics.csv");
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows["all"]["impacts"], "50");
}

// The resistance analysis reads each case's concentration and thrust from its scenario.toml: a case
// named without its concentration still has one, and a scenario without one gives an empty cell.
TEST(Analyze, ResistanceReadsInputsFromTheScenario) {
  TempDir tmp;
  writeCase(tmp.path(), "a", "first,bollard_thrust=46000", "[field]\nconcentration = 0.35\n[vessel]\nbollard_thrust = 46e3\n", 5, 1, "f1");
  writeCase(tmp.path(), "b", "first,bollard_thrust=92000", "[field]\nconcentration = 0.35\n[vessel]\nbollard_thrust = 92e3\n", 5, 2, "f1");
  writeCase(tmp.path(), "c", "field_99,bollard_thrust=46000", "[vessel]\nbollard_thrust = 46e3\n", 5, 3, "f2");
  tmp.write("summary.csv",
            "name,vessel.bollard_thrust,impacts,ship_speed_in_ice_mean,resistance_in_ice_mean\n"
            "\"first,bollard_thrust=46000\",46000,5,1.5,20000\n"
            "\"first,bollard_thrust=92000\",92000,5,2.5,40000\n"
            "\"field_99,bollard_thrust=46000\",46000,5,1.0,30000\n");
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);
  const CsvTable table = readCsvTable(tmp.path() / "analysis" / "resistance.csv");
  ASSERT_EQ(table.rows.size(), 3u);
  EXPECT_EQ(table.rows[0], (std::vector<std::string>{"f1", "0.35", "46000", "1.5", "20000"}));
  EXPECT_EQ(table.rows[1], (std::vector<std::string>{"f1", "0.35", "92000", "2.5", "40000"}));
  EXPECT_EQ(table.rows[2], (std::vector<std::string>{"f2", "", "46000", "1", "30000"}));  // not "nan", not 0.99
}

TEST(Analyze, RunWithoutImpactsGivesEmptyFitsAndValidPlots) {
  TempDir tmp;
  writeImpacts(tmp.path(), 0, 1);
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);
  auto rows = readStatistics(tmp.path() / "analysis" / "statistics.csv");
  EXPECT_EQ(rows["all"]["impacts"], "0");
  EXPECT_EQ(rows["all"]["force_weibull_k"], "");  // no fit: an empty cell, not nan
  for (const std::string& plot : kPlots) {
    pugi::xml_document doc;
    EXPECT_TRUE(doc.load_file((tmp.path() / "analysis" / plot).c_str())) << plot;
  }
}

TEST(Analyze, FolderWithoutImpactsIsAnInputError) {
  TempDir tmp;
  fs::create_directories(tmp.path() / "cases" / "a_1");
  try {
    runAnalyze(quietOptions(tmp.path()));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(tmp.path().string()), std::string::npos) << e.what();
  }
  EXPECT_THROW(runAnalyze(quietOptions(tmp.path() / "missing")), InputError);
}

TEST(Analyze, MalformedImpactsNameFileAndLine) {
  TempDir tmp;
  writeImpacts(tmp.path(), 3, 1);
  std::ofstream(tmp.path() / "impacts.csv", std::ios::app) << "1,2,3,4,5,6,7,8,9,10,11,12,13,oops,inf,0\n";
  try {
    runAnalyze(quietOptions(tmp.path()));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("impacts.csv:5"), std::string::npos) << what;
    EXPECT_NE(what.find("fn"), std::string::npos) << what;
  }
}

// Values GEM never writes (found by fuzzing: an apex of 12,345,455 deg made a 150 MB histogram
// and took seconds) are refused with the file, line and column, not plotted.
TEST(Analyze, ValuesOutsideTheirColumnsRangeNameFileAndLine) {
  for (const auto& [row, column] :
       std::vector<std::pair<std::string, std::string>>{{"1,2,3,4,1780,6,7,8,9,10,11,12,13,14,15,0", "apex_deg"},
                                                        {"1,2,3,4,5,6,7,8,9,10,11,1e300,13,14,15,0", "y_from_centerline"},
                                                        {"1,2,3,4,5,6,7,8,9,10,-1e9,12,13,14,15,0", "x_from_stem"},
                                                        {"1,2,3,4,5,6,7,8,9,10,11,12,13,-1e308,15,0", "fn"},
                                                        {"1,2,3,4,5,6,7,8,9,10,11,12,13,nan,15,0", "fn"},
                                                        {"1,2,3,4,5,6,7,8,9,10,11,12,inf,14,15,0", "vn"},
                                                        {"1e308,2,3,4,5,6,7,8,9,10,11,12,13,14,15,0", "t"},
                                                        // ids are whole numbers from 0, masses positive (hostile-input audit)
                                                        {"1,4.5,3,4,5,6,7,8,9,10,11,12,13,14,15,0", "floe_id"},
                                                        {"1,-99999999999999999999,3,4,5,6,7,8,9,10,11,12,13,14,15,0", "floe_id"},
                                                        {"1,2,0,4,5,6,7,8,9,10,11,12,13,14,15,0", "floe_mass"}}) {
    SCOPED_TRACE(column);
    TempDir tmp;
    writeImpacts(tmp.path(), 3, 1);
    std::ofstream(tmp.path() / "impacts.csv", std::ios::app) << row << "\n";
    try {
      runAnalyze(quietOptions(tmp.path()));
      ADD_FAILURE() << "expected an InputError";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("impacts.csv:5"), std::string::npos) << what;
      EXPECT_NE(what.find(column), std::string::npos) << what;
    }
  }
}

// gem view and gem plot read the run's CSVs with the same checks as gem analyze: a NaN force or a
// broke flag of 7 is refused naming the file, line and column, not drawn (gem view once wrote
// the NaN into its page with exit 0).
TEST(Analyze, ViewAndPlotRefuseWhatAnalyzeRefuses) {
  TempDir tmp;
  const auto scenario = tmp.write("busy.toml", gem::test::kBusyScene);
  const auto run = tmp.path() / "run";
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() + " --steps 20 --quiet --no-plots --out " + run.string(), tmp.path() / "run.log"),
            0)
      << gem::test::readFile(tmp.path() / "run.log");
  const std::string impacts = gem::test::readFile(run / "impacts.csv");
  for (const auto& [row, column, command] :
       std::vector<std::tuple<std::string, std::string, std::string>>{{"1,2,3,4,5,6,7,8,9,10,11,12,13,nan,15,0", "fn", "view"},
                                                                      {"-1e300,2,3,4,5,6,7,8,9,10,11,12,13,14,15,0", "t", "view"},
                                                                      {"1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,7", "broke", "plot"},
                                                                      {"1,4.5,3,4,5,6,7,8,9,10,11,12,13,14,15,0", "floe_id", "analyze"}}) {
    SCOPED_TRACE(command + " " + column);
    std::ofstream(run / "impacts.csv") << impacts << row << "\n";
    const auto log = tmp.path() / "log";
    const std::string out = command == "view" ? " --out " + (tmp.path() / "v.html").string() : "";
    EXPECT_EQ(gem::test::runGem(command + " " + run.string() + out + " --quiet", log), 2) << gem::test::readFile(log);
    const std::string text = gem::test::readFile(log);
    EXPECT_NE(text.find("impacts.csv:"), std::string::npos) << text;
    EXPECT_NE(text.find("column " + column), std::string::npos) << text;
  }
}

TEST(Analyze, CommandLineExitStatus) {
  TempDir tmp;
  writeImpacts(tmp.path() / "run", 20, 4);
  EXPECT_EQ(gem::test::runGem("analyze --quiet " + (tmp.path() / "run").string(), tmp.path() / "log"), 0)
      << gem::test::readFile(tmp.path() / "log");
  EXPECT_EQ(gem::test::runGem("analyze " + (tmp.path() / "nothing").string(), tmp.path() / "log"), 2);
}

TEST(Analyze, StemContactsAreLeftOutOfTheStemDistanceFit) {
  // fn = 1e4 x^-0.5 exactly, plus contacts at the stem tip (x rounding to 1e-14 m) that would
  // dominate a log-log fit: the fit must come back exact.
  TempDir tmp;
  std::string csv = "t,floe_id,floe_mass,thickness,apex_deg,frame_angle_deg,x,y,nx,ny,x_from_stem,y_from_centerline,vn,fn,flim,broke\n";
  for (int i = 1; i <= 30; ++i)
    csv += fmt::format("{},{},1e4,0.7,120,10,0,0,1,0,{},0.5,1,{:.17g},inf,0\n", i, i, double(i), 1e4 / std::sqrt(double(i)));
  for (int i = 0; i < 3; ++i) csv += fmt::format("{},{},1e4,0.7,120,10,0,0,1,0,1e-14,0.5,1,5e5,inf,0\n", 40 + i, 40 + i);
  tmp.write("impacts.csv", csv);
  runAnalyze(quietOptions(tmp.path()));
  auto rows = readStatistics(tmp.path() / "analysis" / "statistics.csv");
  EXPECT_NEAR(num(rows["all"]["force_vs_stem_b"]), -0.5, 1e-5);
  EXPECT_NEAR(num(rows["all"]["force_vs_stem_a"]), 1e4, 1e-1);
  EXPECT_EQ(rows["all"]["impacts"], "33");
}
