#include "framework/analysis/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "framework/analysis/cairo_canvas.hpp"
#include "framework/output/atomic_file.hpp"

namespace gem {

namespace {

// Data value -> axis coordinate (before the affine map to pixels); NaN when not drawable.
double transform(AxisScale scale, double v) {
  if (!std::isfinite(v)) return std::numeric_limits<double>::quiet_NaN();
  switch (scale) {
    case AxisScale::Linear:
      return v;
    case AxisScale::Log:
      return v > 0 ? std::log10(v) : std::numeric_limits<double>::quiet_NaN();
    case AxisScale::WeibullProbability:
      return v > 0 && v < 1 ? std::log(-std::log1p(-v)) : std::numeric_limits<double>::quiet_NaN();
  }
  return v;
}

// 1, 2 or 5 times a power of ten, near range / target.
double niceStep(double range, int target) {
  const double raw = range / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / p;
  return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

std::string tickLabel(double v, double step) {
  if (v == 0) return "0";
  const double a = std::abs(v);
  if (a >= 1e5 || a < 1e-3) return fmt::format("{:.3g}", v);
  const int decimals = std::max(0, int(-std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", v, decimals);
}

struct Tick {
  double t;  // transformed coordinate
  std::string label;
};

std::vector<Tick> makeTicks(AxisScale scale, double lo, double hi) {
  std::vector<Tick> ticks;
  if (scale == AxisScale::Linear) {
    const double step = niceStep(hi - lo, 6);
    for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + 1e-9 * step; v += step)
      ticks.push_back({v, tickLabel(std::abs(v) < 1e-12 * step ? 0 : v, step)});
  } else if (scale == AxisScale::Log) {
    if (hi - lo < 1) {  // less than a decade: plain linear steps, placed on the log axis
      const double a = std::pow(10.0, lo), b = std::pow(10.0, hi), step = niceStep(b - a, 5);
      for (double v = std::ceil(a / step - 1e-9) * step; v <= b * (1 + 1e-12); v += step)
        if (v > 0) ticks.push_back({std::log10(v), tickLabel(v, step)});
      return ticks;
    }
    const int first = int(std::ceil(lo - 1e-9)), last = int(std::floor(hi + 1e-9));
    const int every = std::max(1, (last - first + 1 + 7) / 8);  // at most about 8 decade labels
    for (int e = first; e <= last; e += every) {
      const double v = std::pow(10.0, e);
      ticks.push_back({double(e), e >= -3 && e <= 3 ? fmt::format("{:g}", v) : fmt::format("1e{}", e)});
    }
    if (last - first < 2) {  // less than two decades: label 2 and 5 times each power too
      for (int e = first - 1; e <= last; ++e)
        for (double m : {2.0, 5.0}) {
          const double t = e + std::log10(m);
          const double v = m * std::pow(10.0, e);
          if (t >= lo && t <= hi) ticks.push_back({t, e >= -3 && e <= 3 ? fmt::format("{:g}", v) : fmt::format("{:g}e{}", m, e)});
        }
    }
  } else {
    for (double p : {0.001, 0.01, 0.05, 0.1, 0.2, 0.3, 0.5, 0.632, 0.8, 0.9, 0.95, 0.99, 0.999}) {
      const double t = transform(scale, p);
      if (t >= lo && t <= hi) ticks.push_back({t, fmt::format("{:g}", p)});
    }
  }
  return ticks;
}

}  // namespace

std::string plotColor(std::size_t i) {
  // Okabe-Ito, then a few darker tones: distinguishable for colour-blind readers.
  static const char* const kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#F0E442", "#8C564B",
                                         "#7F3C8D", "#11A579", "#3969AC", "#F2B701", "#E73F74", "#80BA5A", "#E68310", "#008695"};
  return kPalette[i % (sizeof(kPalette) / sizeof(kPalette[0]))];
}

std::size_t thinPoints(std::vector<double>& x, std::vector<double>& y, std::size_t maxPoints) {
  const size_t k = (x.size() + maxPoints - 1) / std::max<size_t>(maxPoints, 1);
  if (k <= 1) return 1;
  size_t j = 0;
  for (size_t i = 0; i < x.size(); i += k, ++j) x[j] = x[i], y[j] = y[i];
  x.resize(j), y.resize(j);
  return k;
}

void envelopeLine(std::vector<double>& x, std::vector<double>& y, std::size_t maxPoints) {
  const size_t n = std::min(x.size(), y.size()), runs = std::max<size_t>(maxPoints / 2, 1);
  if (n <= maxPoints) return;
  std::vector<double> ex, ey;
  for (size_t r = 0; r < runs; ++r) {
    const size_t from = r * n / runs, to = (r + 1) * n / runs;
    size_t lo = from, hi = from;
    for (size_t i = from; i < to; ++i) {  // NaN compares false: a gap stays a gap only if all of the run is one
      if (y[i] < y[lo] || std::isnan(y[lo])) lo = i;
      if (y[i] > y[hi] || std::isnan(y[hi])) hi = i;
    }
    for (size_t i : {std::min(lo, hi), std::max(lo, hi)}) ex.push_back(x[i]), ey.push_back(y[i]);
  }
  x = std::move(ex), y = std::move(ey);
}

SvgPlot::SvgPlot(std::string title, std::string xLabel, std::string yLabel) : m_title(std::move(title)) {
  m_x.label = std::move(xLabel);
  m_y.label = std::move(yLabel);
}

std::string SvgPlot::nextColor() { return plotColor(m_colorIndex++); }

void SvgPlot::addScatter(std::string label, std::vector<double> x, std::vector<double> y, std::string color, double radius) {
  m_series.push_back(
      {Kind::Scatter, std::move(label), color.empty() ? nextColor() : std::move(color), std::move(x), std::move(y), false, radius});
}

void SvgPlot::addLine(std::string label, std::vector<double> x, std::vector<double> y, std::string color, bool dashed) {
  m_series.push_back({Kind::Line, std::move(label), color.empty() ? nextColor() : std::move(color), std::move(x), std::move(y), dashed});
}

void SvgPlot::addSteps(std::string label, std::vector<double> edges, std::vector<double> values, std::string color) {
  m_series.push_back({Kind::Steps, std::move(label), color.empty() ? nextColor() : std::move(color), std::move(edges), std::move(values)});
}

void SvgPlot::draw(PlotCanvas& canvas, int width, int height) const {
  // Data ranges in transformed coordinates over every drawable point.
  double xLo = INFINITY, xHi = -INFINITY, yLo = INFINITY, yHi = -INFINITY;
  for (const Series& s : m_series) {
    const size_t n = s.kind == Kind::Steps ? s.y.size() : std::min(s.x.size(), s.y.size());
    for (size_t i = 0; i < n; ++i) {
      const double tx = transform(m_x.scale, s.x[i]), ty = transform(m_y.scale, s.y[i]);
      if (std::isnan(tx) || std::isnan(ty)) continue;
      xLo = std::min(xLo, tx), xHi = std::max(xHi, tx), yLo = std::min(yLo, ty), yHi = std::max(yHi, ty);
      if (s.kind == Kind::Steps) {  // the right edge of the bin, and the baseline of a histogram
        const double tx1 = transform(m_x.scale, s.x[i + 1]);
        if (!std::isnan(tx1)) xHi = std::max(xHi, tx1), xLo = std::min(xLo, tx1);
        if (m_y.scale == AxisScale::Linear) yLo = std::min(yLo, 0.0);
      }
    }
  }
  const bool empty = !(xLo <= xHi && yLo <= yHi);
  auto settle = [](const Axis& axis, double& lo, double& hi, bool none) {
    if (axis.range) {
      lo = transform(axis.scale, axis.range->first), hi = transform(axis.scale, axis.range->second);
    } else if (none) {
      lo = transform(axis.scale, axis.scale == AxisScale::Linear ? 0.0 : axis.scale == AxisScale::Log ? 1.0 : 0.01);
      hi = transform(axis.scale, axis.scale == AxisScale::Linear ? 1.0 : axis.scale == AxisScale::Log ? 10.0 : 0.99);
    } else {
      const double span = hi - lo;
      const double pad = span > 0 ? 0.04 * span : std::max(0.5, 0.1 * std::abs(lo));
      lo -= pad, hi += pad;
      if (axis.scale == AxisScale::Linear && lo < 0 && lo + pad >= 0) lo = 0;  // keep a zero baseline at zero
    }
    if (!(hi > lo)) hi = lo + 1;
  };
  settle(m_x, xLo, xHi, empty);
  settle(m_y, yLo, yHi, empty);

  const double left = 84, right = width - 24.0;
  const double top = 44 + 14.0 * double(m_notes.size()), bottom = height - 56.0;
  auto px = [&](double t) { return left + (t - xLo) / (xHi - xLo) * (right - left); };
  auto py = [&](double t) { return bottom - (t - yLo) / (yHi - yLo) * (bottom - top); };

  canvas.rect(0, 0, width, height, {.fill = "#FFFFFF"});
  canvas.text(0.5 * (left + right), 24, m_title, {.size = 15, .bold = true, .anchor = TextAnchor::Middle});
  for (size_t i = 0; i < m_notes.size(); ++i)
    canvas.text(0.5 * (left + right), 40.0 + 14.0 * double(i), m_notes[i], {.size = 11, .anchor = TextAnchor::Middle, .color = "#444444"});

  // Grid and ticks.
  const std::vector<Tick> xTicks = makeTicks(m_x.scale, xLo, xHi), yTicks = makeTicks(m_y.scale, yLo, yHi);
  std::vector<PixelPath> grid, marks;
  for (const Tick& t : xTicks) {
    grid.push_back({{px(t.t), top}, {px(t.t), bottom}});
    marks.push_back({{px(t.t), bottom}, {px(t.t), bottom + 5}});
  }
  for (const Tick& t : yTicks) {
    grid.push_back({{left, py(t.t)}, {right, py(t.t)}});
    marks.push_back({{left - 5, py(t.t)}, {left, py(t.t)}});
  }
  canvas.path(grid, false, {.stroke = "#E4E4E4"});
  canvas.path(marks, false, {.stroke = "#000000"});
  for (const Tick& t : xTicks) canvas.text(px(t.t), bottom + 18, t.label, {.anchor = TextAnchor::Middle});
  for (const Tick& t : yTicks) canvas.text(left - 8, py(t.t) + 4, t.label, {.anchor = TextAnchor::End});
  canvas.text(0.5 * (left + right), double(height) - 14, m_x.label, {.size = 13, .anchor = TextAnchor::Middle});
  canvas.text(18, 0.5 * (top + bottom), m_y.label, {.size = 13, .anchor = TextAnchor::Middle, .vertical = true});

  // Series, clipped to the plot area (fixed ranges may cut them).
  canvas.clipTo(left, top, right - left, bottom - top);
  for (const Series& s : m_series) {
    if (s.kind == Kind::Scatter) {
      const size_t n = std::min(s.x.size(), s.y.size());
      for (size_t i = 0; i < n; ++i) {
        const double tx = transform(m_x.scale, s.x[i]), ty = transform(m_y.scale, s.y[i]);
        if (std::isnan(tx) || std::isnan(ty)) continue;
        canvas.circle(px(tx), py(ty), s.radius, {.fill = s.color, .fillOpacity = 0.6});
      }
      continue;
    }
    // Lines and steps: one path, broken where a point cannot be drawn.
    std::vector<PixelPath> pieces;
    bool pen = false;
    auto point = [&](double tx, double ty) {
      if (std::isnan(tx) || std::isnan(ty)) {
        pen = false;
        return;
      }
      if (!pen) pieces.emplace_back();
      pieces.back().emplace_back(px(tx), py(ty));
      pen = true;
    };
    if (s.kind == Kind::Line) {
      const size_t n = std::min(s.x.size(), s.y.size());
      for (size_t i = 0; i < n; ++i) point(transform(m_x.scale, s.x[i]), transform(m_y.scale, s.y[i]));
    } else {
      const bool baseline = m_y.scale == AxisScale::Linear;
      for (size_t i = 0; i < s.y.size() && i + 1 < s.x.size(); ++i) {
        const double tx0 = transform(m_x.scale, s.x[i]), tx1 = transform(m_x.scale, s.x[i + 1]);
        const double ty = transform(m_y.scale, s.y[i]);
        if (i == 0 && baseline) point(tx0, 0.0);
        point(tx0, ty);
        point(tx1, ty);
      }
      if (baseline && !s.y.empty() && s.x.size() > s.y.size()) point(transform(m_x.scale, s.x[s.y.size()]), 0.0);
      if (baseline && !pieces.empty()) canvas.path(pieces, true, {.fill = s.color, .fillOpacity = 0.12});
    }
    if (!pieces.empty()) canvas.path(pieces, false, {.stroke = s.color, .strokeWidth = 1.6, .dashed = s.dashed});
  }
  canvas.clearClip();
  canvas.rect(left, top, right - left, bottom - top, {.stroke = "#000000"});
  if (empty)
    canvas.text(0.5 * (left + right), 0.5 * (top + bottom), "no data", {.size = 14, .anchor = TextAnchor::Middle, .color = "#888888"});

  // Legend, in a top corner inside the plot area.
  std::vector<const Series*> labelled;
  for (const Series& s : m_series)
    if (!s.label.empty()) labelled.push_back(&s);
  if (!labelled.empty()) {
    size_t longest = 0;
    for (const Series* s : labelled) longest = std::max(longest, s->label.size());
    const double w = 40 + 6.8 * double(longest), h = 8 + 16.0 * double(labelled.size());
    const double lx = m_legendRight ? right - 10 - w : left + 10, ly = top + 10;
    canvas.rect(lx, ly, w, h, {.fill = "#FFFFFF", .fillOpacity = 0.85, .stroke = "#999999"});
    for (size_t i = 0; i < labelled.size(); ++i) {
      const Series& s = *labelled[i];
      const double y = ly + 14 + 16.0 * double(i);
      if (s.kind == Kind::Scatter)
        canvas.circle(lx + 16, y - 4, 3, {.fill = s.color});
      else
        canvas.path({{{lx + 6, y - 4}, {lx + 26, y - 4}}}, false, {.stroke = s.color, .strokeWidth = 2, .dashed = s.dashed});
      canvas.text(lx + 32, y, s.label, {.size = 11});
    }
  }
}

std::string SvgPlot::render(int width, int height) const {
  SvgCanvas canvas(width, height);
  draw(canvas, width, height);
  return canvas.finish();
}

void SvgPlot::writePng(const std::filesystem::path& path, int width, int height) const {
  CairoCanvas canvas(width, height);
  draw(canvas, width, height);
  canvas.writePng(path);
}

void SvgPlot::writeSvgAndPng(const std::filesystem::path& stem) const {
  write(stem.string() + ".svg");
  writePng(stem.string() + ".png");
}

void SvgPlot::write(const std::filesystem::path& path) const { writeFileAtomically(path, render()); }

}  // namespace gem
