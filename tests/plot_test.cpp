// gem plot (issue "The user's day", item 2): a run folder's time series and impact loads as SVG and
// PNG from one drawing; gem run makes them unless --no-plots, and a re-run removes the old ones.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include <fmt/format.h>
#include <pugixml.hpp>

#include "framework/analysis/svg_plot.hpp"
#include "framework/output/run_folder.hpp"
#include "picture_support.hpp"

using namespace gem;
using gem::test::TempDir;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kSeries = {"ship_speed", "net_thrust", "ice_force", "contacts"};
const std::vector<std::string> kImpactPlots = {"impact_force_hist", "impact_positions", "impact_force_vs_time"};

// NAME.svg is SVG with something drawn; NAME.png is an 800 x 520 picture, mostly white, showing
// the series' colour.
void expectPlot(const fs::path& plots, const std::string& name, std::uint32_t seriesColor) {
  pugi::xml_document doc;
  const fs::path svg = plots / (name + ".svg");
  ASSERT_TRUE(doc.load_file(svg.c_str())) << svg;
  EXPECT_STREQ(doc.document_element().name(), "svg") << svg;
  EXPECT_FALSE(doc.select_nodes("//path | //circle").empty()) << svg << " draws nothing";
  const std::string hex = fmt::format("#{:06X}", seriesColor);
  const std::string query = "//*[@stroke='" + hex + "' or @fill='" + hex + "']";
  EXPECT_TRUE(doc.select_node(query.c_str())) << svg << " has no element in the series colour " << hex;

  const test::Picture png = test::readPng(plots / (name + ".png"));
  ASSERT_EQ(png.width, 800) << name;
  ASSERT_EQ(png.height, 520) << name;
  const long pixels = long(png.argb.size());
  EXPECT_GT(png.count(0xFFFFFF), pixels / 2) << name << ": the background is white";
  EXPECT_GT(png.count(seriesColor, 40), 40) << name << ": the series' colour is not drawn";
  EXPECT_GT(png.count(0x000000, 60), 500) << name << ": no axes or labels";
}

}  // namespace

TEST(Plot, RunFolderGetsTimeSeriesAndImpactPlots) {
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  EXPECT_FALSE(fs::exists(run / "plots")) << "--no-plots made plots";
  ASSERT_EQ(test::runGem("plot " + run.string(), dir.path() / "plot.log"), 0) << test::readFile(dir.path() / "plot.log");
  const std::string log = test::readFile(dir.path() / "plot.log");
  for (const std::string& name : kSeries) EXPECT_NE(log.find(name + ".png"), std::string::npos) << log;
  expectPlot(run / "plots", "ship_speed", 0x0072B2);
  expectPlot(run / "plots", "net_thrust", 0xD55E00);
  expectPlot(run / "plots", "ice_force", 0x009E73);
  expectPlot(run / "plots", "contacts", 0xCC79A7);
  expectPlot(run / "plots", "impact_force_hist", 0x0072B2);
  expectPlot(run / "plots", "impact_positions", 0x0072B2);
  expectPlot(run / "plots", "impact_force_vs_time", 0x009E73);
  // Every file gem plot writes is one a re-run removes.
  size_t listed = 0;
  for (const auto& entry : fs::directory_iterator(run / "plots")) {
    const std::string stem = entry.path().stem().string();
    EXPECT_NE(std::find(std::begin(kRunPlotNames), std::end(kRunPlotNames), stem), std::end(kRunPlotNames)) << entry.path();
    ++listed;
  }
  EXPECT_EQ(listed, 2 * std::size(kRunPlotNames));
}

TEST(Plot, RunMakesPlotsUnlessNoPlotsAndAReRunRemovesThem) {
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir, "");
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  for (const std::string& name : kSeries) EXPECT_TRUE(fs::exists(run / "plots" / (name + ".png"))) << name;
  for (const std::string& name : kImpactPlots) EXPECT_TRUE(fs::exists(run / "plots" / (name + ".svg"))) << name;
  // The same folder again without plots: the old ones must not describe the new run.
  ASSERT_FALSE(test::makeBusyRun(dir, "--no-plots").empty()) << test::readFile(dir.path() / "run.log");
  EXPECT_FALSE(fs::exists(run / "plots")) << "a re-run with --no-plots left the earlier run's plots";
}

TEST(Plot, RunWithoutImpactsGetsItsTimeSeriesAndANote) {
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  std::string header;
  std::getline(std::ifstream(run / "impacts.csv"), header);
  std::ofstream(run / "impacts.csv") << header << "\n";  // the header alone: no impact logged
  ASSERT_EQ(test::runGem("plot " + run.string(), dir.path() / "plot.log"), 0) << test::readFile(dir.path() / "plot.log");
  for (const std::string& name : kSeries) EXPECT_TRUE(fs::exists(run / "plots" / (name + ".png"))) << name;
  for (const std::string& name : kImpactPlots) EXPECT_FALSE(fs::exists(run / "plots" / (name + ".png"))) << name;
  EXPECT_NE(test::readFile(dir.path() / "plot.log").find("no impacts"), std::string::npos) << test::readFile(dir.path() / "plot.log");
}

TEST(Plot, AFolderThatIsNoRunIsRefusedByName) {
  TempDir dir;
  const fs::path empty = dir.path() / "not-a-run";
  fs::create_directories(empty);
  EXPECT_EQ(test::runGem("plot " + empty.string(), dir.path() / "plot.log"), 2);
  EXPECT_NE(test::readFile(dir.path() / "plot.log").find(empty.string()), std::string::npos) << test::readFile(dir.path() / "plot.log");
  EXPECT_FALSE(fs::exists(empty / "plots"));
}

TEST(Plot, SvgAndPngComeFromOneDrawing) {
  // A plot with a single red line: both outputs show it, at the size asked for.
  TempDir dir;
  SvgPlot plot("one line", "x", "y");
  plot.addLine("line", {0, 1, 2, 3}, {0, 1, 0, 1}, "#FF0000");
  plot.writeSvgAndPng(dir.path() / "one");
  const std::string svg = test::readFile(dir.path() / "one.svg");
  EXPECT_NE(svg.find("stroke=\"#FF0000\""), std::string::npos) << svg;
  EXPECT_NE(svg.find(">one line</text>"), std::string::npos) << svg;
  const test::Picture png = test::readPng(dir.path() / "one.png");
  ASSERT_EQ(png.width, 800);
  EXPECT_GT(png.count(0xFF0000, 30), 300);  // a 1.6 px zigzag across the plot area
  EXPECT_EQ(png.count(0x00FF00, 60), 0);    // and nothing it was not asked to draw
}

TEST(Plot, LongSeriesAreReducedKeepingTheirSpikes) {
  // A long run's time series: 10^5 rows, one spike, one gap.
  std::vector<double> t, v;
  for (int i = 0; i < 100000; ++i)
    t.push_back(0.1 * i), v.push_back(i == 31415 ? 50.0 : i >= 60000 && i < 60010 ? NAN : std::sin(i * 1e-3));
  envelopeLine(t, v, 4000);
  EXPECT_LE(t.size(), 4000u);
  EXPECT_GE(t.size(), 3000u);
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
  EXPECT_EQ(*std::max_element(v.begin(), v.end()), 50.0);
  EXPECT_NE(std::find(t.begin(), t.end(), 0.1 * 31415), t.end());
  // Scatter points: every k-th, at most the number asked for.
  std::vector<double> x(12001, 1.0), y(12001, 2.0);
  EXPECT_EQ(thinPoints(x, y, 5000), 3u);
  EXPECT_LE(x.size(), 5000u);
  EXPECT_EQ(x.size(), y.size());
}
