// One frame of a run as a picture (gem movie, its stills): the floes filled by a colour key
// (speed, thickness or id) with a colour bar, the vessel in red, walls grey, broken pieces outlined
// in black, and the time written on it; the view is fitted once to the field (frame 0's floes), so
// the camera stands still while the vessel crosses it.
#pragma once
#include <cmath>
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
  FramePainter(FrameColor color, int width, int height);

  // Shown every frame of the series, in order, before the first draw(): the view is fitted to
  // frame 0's floes (the vessel before and after the field, and walls running on beyond it, are
  // cut at the view's edge) and the colour range to the floes' speeds (up to their 99th
  // percentile, so one flung piece does not wash out the rest) or thicknesses over every frame.
  // Only a bounding box and a thinned sample of values are kept, never the frames.
  void survey(const FrameState& frame);
  std::size_t frameCount() const { return m_frameCount; }

  void draw(PlotCanvas& canvas, const FrameState& frame, std::size_t index);

 private:
  void fit();  // at the first draw()
  // Pixel coordinates of a world point.
  std::pair<double, double> pixel(Vec2 p) const;
  std::string floeColor(const FrameBody& body) const;
  void drawColorBar(PlotCanvas& canvas) const;

  FrameColor m_color;
  int m_width, m_height;
  std::size_t m_frameCount = 0;
  bool m_fitted = false;
  struct Box {
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    void cover(const FrameBody& b);
  } m_field, m_others;           // frame 0's floes; the vessel and walls in every frame (a field without ice)
  std::vector<double> m_values;  // every m_stride-th floe speed or thickness seen
  std::size_t m_seen = 0, m_stride = 1;
  double m_x0 = 0, m_y1 = 0, m_scale = 1, m_left = 0, m_top = 0;  // world (m_x0, m_y1) sits at pixel (m_left, m_top)
  double m_lo = 0, m_hi = 1;                                      // colour range of the key
};

}  // namespace gem
