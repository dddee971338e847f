#include "framework/analysis/analyze.hpp"

#include "framework/analysis/resistance_analysis.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "framework/api/input_size.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/csv.hpp"
#include "framework/api/errors.hpp"
#include "framework/analysis/statistics.hpp"
#include "framework/analysis/sweep_cases.hpp"
#include "framework/analysis/svg_plot.hpp"

namespace gem {

namespace fs = std::filesystem;

namespace {

// At most this many points of one group in a scatter plot: a 70-run sweep logs tens of thousands
// of impacts, and an SVG of that many circles is slow to open without showing more.
constexpr size_t kMaxScatterPoints = 3000;
constexpr const char* kAllColor = "#000000";
// Contacts closer to the stem than this are "at the stem" (the logged distance is then rounding
// noise, down to 1e-14 m): fn = a x^b cannot hold as x -> 0, and on log axes those few points
// would set the fit of thesis Figure 6.35. They are left out of that fit and plot, and counted.
constexpr double kMinStemDistance = 0.01;  // m

struct Impact {
  double t, floeId, floeMass, apexDeg, xFromStem, yFromCenterline, vn, fn;
  double shipSpeed;  // from timeseries.csv at t; NaN without one
};

double stemDistance(const Impact& i) { return i.xFromStem >= kMinStemDistance ? i.xFromStem : NAN; }

struct Run {
  std::string name, group, folder;
  std::vector<Impact> impacts;
  bool hasShipSpeed = false;
};

struct Group {
  std::string name, color;
  std::vector<const Run*> runs;

  template <class F>
  std::vector<double> column(F field) const {
    std::vector<double> out;
    for (const Run* r : runs)
      for (const Impact& i : r->impacts) out.push_back(field(i));
    return out;
  }
  size_t impactCount() const {
    size_t n = 0;
    for (const Run* r : runs) n += r->impacts.size();
    return n;
  }
};

struct GroupStatistics {
  size_t impacts = 0, struckFloes = 0;
  double forceMean = 0, forceMax = 0;
  WeibullFit force, apex;
  LognormalFit mass;
  PowerLawFit vsStem, vsVn, vsShipSpeed;
};

// One run folder: its impacts, with the ship speed at each impact interpolated from timeseries.csv
// (thesis Figure 6.36 plots force against ship speed, which impacts.csv does not hold).
Run readRun(const fs::path& dir, std::string name) {
  Run run;
  run.name = std::move(name);
  const auto c =
      readColumns(dir / "impacts.csv", {"t", "floe_id", "floe_mass", "apex_deg", "x_from_stem", "y_from_centerline", "vn", "fn"});
  std::vector<double> ts, speed;
  if (fs::exists(dir / "timeseries.csv")) {
    const auto s = readColumns(dir / "timeseries.csv", {"t", "ship_speed"});
    ts = s[0], speed = s[1];
    run.hasShipSpeed = !ts.empty() && std::is_sorted(ts.begin(), ts.end());
  }
  for (size_t i = 0; i < c[0].size(); ++i) {
    double ship = NAN;
    if (run.hasShipSpeed) {
      const auto it = std::lower_bound(ts.begin(), ts.end(), c[0][i]);
      if (it == ts.begin())
        ship = speed.front();
      else if (it == ts.end())
        ship = speed.back();
      else {
        const size_t k = size_t(it - ts.begin());
        const double w = ts[k] > ts[k - 1] ? (c[0][i] - ts[k - 1]) / (ts[k] - ts[k - 1]) : 1.0;
        ship = speed[k - 1] + w * (speed[k] - speed[k - 1]);
      }
    }
    run.impacts.push_back({c[0][i], c[1][i], c[2][i], c[3][i], c[4][i], c[5][i], c[6][i], c[7][i], ship});
  }
  return run;
}

GroupStatistics computeStatistics(const Group& g) {
  GroupStatistics s;
  s.impacts = g.impactCount();
  const std::vector<double> fn = g.column([](const Impact& i) { return i.fn; });
  double sum = 0;
  size_t finite = 0;
  for (double f : fn)
    if (std::isfinite(f)) sum += f, ++finite, s.forceMax = std::max(s.forceMax, f);
  s.forceMean = finite ? sum / double(finite) : 0.0;
  s.force = fitWeibull(fn);
  s.apex = fitWeibull(g.column([](const Impact& i) { return i.apexDeg; }));
  // Masses of the floes struck, each floe once per run (thesis Figure 6.32 compares the floes
  // struck with the whole population; a floe hit five times is still one floe).
  std::vector<double> masses;
  for (const Run* r : g.runs) {
    std::set<double> seen;
    for (const Impact& i : r->impacts)
      if (seen.insert(i.floeId).second) masses.push_back(i.floeMass);
  }
  s.struckFloes = masses.size();
  s.mass = fitLognormal(masses);
  s.vsStem = fitPowerLaw(g.column(stemDistance), fn);
  s.vsVn = fitPowerLaw(g.column([](const Impact& i) { return i.vn; }), fn);
  s.vsShipSpeed = fitPowerLaw(g.column([](const Impact& i) { return i.shipSpeed; }), fn);
  return s;
}

std::string cell(double v, bool ok = true) { return ok && std::isfinite(v) ? fmt::format("{:.6g}", v) : ""; }

std::string statisticsCsv(const std::vector<Group>& groups, const std::vector<GroupStatistics>& stats) {
  std::string out =
      "group,runs,impacts,force_mean_n,force_max_n,force_weibull_k,force_weibull_lambda_n,struck_floes,mass_lognormal_mu,"
      "mass_lognormal_sigma,mass_median_kg,apex_weibull_k,apex_weibull_lambda_deg,force_vs_stem_a,force_vs_stem_b,"
      "force_vs_stem_r2,force_vs_vn_a,force_vs_vn_b,force_vs_vn_r2,force_vs_ship_speed_a,force_vs_ship_speed_b,"
      "force_vs_ship_speed_r2\n";
  for (size_t i = 0; i < groups.size(); ++i) {
    const GroupStatistics& s = stats[i];
    auto power = [](const PowerLawFit& p) { return fmt::format("{},{},{}", cell(p.a, p.ok), cell(p.b, p.ok), cell(p.r2, p.ok)); };
    out += fmt::format("{},{},{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n", csvField(groups[i].name), groups[i].runs.size(), s.impacts,
                       cell(s.forceMean, s.impacts > 0), cell(s.forceMax, s.impacts > 0), cell(s.force.shape, s.force.ok),
                       cell(s.force.scale, s.force.ok), s.struckFloes, cell(s.mass.mu, s.mass.ok), cell(s.mass.sigma, s.mass.ok),
                       cell(std::exp(s.mass.mu), s.mass.ok), cell(s.apex.shape, s.apex.ok), cell(s.apex.scale, s.apex.ok), power(s.vsStem),
                       power(s.vsVn), power(s.vsShipSpeed));
  }
  return out;
}

// Impacts per metre of breadth per run in 1 m bins of y_from_centerline (thesis Figure 6.34): the
// same bins for every group, from the floor of the smallest y to past the largest.
struct AcrossBow {
  double y0 = 0;
  std::vector<std::vector<double>> perMetrePerRun;  // [group][bin]
  std::vector<std::vector<size_t>> counts;
};

AcrossBow acrossBow(const std::vector<Group>& groups) {
  AcrossBow a;
  double lo = INFINITY, hi = -INFINITY;
  for (const Group& g : groups)
    for (double y : g.column([](const Impact& i) { return i.yFromCenterline; }))
      if (std::isfinite(y)) lo = std::min(lo, y), hi = std::max(hi, y);
  const size_t bins = lo <= hi ? size_t(std::floor(hi) - std::floor(lo)) + 1 : 0;
  a.y0 = lo <= hi ? std::floor(lo) : 0;
  for (const Group& g : groups) {
    std::vector<size_t> count(bins, 0);
    for (double y : g.column([](const Impact& i) { return i.yFromCenterline; }))
      if (std::isfinite(y)) ++count[std::min(bins - 1, size_t(std::floor(y) - a.y0))];
    std::vector<double> rate(bins);
    const double binWidth = 1.0;
    for (size_t b = 0; b < bins; ++b) rate[b] = double(count[b]) / (binWidth * double(std::max<size_t>(1, g.runs.size())));
    a.counts.push_back(std::move(count));
    a.perMetrePerRun.push_back(std::move(rate));
  }
  return a;
}

std::string acrossBowCsv(const std::vector<Group>& groups, const AcrossBow& a) {
  std::string out = "group,y_min_m,y_max_m,impacts,impacts_per_m_per_run\n";
  for (size_t g = 0; g < groups.size(); ++g)
    for (size_t b = 0; b < a.counts[g].size(); ++b)
      out += fmt::format("{},{:g},{:g},{},{:.6g}\n", csvField(groups[g].name), a.y0 + double(b), a.y0 + double(b) + 1, a.counts[g][b],
                         a.perMetrePerRun[g][b]);
  return out;
}

std::vector<double> logSpaced(double lo, double hi, int n) {
  std::vector<double> v(n);
  for (int i = 0; i < n; ++i) v[i] = lo * std::pow(hi / lo, double(i) / (n - 1));
  return v;
}

size_t thin(std::vector<double>& x, std::vector<double>& y) { return thinPoints(x, y, kMaxScatterPoints); }

// Groups drawn as separate series: the prefix groups, or "all" alone when it is the only one.
std::vector<size_t> drawnGroups(const std::vector<Group>& groups) {
  std::vector<size_t> out;
  for (size_t i = 0; i < groups.size(); ++i)
    if (groups.size() == 1 || groups[i].name != "all") out.push_back(i);
  return out;
}

// Thesis Figure 6.38: the impact forces of each group on Weibull probability paper (median ranks),
// with the fitted Weibull CDFs, straight lines there.
void plotForceCdf(const std::vector<Group>& groups, const std::vector<GroupStatistics>& stats, const fs::path& file) {
  SvgPlot plot("Impact forces: empirical CDF and Weibull fits (thesis Fig. 6.38)", "impact force fn [N]",
               "cumulative probability (Weibull scale)");
  plot.setXScale(AxisScale::Log);
  plot.setYScale(AxisScale::WeibullProbability);
  plot.addNote("F(x) = 1 - exp(-(x/lambda)^k), maximum likelihood; points at median ranks (i - 0.3)/(n + 0.4)");
  for (size_t gi = 0; gi < groups.size(); ++gi) {
    std::vector<double> x;
    for (double f : groups[gi].column([](const Impact& i) { return i.fn; }))
      if (std::isfinite(f) && f > 0) x.push_back(f);
    std::sort(x.begin(), x.end());
    std::vector<double> p = medianRanks(x.size());
    const WeibullFit& w = stats[gi].force;
    const size_t every = thin(x, p);
    plot.addScatter(fmt::format("{}: n={}{}", groups[gi].name, w.count,
                                w.ok ? fmt::format(", k={:.3g}, lambda={:.3g} N", w.shape, w.scale) : std::string(", no fit")) +
                        (every > 1 ? fmt::format(" (1 in {} shown)", every) : ""),
                    x, p, groups[gi].color, 1.8);
    if (w.ok && !x.empty()) {
      std::vector<double> fx = logSpaced(x.front(), x.back(), 80), fp;
      for (double v : fx) fp.push_back(weibullCdf(v, w.shape, w.scale));
      plot.addLine("", fx, fp, groups[gi].color);
    }
  }
  plot.write(file);
}

// Thesis Figure 6.32: masses of the floes struck, a histogram of ln(mass) (the lognormal is a
// normal there) with the fitted density.
void plotMass(const Group& all, const GroupStatistics& s, const fs::path& file) {
  SvgPlot plot("Masses of the floes struck and lognormal fit (thesis Fig. 6.32)", "floe mass [kg]", "density per unit ln(mass)");
  plot.setXScale(AxisScale::Log);
  std::vector<double> logs;
  for (const Run* r : all.runs) {
    std::set<double> seen;
    for (const Impact& i : r->impacts)
      if (seen.insert(i.floeId).second && std::isfinite(i.floeMass) && i.floeMass > 0) logs.push_back(std::log(i.floeMass));
  }
  if (!logs.empty()) {
    const auto [lo, hi] = std::minmax_element(logs.begin(), logs.end());
    const int bins = std::clamp(int(std::sqrt(double(logs.size()))), 5, 40);
    const double a = *lo - 1e-9, width = std::max(1e-6, (*hi - *lo) / bins + 2e-9 / bins);
    std::vector<double> counts(bins, 0.0), edges(bins + 1);
    for (double l : logs) counts[std::min(bins - 1, int((l - a) / width))] += 1;
    for (int b = 0; b <= bins; ++b) edges[b] = std::exp(a + b * width);
    for (double& c : counts) c /= double(logs.size()) * width;
    plot.addSteps(fmt::format("floes struck (n={})", logs.size()), edges, counts, "#0072B2");
    if (s.mass.ok) {
      std::vector<double> mx, my;
      for (int i = 0; i <= 120; ++i) {
        const double l = s.mass.mu + s.mass.sigma * (-4.0 + 8.0 * i / 120.0);
        mx.push_back(std::exp(l));
        my.push_back(lognormalLogDensity(l, s.mass.mu, s.mass.sigma));
      }
      plot.addLine(fmt::format("lognormal mu={:.3g}, sigma={:.3g} (median {:.3g} kg)", s.mass.mu, s.mass.sigma, std::exp(s.mass.mu)), mx,
                   my, "#D55E00");
    }
  }
  plot.write(file);
}

// Thesis Figure 6.31: apex angles at impact, 5 degree bins, with the fitted Weibull density.
void plotApex(const Group& all, const GroupStatistics& s, const fs::path& file) {
  SvgPlot plot("Apex angles at impact and Weibull fit (thesis Fig. 6.31)", "apex angle [deg]", "density [1/deg]");
  std::vector<double> apex;
  for (double v : all.column([](const Impact& i) { return i.apexDeg; }))
    if (std::isfinite(v) && v > 0) apex.push_back(v);
  if (!apex.empty()) {
    const double binWidth = 5.0;
    const int bins = int(std::ceil(std::max(180.0, *std::max_element(apex.begin(), apex.end())) / binWidth));
    std::vector<double> counts(bins, 0.0), edges(bins + 1);
    for (double v : apex) counts[std::min(bins - 1, int(v / binWidth))] += 1;
    for (int b = 0; b <= bins; ++b) edges[b] = b * binWidth;
    for (double& c : counts) c /= double(apex.size()) * binWidth;
    plot.addSteps(fmt::format("impacts (n={})", apex.size()), edges, counts, "#0072B2");
    if (s.apex.ok) {
      std::vector<double> ax, ay;
      for (int i = 1; i <= 200; ++i) {
        ax.push_back(edges.back() * i / 200.0);
        ay.push_back(weibullPdf(ax.back(), s.apex.shape, s.apex.scale));
      }
      plot.addLine(fmt::format("Weibull k={:.3g}, lambda={:.3g} deg", s.apex.shape, s.apex.scale), ax, ay, "#D55E00");
    }
  }
  plot.write(file);
}

void plotAcrossBow(const std::vector<Group>& groups, const AcrossBow& a, const fs::path& file) {
  SvgPlot plot("Impacts across the bow (thesis Fig. 6.34)", "distance from centreline y [m]", "impacts per metre per run");
  for (size_t gi : drawnGroups(groups)) {
    std::vector<double> edges;
    for (size_t b = 0; b <= a.perMetrePerRun[gi].size(); ++b) edges.push_back(a.y0 + double(b));
    if (!a.perMetrePerRun[gi].empty())
      plot.addSteps(fmt::format("{} ({} run{})", groups[gi].name, groups[gi].runs.size(), groups[gi].runs.size() == 1 ? "" : "s"), edges,
                    a.perMetrePerRun[gi], groups[gi].color);
  }
  plot.write(file);
}

// Force against a per-impact quantity on log-log axes, with each group's power law (thesis
// Figures 6.35 and 6.36).
template <class F>
void plotPowerLaw(const std::vector<Group>& groups, const std::vector<GroupStatistics>& stats, PowerLawFit GroupStatistics::*fit, F field,
                  const std::string& title, const std::string& xLabel, const fs::path& file, AxisScale xScale = AxisScale::Log,
                  const std::string& extraNote = "") {
  SvgPlot plot(title, xLabel, "impact force fn [N]");
  plot.setXScale(xScale);
  plot.setLegendRight(xScale == AxisScale::Linear);  // linear distances crowd at the stem, on the left
  plot.setYScale(AxisScale::Log);
  plot.addNote("fn = a x^b, least squares in log-log space over the impacts with x > 0 and fn > 0");
  if (!extraNote.empty()) plot.addNote(extraNote);
  for (size_t gi : drawnGroups(groups)) {
    std::vector<double> x = groups[gi].column(field), y = groups[gi].column([](const Impact&i) { return i.fn; });
    const PowerLawFit& p = stats[gi].*fit;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t i = 0; i < x.size(); ++i)
      if (x[i] > 0 && std::isfinite(x[i]) && y[i] > 0) lo = std::min(lo, x[i]), hi = std::max(hi, x[i]);
    const size_t every = thin(x, y);
    plot.addScatter(fmt::format("{}: {}{}", groups[gi].name,
                                p.ok ? fmt::format("a={:.3g}, b={:.3g}, r2={:.2f}", p.a, p.b, p.r2) : std::string("no fit"),
                                every > 1 ? fmt::format(" (1 in {} shown)", every) : ""),
                    x, y, groups[gi].color, 1.6);
    if (p.ok && lo < hi) {
      std::vector<double> fx = logSpaced(lo, hi, 40), fy;
      for (double v : fx) fy.push_back(p.a * std::pow(v, p.b));
      plot.addLine("", fx, fy, groups[gi].color, true);
    }
  }
  plot.write(file);
}

void printTable(const std::vector<Group>& groups, const std::vector<GroupStatistics>& stats, const fs::path& outDir) {
  auto num = [](double v, bool ok) { return ok && std::isfinite(v) ? fmt::format("{:.3g}", v) : std::string("-"); };
  std::printf("%-8s %5s %8s %10s %10s %7s %10s %7s %7s %7s %7s %7s\n", "group", "runs", "impacts", "F mean N", "F max N", "F k", "F lambda",
              "ln m mu", "sigma", "apex k", "lambda", "F~vn b");
  for (size_t i = 0; i < groups.size(); ++i) {
    const GroupStatistics& s = stats[i];
    std::printf("%-8s %5zu %8zu %10s %10s %7s %10s %7s %7s %7s %7s %7s\n", groups[i].name.c_str(), groups[i].runs.size(), s.impacts,
                num(s.forceMean, s.impacts > 0).c_str(), num(s.forceMax, s.impacts > 0).c_str(), num(s.force.shape, s.force.ok).c_str(),
                num(s.force.scale, s.force.ok).c_str(), num(s.mass.mu, s.mass.ok).c_str(), num(s.mass.sigma, s.mass.ok).c_str(),
                num(s.apex.shape, s.apex.ok).c_str(), num(s.apex.scale, s.apex.ok).c_str(), num(s.vsVn.b, s.vsVn.ok).c_str());
  }
  std::printf("  tables and plots in %s\n", outDir.string().c_str());
}

}  // namespace

int runAnalyze(const AnalyzeOptions& options) {
  const fs::path dir = options.dir;
  requireFolder(dir, "folder");

  // The runs: the folder itself, or every case of a sweep that has finished (impacts.csv is
  // written atomically at the end of a run, so its presence means the case is complete).
  std::vector<Run> runs;
  const bool sweep = !holdsFile(dir / "impacts.csv", "impacts.csv");
  size_t incomplete = 0;
  if (!sweep) {
    runs.push_back(readRun(dir, dir.filename().string()));
  } else {
    for (const SweepCaseInfo& c : readSweepCases(dir).cases) {
      if (holdsFile(c.dir / "impacts.csv", "impacts.csv")) {
        runs.push_back(readRun(c.dir, c.name));
        runs.back().group = c.group;
        runs.back().folder = c.dir.filename().string();
      } else {
        ++incomplete;
      }
    }
  }
  // A sweep of bollard thrusts with summary.csv's in-ice means also gets its resistance analysis.
  const bool resistance = sweep && analyzeResistance(dir, options.quiet);
  if (runs.empty() && resistance) return 0;
  if (runs.empty())
    throw InputError(
        fmt::format("{}: no impacts.csv here and none in cases/*/: not a run folder or a sweep folder with a finished "
                    "case",
                    dir.string()));

  // A run folder is one group: a --groups naming another (a typo, a sweep's label) analysed the
  // whole run under "all" with exit 0.
  for (const std::string& wanted : options.groups)
    if (!sweep && wanted != "all" && wanted != runs.front().name)
      throw InputError(
          fmt::format("--groups {}: {} is a run folder, one group: \"all\" (groups are a sweep folder's)", wanted, dir.string()));

  // Groups: a run folder is one group "all"; a sweep groups its cases by the values of its varied
  // keys other than thrust and seed (sweep_cases.hpp; thesis Figure 6.38 groups by ice mix), plus
  // "all" of the chosen ones. --groups names a group by its label or by one of its cases' names.
  std::vector<Group> groups;
  if (sweep) {
    std::map<std::string, std::vector<const Run*>> byGroup;
    for (const Run& r : runs) byGroup[r.group].push_back(&r);
    std::set<std::string> chosen;
    for (const std::string& wanted : options.groups) {
      const auto member = std::find_if(runs.begin(), runs.end(), [&](const Run& r) { return r.name == wanted || r.folder == wanted; });
      if (byGroup.count(wanted)) {
        chosen.insert(wanted);
      } else if (member != runs.end()) {
        chosen.insert(member->group);
      } else {
        std::string known;
        for (const auto& [name, members] : byGroup) known += (known.empty() ? "" : "; ") + name;
        throw InputError(fmt::format("{}: no case in group \"{}\" (groups: {})", dir.string(), wanted, known));
      }
    }
    for (const auto& [name, members] : byGroup)
      if (options.groups.empty() || chosen.count(name)) groups.push_back({name, plotColor(groups.size()), members});
  }
  Group all{"all", kAllColor, {}};
  for (const Group& g : groups) all.runs.insert(all.runs.end(), g.runs.begin(), g.runs.end());
  if (!sweep) all.runs.push_back(&runs.front());
  if (groups.size() == 1) groups.clear();  // one group: it is "all"
  groups.push_back(std::move(all));

  std::vector<GroupStatistics> stats;
  for (const Group& g : groups) stats.push_back(computeStatistics(g));

  const fs::path out = dir / "analysis";
  fs::create_directories(out);
  writeFileAtomically(out / "statistics.csv", statisticsCsv(groups, stats));
  const AcrossBow bow = acrossBow(groups);
  writeFileAtomically(out / "across_bow.csv", acrossBowCsv(groups, bow));
  plotForceCdf(groups, stats, out / "force_cdf.svg");
  plotMass(groups.back(), stats.back(), out / "floe_mass_hist.svg");
  plotApex(groups.back(), stats.back(), out / "apex_hist.svg");
  plotAcrossBow(groups, bow, out / "across_bow.svg");
  size_t atStem = 0;
  for (const Run& r : runs)
    atStem += size_t(std::count_if(r.impacts.begin(), r.impacts.end(), [](const Impact& i) { return i.xFromStem < kMinStemDistance; }));
  plotPowerLaw(groups, stats, &GroupStatistics::vsStem, stemDistance, "Impact force against distance from stem (thesis Fig. 6.35)",
               "distance from stem x [m]", out / "force_vs_stem_distance.svg", AxisScale::Linear,
               atStem ? fmt::format("{} impact(s) within {} m of the stem left out", atStem, kMinStemDistance) : std::string());
  plotPowerLaw(
      groups, stats, &GroupStatistics::vsVn, [](const Impact& i) { return i.vn; }, "Impact force against closing speed",
      "normal closing speed vn [m/s]", out / "force_vs_speed.svg");
  const bool shipSpeed = std::all_of(runs.begin(), runs.end(), [](const Run& r) { return r.hasShipSpeed; });
  if (shipSpeed)
    plotPowerLaw(
        groups, stats, &GroupStatistics::vsShipSpeed, [](const Impact& i) { return i.shipSpeed; },
        "Impact force against ship speed (thesis Fig. 6.36)", "ship speed at impact [m/s]", out / "force_vs_ship_speed.svg");
  else
    fs::remove(out / "force_vs_ship_speed.svg");  // a stale plot must not describe this data

  if (!options.quiet) {
    if (incomplete > 0) std::printf("  %zu case(s) without impacts.csv skipped (not finished)\n", incomplete);
    printTable(groups, stats, out);
  }
  return 0;
}

}  // namespace gem
