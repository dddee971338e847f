// One frame of a run as a picture (gem movie, its stills): the floes filled by a colour key
// (speed, thickness or id) with a colour bar, the vessel in red, walls grey, broken pieces outlined
// in black, and the time written on it; the view is fitted once to the field (frame 0's floes), so
// the camera stands still while the vessel crosses it.
#pragma once
#include <string>
#include <vector>

#include "framework/analysis/frame_series.hpp"
#include "framework/analysis/plot_canvas.hpp"

namespace gem {

enum class FrameColor { Speed, Thickness, Id };

// "speed", "thickness", "id"; throws InputError for anything else.
FrameColor parseFrameColor(const std::string& name);

// The colour at u in [0, 1] of a perceptually even blue-to-yellow scale (viridis).
Rgb viridis(double u);

class FramePainter {
 public:
  // Fits the view to frame 0's floes (the vessel before and after the field, and walls running on
  // beyond it, are cut at the view's edge) and the colour range to the series: the floes' speeds
  // (up to their 99th percentile, so one flung piece does not wash out the rest) or thicknesses
  // over every frame.
  FramePainter(const std::vector<FrameState>& frames, FrameColor color, int width, int height);

  void draw(PlotCanvas& canvas, const FrameState& frame, std::size_t index) const;

 private:
  // Pixel coordinates of a world point.
  std::pair<double, double> pixel(Vec2 p) const;
  std::string floeColor(const FrameBody& body) const;
  void drawColorBar(PlotCanvas& canvas) const;

  FrameColor m_color;
  int m_width, m_height;
  std::size_t m_frameCount;
  double m_x0 = 0, m_y1 = 0, m_scale = 1, m_left = 0, m_top = 0;  // world (m_x0, m_y1) sits at pixel (m_left, m_top)
  double m_lo = 0, m_hi = 1;                                      // colour range of the key
};

}  // namespace gem
