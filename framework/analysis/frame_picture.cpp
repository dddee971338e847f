// Drawing one frame of a run (frame_picture.hpp) on a PlotCanvas.
#include "framework/analysis/frame_picture.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "framework/api/errors.hpp"

namespace gem {

namespace {

constexpr double kHeader = 40;    // px above the field: the time and the key
constexpr double kMargin = 10;    // px around the field
constexpr double kBarSpace = 96;  // px right of the field: the colour bar and its labels
constexpr const char* kWater = "#CFE2F3";
constexpr const char* kVessel = "#C0392B";
constexpr const char* kWall = "#8C8C8C";
constexpr size_t kMaxValues = 1 << 20;  // floe values kept for the colour range: about 1 % of a percent off at worst

double speedOf(const FrameBody& b) { return std::hypot(double(b.velocity.x), double(b.velocity.y)); }

// A floe's colour for its id: hues a golden angle apart, so neighbouring ids differ.
Rgb idColor(std::int64_t id) {
  const double h = std::fmod(double(id) * 0.6180339887498949, 1.0) * 6.0, s = 0.55, v = 0.92;
  const double f = h - std::floor(h), p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (int(h) % 6) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

}  // namespace

FrameColor parseFrameColor(const std::string& name) {
  if (name == "speed") return FrameColor::Speed;
  if (name == "thickness") return FrameColor::Thickness;
  if (name == "id") return FrameColor::Id;
  throw InputError(fmt::format("--color {}: expected speed, thickness or id", name));
}

Rgb viridis(double u) {
  static const char* const kStops[] = {"#440154", "#472D7B", "#3B528B", "#2C728E", "#21918C", "#28AE80", "#5EC962", "#ADDC30", "#FDE725"};
  constexpr int kLast = 8;
  const double s = std::clamp(std::isfinite(u) ? u : 0.0, 0.0, 1.0) * kLast;
  const int i = std::min(int(s), kLast - 1);
  const double w = s - i;
  const Rgb a = parseColor(kStops[i]), b = parseColor(kStops[i + 1]);
  return {a.r + w * (b.r - a.r), a.g + w * (b.g - a.g), a.b + w * (b.b - a.b)};
}

FramePainter::FramePainter(FrameColor color, int width, int height) : m_color(color), m_width(width), m_height(height) {}

void FramePainter::Box::cover(const FrameBody& b) {
  for (const Vec2& v : b.vertices)
    x0 = std::min(x0, double(v.x)), x1 = std::max(x1, double(v.x)), y0 = std::min(y0, double(v.y)), y1 = std::max(y1, double(v.y));
}

void FramePainter::survey(const FrameState& frame) {
  for (const FrameBody& b : frame.bodies) {
    if (b.kind != BodyKind::Floe) {
      m_others.cover(b);
      continue;
    }
    if (m_frameCount == 0) m_field.cover(b);
    if (m_seen++ % m_stride) continue;
    m_values.push_back(m_color == FrameColor::Thickness ? double(b.thickness) : speedOf(b));
    if (m_values.size() >= kMaxValues) {  // thin the sample to every other value, and keep every other from now on
      for (size_t i = 0; 2 * i < m_values.size(); ++i) m_values[i] = m_values[2 * i];
      m_values.resize((m_values.size() + 1) / 2);
      m_stride *= 2;
    }
  }
  ++m_frameCount;
}

void FramePainter::fit() {
  m_fitted = true;
  Box box = m_field;
  if (!(box.x1 > box.x0 && box.y1 > box.y0)) box = m_others;  // no ice at the start: the vessel's track and the walls
  if (!(box.x1 > box.x0)) box.x0 = -1, box.x1 = 1;
  if (!(box.y1 > box.y0)) box.y0 = -1, box.y1 = 1;
  const double pad = 0.03 * std::max(box.x1 - box.x0, box.y1 - box.y0);  // the walls along a channel's sides stay in view
  const double x0 = box.x0 - pad, x1 = box.x1 + pad, y0 = box.y0 - pad, y1 = box.y1 + pad;
  const double right = m_color == FrameColor::Id ? kMargin : kBarSpace;
  const double areaW = m_width - kMargin - right, areaH = m_height - kHeader - kMargin;
  m_scale = std::max(1e-9, std::min(areaW / (x1 - x0), areaH / (y1 - y0)));
  m_x0 = x0, m_y1 = y1;
  m_left = kMargin + 0.5 * (areaW - m_scale * (x1 - x0));
  m_top = kHeader + 0.5 * (areaH - m_scale * (y1 - y0));

  std::vector<double>& values = m_values;
  values.erase(std::remove_if(values.begin(), values.end(), [](double v) { return !std::isfinite(v); }), values.end());
  std::sort(values.begin(), values.end());
  if (m_color == FrameColor::Speed) {
    m_lo = 0;
    m_hi = values.empty() ? 0 : values[std::min(values.size() - 1, size_t(0.99 * double(values.size())))];
  } else if (!values.empty()) {
    m_lo = values.front(), m_hi = values.back();
  }
  if (!(m_hi > m_lo)) m_hi = m_lo + (m_color == FrameColor::Speed ? 0.1 : 0.1 * std::max(m_lo, 1.0));
  values = {};
}

std::pair<double, double> FramePainter::pixel(Vec2 p) const {
  return {m_left + (double(p.x) - m_x0) * m_scale, m_top + (m_y1 - double(p.y)) * m_scale};
}

std::string FramePainter::floeColor(const FrameBody& b) const {
  if (m_color == FrameColor::Id) return colorHex(idColor(b.id));
  const double v = m_color == FrameColor::Speed ? speedOf(b) : double(b.thickness);
  return colorHex(viridis((v - m_lo) / (m_hi - m_lo)));
}

void FramePainter::drawColorBar(PlotCanvas& canvas) const {
  constexpr int kSteps = 64;
  const double x = m_width - kBarSpace + 14, w = 18, top = kHeader + 20, bottom = m_height - kMargin - 10, h = bottom - top;
  for (int i = 0; i < kSteps; ++i) {  // from the top (high values) down
    const double u = 1.0 - (i + 0.5) / kSteps;
    // Each slice overlaps the next by a pixel: no seams of background between them.
    canvas.rect(x, top + h * i / kSteps, w, h / kSteps + 1, {.fill = colorHex(viridis(u))});
  }
  canvas.rect(x, top, w, h, {.stroke = "#000000"});
  canvas.text(x, top - 8, m_color == FrameColor::Speed ? "speed [m/s]" : "thickness [m]", {.size = 11});
  for (int i = 0; i <= 4; ++i) {
    const double y = bottom - h * i / 4.0, v = m_lo + (m_hi - m_lo) * i / 4.0;
    canvas.path({{{x + w, y}, {x + w + 4, y}}}, false, {.stroke = "#000000"});
    canvas.text(x + w + 7, y + 4, fmt::format("{:.3g}", v), {.size = 11});
  }
}

void FramePainter::draw(PlotCanvas& canvas, const FrameState& frame, std::size_t index) {
  if (!m_fitted) fit();
  canvas.rect(0, 0, m_width, m_height, {.fill = "#F7F7F7"});
  canvas.text(kMargin, 26, fmt::format("t = {:.1f} s", frame.time), {.size = 18, .bold = true});
  const char* key = m_color == FrameColor::Speed       ? "floes by speed"
                    : m_color == FrameColor::Thickness ? "floes by thickness"
                                                       : "floes by id";
  canvas.text(kMargin + 130, 26,
              fmt::format("frame {} / {}   {}; vessel red, walls grey, broken pieces outlined", index, m_frameCount - 1, key),
              {.size = 12, .color = "#333333"});
  const double fieldW = m_width - kMargin - (m_color == FrameColor::Id ? kMargin : kBarSpace);
  canvas.clipTo(kMargin, kHeader, fieldW, m_height - kHeader - kMargin);
  canvas.rect(kMargin, kHeader, fieldW, m_height - kHeader - kMargin, {.fill = kWater});
  // Walls under floes under pieces under the vessel: what matters most is drawn last.
  auto outline = [&](const FrameBody& b) {
    PixelPath p;
    for (const Vec2& v : b.vertices) p.push_back(pixel(v));
    return std::vector<PixelPath>{std::move(p)};
  };
  for (const FrameBody& b : frame.bodies)
    if (b.kind == BodyKind::Wall) canvas.path(outline(b), true, {.fill = kWall});
  for (int pass = 0; pass < 2; ++pass)
    for (const FrameBody& b : frame.bodies)
      if (b.kind == BodyKind::Floe && b.piece == (pass == 1))
        canvas.path(outline(b), true,
                    {.fill = floeColor(b), .stroke = b.piece ? "#000000" : "#2B2B2B", .strokeWidth = b.piece ? 1.4 : 0.4});
  for (const FrameBody& b : frame.bodies)
    if (b.kind == BodyKind::Vessel) canvas.path(outline(b), true, {.fill = kVessel, .stroke = "#000000", .strokeWidth = 1.2});
  canvas.clearClip();
  if (m_color != FrameColor::Id) drawColorBar(canvas);
}

}  // namespace gem
