// Helpers of the plot and movie tests: a small busy run made by the real gem binary, and PNGs
// decoded with Cairo for pixel checks.
#pragma once
#include <cairo.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "test_support.hpp"

namespace gem::test {

// kBusyScene (the vessel ramming 40 % ice: impacts and broken floes) run by `gem run ARGS` into
// DIR/run; returns the run folder, or an empty path when gem failed.
inline std::filesystem::path makeBusyRun(const TempDir& dir, const std::string& arguments = "--no-plots") {
  const std::filesystem::path scenario = dir.write("busy.toml", kBusyScene), run = dir.path() / "run";
  const int status = runGem("run " + scenario.string() + " --quiet --out " + run.string() + " " + arguments, dir.path() / "run.log");
  return status == 0 ? run : std::filesystem::path();
}

struct Picture {
  int width = 0, height = 0;
  std::vector<std::uint32_t> argb;  // row by row; 0 pixels when the file did not decode

  std::uint32_t at(int x, int y) const { return argb[size_t(y) * size_t(width) + size_t(x)]; }
  // Pixels within `tolerance` (each channel, 0-255) of the opaque colour 0xRRGGBB.
  long count(std::uint32_t rgb, int tolerance = 0) const {
    long n = 0;
    for (std::uint32_t p : argb) {
      bool near = (p >> 24) == 0xff;
      for (int shift : {0, 8, 16}) near = near && std::abs(int((p >> shift) & 0xff) - int((rgb >> shift) & 0xff)) <= tolerance;
      n += near;
    }
    return n;
  }
};

inline Picture readPng(const std::filesystem::path& file) {
  Picture picture;
  cairo_surface_t* image = cairo_image_surface_create_from_png(file.c_str());
  if (cairo_surface_status(image) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_t* argb =
        cairo_image_surface_create(CAIRO_FORMAT_ARGB32, cairo_image_surface_get_width(image), cairo_image_surface_get_height(image));
    cairo_t* cr = cairo_create(argb);  // whatever format the PNG decoded to, as ARGB32
    cairo_set_source_surface(cr, image, 0, 0);
    cairo_paint(cr);
    cairo_destroy(cr);
    cairo_surface_flush(argb);
    picture.width = cairo_image_surface_get_width(argb);
    picture.height = cairo_image_surface_get_height(argb);
    const int stride = cairo_image_surface_get_stride(argb);
    const unsigned char* data = cairo_image_surface_get_data(argb);
    for (int y = 0; y < picture.height; ++y) {
      const auto* row = reinterpret_cast<const std::uint32_t*>(data + size_t(y) * size_t(stride));
      picture.argb.insert(picture.argb.end(), row, row + picture.width);
    }
    cairo_surface_destroy(argb);
  }
  cairo_surface_destroy(image);
  return picture;
}

}  // namespace gem::test
