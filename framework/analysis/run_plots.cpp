// The figures of one run folder (run_plots.hpp), drawn with SvgPlot.
#include "framework/analysis/run_plots.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "framework/output/csv.hpp"
#include "framework/analysis/svg_plot.hpp"
#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/output/run_folder.hpp"

namespace gem {

namespace fs = std::filesystem;

namespace {

std::vector<double> scaled(std::vector<double> v, double factor) {
  for (double& x : v) x *= factor;
  return v;
}

// "mean M UNIT, from LO to HI UNIT" over the finite values; "" when there are none. Both ends: the
// ice force is negative (it resists), so its largest load is its minimum.
std::string meanAndRange(const std::vector<double>& v, const char* unit) {
  double sum = 0, lo = INFINITY, hi = -INFINITY;
  size_t n = 0;
  for (double x : v)
    if (std::isfinite(x)) sum += x, lo = std::min(lo, x), hi = std::max(hi, x), ++n;
  return n ? fmt::format("mean {:.4g}{}, from {:.4g} to {:.4g}{}", sum / double(n), unit, lo, hi, unit) : "";
}

// The value below which a fraction q of the sorted values lie (nearest rank).
double quantile(const std::vector<double>& sorted, double q) {
  return sorted[std::min(sorted.size() - 1, size_t(q * double(sorted.size())))];
}

// More points than a plot 800 px wide can show: long runs are reduced (envelopeLine, thinPoints).
constexpr size_t kMaxLinePoints = 4000, kMaxScatterPoints = 5000;

struct Writer {
  fs::path dir;
  RunPlots& result;
  void operator()(const SvgPlot& plot, const std::string& name) {
    plot.writeSvgAndPng(dir / name);
    result.files.push_back(dir / (name + ".svg"));
    result.files.push_back(dir / (name + ".png"));
  }
};

// One quantity against t: its line (reduced to kMaxLinePoints) and, above it, its mean and range
// over every row.
void plotAgainstTime(Writer& write, const std::string& name, const std::string& title, const std::string& yLabel, const char* unit,
                     std::vector<double> t, std::vector<double> v, std::size_t color) {
  SvgPlot plot(title, "time t [s]", yLabel);
  plot.addNote(meanAndRange(v, unit));
  envelopeLine(t, v, kMaxLinePoints);
  plot.addLine("", std::move(t), std::move(v), plotColor(color));
  write(plot, name);
}

void plotTimeSeries(const fs::path& runDir, Writer& write, RunPlots& result) {
  const fs::path file = runDir / "timeseries.csv";
  const auto c = readColumns(file, {"t", "ship_speed", "net_thrust", "ice_force_x", "contacts"}, true);
  const std::vector<double>& t = c[0];
  const bool vessel = std::any_of(c[1].begin(), c[1].end(), [](double v) { return std::isfinite(v); });
  if (vessel) {
    plotAgainstTime(write, "ship_speed", "Ship speed", "surge speed [m/s]", " m/s", t, c[1], 0);
    // Thrust left over after open-water resistance: what the ice resists with, on average.
    plotAgainstTime(write, "net_thrust", "Net thrust (thrust less open-water resistance)", "net thrust [kN]", " kN", t, scaled(c[2], 1e-3),
                    1);
    plotAgainstTime(write, "ice_force", "Ice force on the ship, along x", "ice force x [kN]", " kN", t, scaled(c[3], 1e-3), 2);
  } else {
    result.notes.push_back("no vessel in this run: no ship speed, net thrust or ice force plots");
  }
  plotAgainstTime(write, "contacts", "Contacts", "contacts in the step", "", t, c[4], 3);
}

void plotImpacts(const fs::path& runDir, Writer& write, RunPlots& result) {
  const fs::path file = runDir / "impacts.csv";
  if (!holdsFile(file, "timeseries.csv")) {
    result.notes.push_back("no impacts.csv (no ship_impact event in this run): no impact-load plots");
    return;
  }
  const auto c = readColumns(file, {"t", "x_from_stem", "y_from_centerline", "fn", "broke"});
  if (c[0].empty()) {
    result.notes.push_back("impacts.csv has no impacts: no impact-load plots");
    return;
  }
  const std::vector<double> fn = scaled(c[3], 1e-3);
  std::vector<double> sorted;
  for (double f : fn)
    if (std::isfinite(f)) sorted.push_back(f);
  std::sort(sorted.begin(), sorted.end());
  const std::string summary = sorted.empty() ? "no finite force"
                                             : fmt::format("{} impacts; median {:.4g} kN, 95 % below {:.4g} kN, max {:.4g} kN", fn.size(),
                                                           quantile(sorted, 0.5), quantile(sorted, 0.95), sorted.back());

  // Histogram with about sqrt(n) bins (10 to 60) from 0 to the largest force.
  SvgPlot hist("Impact forces", "impact force fn [kN]", "impacts");
  if (!sorted.empty()) {
    const size_t bins = std::clamp<size_t>(size_t(std::sqrt(double(sorted.size()))), 10, 60);
    const double width = std::max(sorted.back(), 1e-9) / double(bins);
    std::vector<double> edges(bins + 1), counts(bins, 0.0);
    for (size_t i = 0; i <= bins; ++i) edges[i] = width * double(i);
    for (double f : sorted) counts[std::min(bins - 1, size_t(std::max(0.0, f) / width))] += 1;
    hist.addSteps("", edges, counts, plotColor(0));
  }
  hist.addNote(summary);
  write(hist, "impact_force_hist");

  // Where the hull is struck and how hard: the stem takes the largest loads (thesis Figure 6.33).
  std::vector<double> xIntact, fIntact, xBroke, fBroke;
  for (size_t i = 0; i < fn.size(); ++i) {
    (c[4][i] != 0 ? xBroke : xIntact).push_back(c[1][i]);
    (c[4][i] != 0 ? fBroke : fIntact).push_back(fn[i]);
  }
  const size_t every = std::max(thinPoints(xIntact, fIntact, kMaxScatterPoints), thinPoints(xBroke, fBroke, kMaxScatterPoints));
  const std::string shown = every > 1 ? fmt::format(" (every {}th shown)", every) : "";
  SvgPlot along("Impact positions along the hull", "distance from stem x [m]", "impact force fn [kN]");
  along.addScatter("floe stayed whole", xIntact, fIntact, plotColor(0), 2.5);
  along.addScatter("floe broke", xBroke, fBroke, plotColor(1), 2.5);
  along.setLegendRight(true);
  along.addNote(summary + shown);
  write(along, "impact_positions");

  std::vector<double> t = c[0], f = fn;
  const size_t everyT = thinPoints(t, f, kMaxScatterPoints);
  SvgPlot vsTime("Impact forces over the run", "time t [s]", "impact force fn [kN]");
  vsTime.addScatter("", t, f, plotColor(2), 2.5);
  vsTime.addNote(summary + (everyT > 1 ? fmt::format(" (every {}th shown)", everyT) : ""));
  write(vsTime, "impact_force_vs_time");
}

}  // namespace

RunPlots writeRunPlots(const fs::path& runDir) {
  requireFolder(runDir, "run folder");
  if (!holdsFile(runDir / "timeseries.csv", "timeseries.csv"))
    throw InputError(runDir.string() + ": not a run folder (no timeseries.csv; `gem run SCENARIO --out DIR` makes one)");
  RunPlots result;
  Writer write{runDir / "plots", result};
  fs::create_directories(write.dir);
  plotTimeSeries(runDir, write, result);
  plotImpacts(runDir, write, result);
  return result;
}

}  // namespace gem
