// The Cairo backend of PlotCanvas: draws into an image in memory, which becomes a PNG (a plot, a
// movie's still) or a raw BGRA frame piped to ffmpeg (movie.hpp). Cairo stays out of this header,
// so code that includes it needs no Cairo headers of its own.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>

#include "framework/analysis/plot_canvas.hpp"

struct _cairo;
struct _cairo_surface;

namespace gem {

class CairoCanvas : public PlotCanvas {
 public:
  // A transparent width x height image; antialiased drawing, DejaVu Sans text.
  CairoCanvas(int width, int height);
  ~CairoCanvas() override;
  CairoCanvas(const CairoCanvas&) = delete;
  CairoCanvas& operator=(const CairoCanvas&) = delete;

  void rect(double x, double y, double w, double h, const ShapeStyle& style) override;
  void path(const std::vector<PixelPath>& pieces, bool closed, const ShapeStyle& style) override;
  void circle(double cx, double cy, double r, const ShapeStyle& style) override;
  void text(double x, double y, const std::string& text, const TextStyle& style) override;
  void clipTo(double x, double y, double w, double h) override;
  void clearClip() override;

  int width() const { return m_width; }
  int height() const { return m_height; }
  // The image as PNG bytes.
  std::string png();
  // Writes png() through writeFileAtomically.
  void writePng(const std::filesystem::path& path);
  // Row-major pixels, 4 bytes each in memory order B, G, R, A (premultiplied; opaque where the
  // drawing painted a background), rows stride() bytes apart: ffmpeg's "bgra".
  const std::uint8_t* pixels();
  int stride() const;

 private:
  void applyStyle(const ShapeStyle& style);  // fills and strokes the current path

  int m_width, m_height;
  _cairo_surface* m_surface;
  _cairo* m_cairo;
};

}  // namespace gem
