// The SVG backend of PlotCanvas and the colour helpers both backends share.
#include "framework/analysis/plot_canvas.hpp"

#include <cstdio>

#include <fmt/format.h>

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

std::string styleAttributes(const ShapeStyle& s) {
  std::string a = fmt::format(" fill=\"{}\"", s.fill.empty() ? "none" : s.fill);
  if (!s.fill.empty() && s.fillOpacity < 1) a += fmt::format(" fill-opacity=\"{:.3g}\"", s.fillOpacity);
  if (s.stroke.empty()) return a + " stroke=\"none\"";
  a += fmt::format(" stroke=\"{}\" stroke-width=\"{:.3g}\"", s.stroke, s.strokeWidth);
  if (s.dashed) a += " stroke-dasharray=\"6 4\"";
  return a;
}

}  // namespace

Rgb parseColor(const std::string& hex) {
  unsigned r = 0, g = 0, b = 0;
  if (hex.size() != 7 || hex[0] != '#' || std::sscanf(hex.c_str() + 1, "%2x%2x%2x", &r, &g, &b) != 3) return {};
  return {r / 255.0, g / 255.0, b / 255.0};
}

std::string colorHex(Rgb c) {
  auto byte = [](double v) { return int(v <= 0 ? 0 : v >= 1 ? 255 : v * 255 + 0.5); };
  return fmt::format("#{:02X}{:02X}{:02X}", byte(c.r), byte(c.g), byte(c.b));
}

SvgCanvas::SvgCanvas(int width, int height) {
  m_svg = fmt::format(
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"DejaVu Sans, Arial, sans-serif\" font-size=\"12\">\n",
      width, height);
}

void SvgCanvas::rect(double x, double y, double w, double h, const ShapeStyle& style) {
  m_svg += fmt::format("<rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\"{}/>\n", x, y, w, h, styleAttributes(style));
}

void SvgCanvas::path(const std::vector<PixelPath>& pieces, bool closed, const ShapeStyle& style) {
  std::string d;
  for (const PixelPath& piece : pieces) {
    for (size_t i = 0; i < piece.size(); ++i) d += fmt::format("{}{:.2f},{:.2f} ", i ? "L" : "M", piece[i].first, piece[i].second);
    if (closed && !piece.empty()) d += "Z ";
  }
  if (d.empty()) return;
  d.pop_back();
  m_svg += fmt::format("<path d=\"{}\"{}/>\n", d, styleAttributes(style));
}

void SvgCanvas::circle(double cx, double cy, double r, const ShapeStyle& style) {
  m_svg += fmt::format("<circle cx=\"{:.2f}\" cy=\"{:.2f}\" r=\"{:.2f}\"{}/>\n", cx, cy, r, styleAttributes(style));
}

void SvgCanvas::text(double x, double y, const std::string& text, const TextStyle& style) {
  static const char* const kAnchors[] = {"start", "middle", "end"};
  m_svg += fmt::format("<text x=\"{:.2f}\" y=\"{:.2f}\" font-size=\"{:.3g}\"", x, y, style.size);
  if (style.anchor != TextAnchor::Start) m_svg += fmt::format(" text-anchor=\"{}\"", kAnchors[int(style.anchor)]);
  if (style.bold) m_svg += " font-weight=\"bold\"";
  if (style.color != "#000000") m_svg += fmt::format(" fill=\"{}\"", style.color);
  if (style.vertical) m_svg += fmt::format(" transform=\"rotate(-90 {:.2f} {:.2f})\"", x, y);
  m_svg += fmt::format(">{}</text>\n", escapeXml(text));
}

void SvgCanvas::clipTo(double x, double y, double w, double h) {
  clearClip();
  const int id = m_clips++;
  m_svg += fmt::format(
      "<defs><clipPath id=\"clip{}\"><rect x=\"{:.2f}\" y=\"{:.2f}\" width=\"{:.2f}\" height=\"{:.2f}\"/></clipPath></defs>\n"
      "<g clip-path=\"url(#clip{})\">\n",
      id, x, y, w, h, id);
  m_clipOpen = true;
}

void SvgCanvas::clearClip() {
  if (m_clipOpen) m_svg += "</g>\n";
  m_clipOpen = false;
}

std::string SvgCanvas::finish() {
  clearClip();
  return m_svg + "</svg>\n";
}

}  // namespace gem
