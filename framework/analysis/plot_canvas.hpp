// The drawing surface of GEM's pictures: a few primitives (rectangles, paths, circles, text, a clip)
// in pixel coordinates with y down, drawn either as SVG text (SvgCanvas, here) or through Cairo
// into a PNG or a movie frame (CairoCanvas, cairo_canvas.hpp). Every plot and frame is drawn once,
// against this interface, so the SVG and the PNG of a plot cannot drift apart.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace gem {

// Colours are "#RRGGBB"; an empty colour means "none" (no fill, or no stroke).
struct ShapeStyle {
  std::string fill{};
  double fillOpacity = 1.0;
  std::string stroke{};
  double strokeWidth = 1.0;
  bool dashed = false;  // a 6 px dash, 4 px gap
};

enum class TextAnchor { Start, Middle, End };

struct TextStyle {
  double size = 12;
  bool bold = false;
  TextAnchor anchor = TextAnchor::Start;
  std::string color = "#000000";
  bool vertical = false;  // rotated a quarter turn anticlockwise about (x, y): a y-axis label
};

using PixelPath = std::vector<std::pair<double, double>>;

class PlotCanvas {
 public:
  virtual ~PlotCanvas() = default;
  virtual void rect(double x, double y, double w, double h, const ShapeStyle& style) = 0;
  // Several pieces make one path (a line broken where a point cannot be drawn); closed joins each
  // piece's last point to its first.
  virtual void path(const std::vector<PixelPath>& pieces, bool closed, const ShapeStyle& style) = 0;
  virtual void circle(double cx, double cy, double r, const ShapeStyle& style) = 0;
  // (x, y) is the baseline point the anchor names.
  virtual void text(double x, double y, const std::string& text, const TextStyle& style) = 0;
  // Until clearClip(), nothing is drawn outside this rectangle (a fixed axis range cuts a series).
  virtual void clipTo(double x, double y, double w, double h) = 0;
  virtual void clearClip() = 0;
};

// Red, green and blue in [0, 1] of "#RRGGBB" (black for anything else).
struct Rgb {
  double r = 0, g = 0, b = 0;
};
Rgb parseColor(const std::string& hex);
std::string colorHex(Rgb c);

// SVG 1.1 text of the drawing; text() in DejaVu Sans, as CairoCanvas draws it.
class SvgCanvas : public PlotCanvas {
 public:
  SvgCanvas(int width, int height);
  void rect(double x, double y, double w, double h, const ShapeStyle& style) override;
  void path(const std::vector<PixelPath>& pieces, bool closed, const ShapeStyle& style) override;
  void circle(double cx, double cy, double r, const ShapeStyle& style) override;
  void text(double x, double y, const std::string& text, const TextStyle& style) override;
  void clipTo(double x, double y, double w, double h) override;
  void clearClip() override;
  // The document, closed: call once, after drawing.
  std::string finish();

 private:
  std::string m_svg;
  int m_clips = 0;
  bool m_clipOpen = false;
};

}  // namespace gem
