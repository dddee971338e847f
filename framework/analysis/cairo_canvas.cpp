// PlotCanvas through Cairo's image surface.
#include "framework/analysis/cairo_canvas.hpp"

#include <stdexcept>

#include <cairo.h>
#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"

namespace gem {

namespace {

void setColor(cairo_t* cr, const std::string& hex, double alpha) {
  const Rgb c = parseColor(hex);
  cairo_set_source_rgba(cr, c.r, c.g, c.b, alpha);
}

cairo_status_t appendBytes(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

}  // namespace

CairoCanvas::CairoCanvas(int width, int height)
    : m_width(width), m_height(height), m_surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width, height)) {
  if (cairo_surface_status(m_surface) != CAIRO_STATUS_SUCCESS) {
    const std::string why = cairo_status_to_string(cairo_surface_status(m_surface));
    cairo_surface_destroy(m_surface);
    throw std::runtime_error(fmt::format("cannot make a {} x {} image: {}", width, height, why));
  }
  m_cairo = cairo_create(m_surface);
  cairo_set_line_join(m_cairo, CAIRO_LINE_JOIN_ROUND);
}

CairoCanvas::~CairoCanvas() {
  cairo_destroy(m_cairo);
  cairo_surface_destroy(m_surface);
}

void CairoCanvas::applyStyle(const ShapeStyle& style) {
  if (!style.fill.empty()) {
    setColor(m_cairo, style.fill, style.fillOpacity);
    if (style.stroke.empty())
      cairo_fill(m_cairo);
    else
      cairo_fill_preserve(m_cairo);
  }
  if (!style.stroke.empty()) {
    setColor(m_cairo, style.stroke, 1.0);
    cairo_set_line_width(m_cairo, style.strokeWidth);
    const double dash[] = {6.0, 4.0};
    cairo_set_dash(m_cairo, dash, style.dashed ? 2 : 0, 0);
    cairo_stroke(m_cairo);
  }
  cairo_new_path(m_cairo);
}

void CairoCanvas::rect(double x, double y, double w, double h, const ShapeStyle& style) {
  cairo_rectangle(m_cairo, x, y, w, h);
  applyStyle(style);
}

void CairoCanvas::path(const std::vector<PixelPath>& pieces, bool closed, const ShapeStyle& style) {
  for (const PixelPath& piece : pieces) {
    for (size_t i = 0; i < piece.size(); ++i) (i ? cairo_line_to : cairo_move_to)(m_cairo, piece[i].first, piece[i].second);
    if (closed && !piece.empty()) cairo_close_path(m_cairo);
  }
  applyStyle(style);
}

void CairoCanvas::circle(double cx, double cy, double r, const ShapeStyle& style) {
  cairo_new_sub_path(m_cairo);
  cairo_arc(m_cairo, cx, cy, r, 0, 6.283185307179586);
  applyStyle(style);
}

void CairoCanvas::text(double x, double y, const std::string& text, const TextStyle& style) {
  cairo_save(m_cairo);
  cairo_select_font_face(m_cairo, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, style.bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(m_cairo, style.size);
  cairo_text_extents_t extents;
  cairo_text_extents(m_cairo, text.c_str(), &extents);
  const double shift = style.anchor == TextAnchor::Start ? 0 : style.anchor == TextAnchor::Middle ? 0.5 : 1.0;
  cairo_translate(m_cairo, x, y);
  if (style.vertical) cairo_rotate(m_cairo, -1.5707963267948966);
  cairo_move_to(m_cairo, -shift * extents.x_advance, 0);
  setColor(m_cairo, style.color, 1.0);
  cairo_show_text(m_cairo, text.c_str());
  cairo_restore(m_cairo);
}

void CairoCanvas::clipTo(double x, double y, double w, double h) {
  cairo_reset_clip(m_cairo);
  cairo_rectangle(m_cairo, x, y, w, h);
  cairo_clip(m_cairo);
}

void CairoCanvas::clearClip() { cairo_reset_clip(m_cairo); }

std::string CairoCanvas::png() {
  cairo_surface_flush(m_surface);
  std::string bytes;
  const cairo_status_t status = cairo_surface_write_to_png_stream(m_surface, appendBytes, &bytes);
  if (status != CAIRO_STATUS_SUCCESS) throw std::runtime_error(fmt::format("PNG encoding failed: {}", cairo_status_to_string(status)));
  return bytes;
}

void CairoCanvas::writePng(const std::filesystem::path& path) { writeFileAtomically(path, png()); }

const std::uint8_t* CairoCanvas::pixels() {
  cairo_surface_flush(m_surface);
  return cairo_image_surface_get_data(m_surface);
}

int CairoCanvas::stride() const { return cairo_image_surface_get_stride(m_surface); }

}  // namespace gem
