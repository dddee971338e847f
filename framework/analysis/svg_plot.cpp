#include "framework/analysis/svg_plot.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"

namespace gem {

namespace {

std::string escapeXml(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

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

std::string SvgPlot::render(int width, int height) const {
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

  std::string svg = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\"12\">\n"
      "<rect x=\"0\" y=\"0\" width=\"{0}\" height=\"{1}\" fill=\"white\"/>\n"
      "<defs><clipPath id=\"plot-area\"><rect x=\"{2:.2f}\" y=\"{3:.2f}\" width=\"{4:.2f}\" height=\"{5:.2f}\"/>"
      "</clipPath></defs>\n",
      width, height, left, top, right - left, bottom - top);
  svg += fmt::format("<text x=\"{:.1f}\" y=\"24\" text-anchor=\"middle\" font-size=\"15\" font-weight=\"bold\">{}</text>\n",
                     0.5 * (left + right), escapeXml(m_title));
  for (size_t i = 0; i < m_notes.size(); ++i)
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"11\" fill=\"#444\">{}</text>\n",
                       0.5 * (left + right), 40.0 + 14.0 * double(i), escapeXml(m_notes[i]));

  // Grid and ticks.
  svg += "<g stroke=\"#e4e4e4\" stroke-width=\"1\">\n";
  const std::vector<Tick> xTicks = makeTicks(m_x.scale, xLo, xHi), yTicks = makeTicks(m_y.scale, yLo, yHi);
  for (const Tick& t : xTicks)
    svg += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\"/>\n", px(t.t), top, bottom);
  for (const Tick& t : yTicks)
    svg += fmt::format("<line x1=\"{1:.2f}\" y1=\"{0:.2f}\" x2=\"{2:.2f}\" y2=\"{0:.2f}\"/>\n", py(t.t), left, right);
  svg += "</g>\n<g stroke=\"black\" stroke-width=\"1\">\n";
  for (const Tick& t : xTicks)
    svg += fmt::format("<line x1=\"{0:.2f}\" y1=\"{1:.2f}\" x2=\"{0:.2f}\" y2=\"{2:.2f}\"/>\n", px(t.t), bottom, bottom + 5);
  for (const Tick& t : yTicks)
    svg += fmt::format("<line x1=\"{1:.2f}\" y1=\"{0:.2f}\" x2=\"{2:.2f}\" y2=\"{0:.2f}\"/>\n", py(t.t), left - 5, left);
  svg += "</g>\n";
  for (const Tick& t : xTicks)
    svg += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" text-anchor=\"middle\">{}</text>\n", px(t.t), bottom + 18, escapeXml(t.label));
  for (const Tick& t : yTicks)
    svg += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" text-anchor=\"end\">{}</text>\n", left - 8, py(t.t) + 4, escapeXml(t.label));
  svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"13\">{}</text>\n", 0.5 * (left + right),
                     double(height) - 14, escapeXml(m_x.label));
  svg +=
      fmt::format("<text x=\"18\" y=\"{0:.1f}\" text-anchor=\"middle\" font-size=\"13\" transform=\"rotate(-90 18 {0:.1f})\">{1}</text>\n",
                  0.5 * (top + bottom), escapeXml(m_y.label));

  // Series, clipped to the plot area (fixed ranges may cut them).
  svg += "<g clip-path=\"url(#plot-area)\">\n";
  for (const Series& s : m_series) {
    if (s.kind == Kind::Scatter) {
      svg += fmt::format("<g fill=\"{}\" fill-opacity=\"0.6\" stroke=\"none\">\n", s.color);
      const size_t n = std::min(s.x.size(), s.y.size());
      for (size_t i = 0; i < n; ++i) {
        const double tx = transform(m_x.scale, s.x[i]), ty = transform(m_y.scale, s.y[i]);
        if (std::isnan(tx) || std::isnan(ty)) continue;
        svg += fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.1f}\"/>\n", px(tx), py(ty), s.radius);
      }
      svg += "</g>\n";
      continue;
    }
    // Lines and steps: one path, broken where a point cannot be drawn.
    std::string d;
    bool pen = false;
    auto point = [&](double tx, double ty) {
      if (std::isnan(tx) || std::isnan(ty)) {
        pen = false;
        return;
      }
      d += fmt::format("{}{:.2f},{:.2f} ", pen ? "L" : "M", px(tx), py(ty));
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
      if (baseline && !d.empty()) svg += fmt::format("<path d=\"{}Z\" fill=\"{}\" fill-opacity=\"0.12\" stroke=\"none\"/>\n", d, s.color);
    }
    if (!d.empty())
      svg += fmt::format("<path d=\"{}\" fill=\"none\" stroke=\"{}\" stroke-width=\"1.6\"{}/>\n", d, s.color,
                         s.dashed ? " stroke-dasharray=\"6 4\"" : "");
  }
  svg += "</g>\n";
  svg += fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\" fill=\"none\" stroke=\"black\"/>\n", left, top,
                     right - left, bottom - top);
  if (empty)
    svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\" text-anchor=\"middle\" font-size=\"14\" fill=\"#888\">no data</text>\n",
                       0.5 * (left + right), 0.5 * (top + bottom));

  // Legend, in a top corner inside the plot area.
  std::vector<const Series*> labelled;
  for (const Series& s : m_series)
    if (!s.label.empty()) labelled.push_back(&s);
  if (!labelled.empty()) {
    size_t longest = 0;
    for (const Series* s : labelled) longest = std::max(longest, s->label.size());
    const double w = 40 + 6.8 * double(longest), h = 8 + 16.0 * double(labelled.size());
    const double lx = m_legendRight ? right - 10 - w : left + 10, ly = top + 10;
    svg += fmt::format(
        "<g font-size=\"11\">\n<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"white\" "
        "fill-opacity=\"0.85\" stroke=\"#999\"/>\n",
        lx, ly, w, h);
    for (size_t i = 0; i < labelled.size(); ++i) {
      const Series& s = *labelled[i];
      const double y = ly + 14 + 16.0 * double(i);
      if (s.kind == Kind::Scatter)
        svg += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"{}\"/>\n", lx + 16, y - 4, s.color);
      else
        svg += fmt::format("<path d=\"M{:.1f},{:.1f} L{:.1f},{:.1f}\" stroke=\"{}\" stroke-width=\"2\"{}/>\n", lx + 6, y - 4, lx + 26,
                           y - 4, s.color, s.dashed ? " stroke-dasharray=\"6 4\"" : "");
      svg += fmt::format("<text x=\"{:.1f}\" y=\"{:.1f}\">{}</text>\n", lx + 32, y, escapeXml(s.label));
    }
    svg += "</g>\n";
  }
  svg += "</svg>\n";
  return svg;
}

void SvgPlot::write(const std::filesystem::path& path) const { writeFileAtomically(path, render()); }

}  // namespace gem
