#include "framework/analysis/resistance_analysis.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"
#include "framework/analysis/statistics.hpp"
#include "framework/analysis/sweep_cases.hpp"
#include "framework/output/csv.hpp"
#include "framework/analysis/svg_plot.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

double toNumber(const std::string& s) {
  try {
    return s.empty() ? NAN : std::stod(s);
  } catch (...) {
    return NAN;
  }
}

// A concentration as its cell: empty when the case's scenario gives none (not "nan").
std::string concentrationCell(double c) { return std::isfinite(c) ? fmt::format("{}", c) : ""; }

}  // namespace

std::vector<ResistancePoint> readResistancePoints(const fs::path& sweepDir) {
  if (!fs::exists(sweepDir / "summary.csv")) return {};
  const CsvTable summary = readCsvTable(sweepDir / "summary.csv");
  const int name = summary.column("name"), speed = summary.column("ship_speed_in_ice_mean"),
            resistance = summary.column("resistance_in_ice_mean");
  if (name < 0 || summary.column("vessel.bollard_thrust") < 0 || speed < 0 || resistance < 0) return {};
  // The inputs of each case from its own folder (scenario.toml), never from its name.
  const SweepCases cases = readSweepCases(sweepDir);
  std::vector<ResistancePoint> points;
  for (const std::vector<std::string>& row : summary.rows) {
    const auto c =
        std::find_if(cases.cases.begin(), cases.cases.end(), [&](const SweepCaseInfo& i) { return i.name == row[size_t(name)]; });
    if (c == cases.cases.end()) continue;
    ResistancePoint p;
    p.field = c->group;
    p.concentration = c->concentration;
    p.thrust = c->thrust;
    p.speed = toNumber(row[size_t(speed)]);
    p.resistance = toNumber(row[size_t(resistance)]);
    if (std::isfinite(p.thrust) && std::isfinite(p.speed) && std::isfinite(p.resistance)) points.push_back(p);
  }
  return points;
}

bool analyzeResistance(const fs::path& sweepDir, bool quiet) {
  const std::vector<ResistancePoint> points = readResistancePoints(sweepDir);
  if (points.empty()) return false;
  const fs::path out = sweepDir / "analysis";
  fs::create_directories(out);

  std::string table = "field,concentration,bollard_thrust_n,ship_speed_in_ice_mps,resistance_in_ice_n\n";
  std::map<std::string, std::vector<const ResistancePoint*>> byField;
  std::map<double, std::vector<const ResistancePoint*>> byThrust;
  for (const ResistancePoint& p : points) {
    table +=
        fmt::format("{},{},{},{:.6g},{:.6g}\n", csvField(p.field), concentrationCell(p.concentration), p.thrust, p.speed, p.resistance);
    byField[p.field].push_back(&p);
    byThrust[p.thrust].push_back(&p);
  }
  writeFileAtomically(out / "resistance.csv", table);

  // R = a V^b per field (thesis Figure 6.26), least squares in log-log over the positive points.
  SvgPlot vsSpeed("Ice resistance against speed (thesis Fig. 6.26)", "mean ship speed in ice V [m/s]", "mean resistance in ice R [N]");
  vsSpeed.setXScale(AxisScale::Log);
  vsSpeed.setYScale(AxisScale::Log);
  std::string fits = "field,concentration,a,b,r2,points\n";
  if (!quiet) std::printf("%-14s %6s %12s %7s %6s\n", "field", "conc.", "R = a V^b: a", "b", "r2");
  size_t colour = 0;
  for (const auto& [field, list] : byField) {
    std::vector<double> v, r;
    for (const ResistancePoint* p : list) v.push_back(p->speed), r.push_back(p->resistance);
    const PowerLawFit fit = fitPowerLaw(v, r);
    const std::string color = plotColor(colour++);
    vsSpeed.addScatter(field, v, r, color, 3.5);
    if (fit.ok) {
      const double lo = *std::min_element(v.begin(), v.end()), hi = *std::max_element(v.begin(), v.end());
      std::vector<double> lx, ly;
      for (int k = 0; k <= 20; ++k) {
        const double x = lo * std::pow(hi / lo, k / 20.0);
        lx.push_back(x), ly.push_back(fit.a * std::pow(x, fit.b));
      }
      vsSpeed.addLine("", lx, ly, color);
    }
    const std::string row = csvField(field) + "," + concentrationCell(list.front()->concentration);
    fits += fit.ok ? fmt::format("{},{:.6g},{:.6g},{:.4f},{}\n", row, fit.a, fit.b, fit.r2, fit.count)
                   : fmt::format("{},,,,{}\n", row, fit.count);
    if (!quiet)
      std::printf("%-14s %5.0f%% %12.4g %7.3f %6.3f\n", field.c_str(), 100 * list.front()->concentration, fit.ok ? fit.a : NAN,
                  fit.ok ? fit.b : NAN, fit.ok ? fit.r2 : NAN);
  }
  writeFileAtomically(out / "resistance_fits.csv", fits);
  vsSpeed.write(out / "resistance_vs_speed.svg");

  // Resistance against concentration, one line per thrust (thesis Figure 6.27).
  SvgPlot vsConcentration("Ice resistance against concentration (thesis Fig. 6.27)", "ice concentration [%]",
                          "mean resistance in ice R [N]");
  colour = 0;
  for (const auto& [thrust, list] : byThrust) {
    std::vector<std::pair<double, double>> xy;
    for (const ResistancePoint* p : list)
      if (std::isfinite(p->concentration)) xy.push_back({100 * p->concentration, p->resistance});
    std::sort(xy.begin(), xy.end());
    std::vector<double> x, y;
    for (auto [a, b] : xy) x.push_back(a), y.push_back(b);
    const std::string color = plotColor(colour++);
    vsConcentration.addScatter(fmt::format("{:.0f} kN", thrust / 1e3), x, y, color, 3.5);
    vsConcentration.addLine("", x, y, color);
  }
  vsConcentration.write(out / "resistance_vs_concentration.svg");
  if (!quiet) std::printf("  resistance tables and plots in %s\n", out.string().c_str());
  return true;
}

}  // namespace gem
