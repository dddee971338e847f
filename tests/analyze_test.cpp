// gem analyze (issue 5, item 5): synthetic run folders drawn from known distributions come back
// with their parameters in statistics.csv, every SVG is well-formed XML with something drawn,
// sweep folders group their cases by name prefix (thesis Figure 6.38), and folders without impacts
// are refused with an InputError naming the folder.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <sstream>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "framework/analysis/analyze.hpp"
#include "framework/api/errors.hpp"
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

// statistics.csv as group -> column -> text.
std::map<std::string, std::map<std::string, std::string>> readStatistics(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> header;
  for (std::stringstream s(line); std::getline(s, line, ',');) header.push_back(line);
  std::map<std::string, std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    const std::vector<std::string> cells = gem::test::csvCells(line);  // quoted names hold commas
    EXPECT_EQ(cells.size(), header.size()) << line;
    for (size_t i = 0; i < cells.size() && i < header.size(); ++i) rows[cells[0]][header[i]] = cells[i];
  }
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
  while (std::getline(bow, line)) {
    std::vector<std::string> c;
    std::stringstream s(line);
    for (std::string x; std::getline(s, x, ',');) c.push_back(x);
    ASSERT_EQ(c.size(), 5u);
    EXPECT_DOUBLE_EQ(num(c[2]) - num(c[1]), 1.0);
    EXPECT_DOUBLE_EQ(num(c[4]), num(c[3]));  // one run, 1 m bins
    total += std::stoi(c[3]);
    ++bins;
  }
  EXPECT_EQ(bins, 10);
  EXPECT_EQ(total, 600);
}

TEST(Analyze, SweepFolderGroupsCasesByNamePrefix) {
  TempDir tmp;
  // Thesis run names nnn_p: two runs of mix 121, one of mix 004 (Figure 6.38 groups).
  writeImpacts(tmp.path() / "cases" / "121_46", 100, 1, 0.0, 1.0);
  writeImpacts(tmp.path() / "cases" / "121_92", 140, 2, 0.0, 1.0);
  writeImpacts(tmp.path() / "cases" / "004_46", 60, 3, 0.0, 1.0);
  fs::create_directories(tmp.path() / "cases" / "004_92");  // not finished: skipped
  tmp.write("summary.csv", "name\n");
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);

  const fs::path out = tmp.path() / "analysis";
  for (const std::string& plot : kPlots) expectDrawnSvg(out / plot);
  EXPECT_FALSE(fs::exists(out / "force_vs_ship_speed.svg"));  // no timeseries.csv
  auto rows = readStatistics(out / "statistics.csv");
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows["121"]["runs"], "2");
  EXPECT_EQ(rows["121"]["impacts"], "240");
  EXPECT_EQ(rows["004"]["runs"], "1");
  EXPECT_EQ(rows["004"]["impacts"], "60");
  EXPECT_EQ(rows["all"]["runs"], "3");
  EXPECT_EQ(rows["all"]["impacts"], "300");
  // Every impact in [0, 1) m: one bin per group, normalised by the runs of the group.
  const std::string bow = gem::test::readFile(out / "across_bow.csv");
  EXPECT_NE(bow.find("121,0,1,240,120\n"), std::string::npos) << bow;
  EXPECT_NE(bow.find("004,0,1,60,60\n"), std::string::npos) << bow;
  EXPECT_NE(bow.find("all,0,1,300,100\n"), std::string::npos) << bow;
}

// A sweep's default case names hold commas ("r35,bollard_thrust=92000"): the group's name is
// quoted in statistics.csv, so the file still parses with one cell per column.
TEST(Analyze, GroupNamesWithCommasAreQuoted) {
  TempDir tmp;
  writeImpacts(tmp.path() / "cases" / "r35,bollard_thrust=92000", 40, 1, 0.0, 1.0);
  writeImpacts(tmp.path() / "cases" / "r40,bollard_thrust=92000", 30, 2, 0.0, 1.0);
  tmp.write("summary.csv", "name\n");
  ASSERT_EQ(runAnalyze(quietOptions(tmp.path())), 0);
  const std::string text = gem::test::readFile(tmp.path() / "analysis" / "statistics.csv");
  EXPECT_NE(text.find("\n\"r35,bollard\","), std::string::npos) << text;
  auto rows = readStatistics(tmp.path() / "analysis" / "statistics.csv");
  EXPECT_EQ(rows["r35,bollard"]["impacts"], "40");
}

TEST(Analyze, ChosenGroupsOnly) {
  TempDir tmp;
  writeImpacts(tmp.path() / "cases" / "121_46", 50, 1);
  writeImpacts(tmp.path() / "cases" / "004_46", 50, 2);
  writeImpacts(tmp.path() / "cases" / "400_46", 50, 3);
  AnalyzeOptions options = quietOptions(tmp.path());
  options.groups = {"121", "400"};
  runAnalyze(options);
  auto rows = readStatistics(tmp.path() / "analysis" / "statistics.csv");
  EXPECT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows.count("004"), 0u);
  EXPECT_EQ(rows["all"]["impacts"], "100");
  options.groups = {"999"};
  try {
    runAnalyze(options);
    FAIL() << "an unknown group must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("\"999\""), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("004"), std::string::npos) << e.what();  // lists the groups
  }
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
                                                        {"1,2,3,4,5,6,7,8,9,10,-1e9,12,13,14,15,0", "x_from_stem"}}) {
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

TEST(Analyze, CaseGroupIsTheNamePrefix) {
  EXPECT_EQ(caseGroup("121_370"), "121");
  EXPECT_EQ(caseGroup("004_46"), "004");
  EXPECT_EQ(caseGroup("plain"), "plain");
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
