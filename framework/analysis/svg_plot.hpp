// A small hand-written SVG plotter for the figures of `gem analyze` (thesis Figures 6.31 to 6.38):
// one plot area with linear, log or Weibull-probability axes, ticks and labels, scatter, lines,
// histogram steps, a legend and a title. The plot is drawn once on a PlotCanvas: as plain SVG 1.1
// text that any browser shows, or through Cairo as a PNG.
#pragma once
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "framework/analysis/plot_canvas.hpp"

namespace gem {

enum class AxisScale {
  Linear,
  Log,  // base 10; values <= 0 are not drawn
  // Weibull probability paper (Minitab's probability plots, thesis Figure 6.38): p is drawn at
  // ln(-ln(1 - p)), so with a log x axis a Weibull CDF is a straight line of slope k. Only for
  // 0 < p < 1.
  WeibullProbability,
};

// The i-th colour of a fixed, colour-blind-friendly palette (cycles).
std::string plotColor(std::size_t i);

// Every k-th point so that at most maxPoints remain; returns k (1: none dropped). For scatter
// plots: tens of thousands of circles make an SVG slow to open without showing more.
std::size_t thinPoints(std::vector<double>& x, std::vector<double>& y, std::size_t maxPoints);
// A line of more than maxPoints points reduced to the lowest and highest point of each run of
// consecutive ones, in order: it looks the same (every spike kept) at a fraction of the size.
void envelopeLine(std::vector<double>& x, std::vector<double>& y, std::size_t maxPoints);

class SvgPlot {
 public:
  SvgPlot(std::string title, std::string xLabel, std::string yLabel);

  void setXScale(AxisScale scale) { m_x.scale = scale; }
  void setYScale(AxisScale scale) { m_y.scale = scale; }
  // Fixed data ranges; otherwise the range covers every drawable point of every series.
  void setXRange(double lo, double hi) { m_x.range = {lo, hi}; }
  void setYRange(double lo, double hi) { m_y.range = {lo, hi}; }
  // A line of small text under the title (fit parameters, how the data was thinned).
  void addNote(std::string text) { m_notes.push_back(std::move(text)); }
  // The legend sits in the top left corner of the plot area unless moved to the top right.
  void setLegendRight(bool right) { m_legendRight = right; }

  // An empty label keeps the series out of the legend; an empty colour takes the next palette one.
  void addScatter(std::string label, std::vector<double> x, std::vector<double> y, std::string color = "", double radius = 2.0);
  void addLine(std::string label, std::vector<double> x, std::vector<double> y, std::string color = "", bool dashed = false);
  // A histogram outline: edges has one more entry than values.
  void addSteps(std::string label, std::vector<double> edges, std::vector<double> values, std::string color = "");

  // Draws the plot on any canvas: the SVG text and the PNG come from this one drawing.
  void draw(PlotCanvas& canvas, int width, int height) const;
  std::string render(int width = 800, int height = 520) const;
  // Writes render() through writeFileAtomically.
  void write(const std::filesystem::path& path) const;
  // The same plot as a PNG through Cairo, written atomically.
  void writePng(const std::filesystem::path& path, int width = 800, int height = 520) const;
  // STEM.svg and STEM.png.
  void writeSvgAndPng(const std::filesystem::path& stem) const;

 private:
  enum class Kind { Scatter, Line, Steps };
  struct Series {
    Kind kind;
    std::string label, color;
    std::vector<double> x, y;
    bool dashed = false;
    double radius = 2.0;
  };
  struct Axis {
    std::string label;
    AxisScale scale = AxisScale::Linear;
    std::optional<std::pair<double, double>> range;
  };
  std::string nextColor();

  std::string m_title;
  Axis m_x, m_y;
  std::vector<std::string> m_notes;
  std::vector<Series> m_series;
  std::size_t m_colorIndex = 0;
  bool m_legendRight = false;
};

}  // namespace gem
