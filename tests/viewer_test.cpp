// gem view: the page written for a real run, opened in Debian's headless chromium (no mock): it
// must draw without a script error, show floes on its canvas, and change when stepped.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <string>

#ifdef GEM_HAVE_CAIRO
#include <cairo.h>
#endif

#include "framework/analysis/frame_series.hpp"
#include "framework/analysis/view_page.hpp"
#include "framework/world/constants.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::TempDir;

namespace {

// The water behind the floes (view_script.cpp's kBackground): its pixels locate the canvas.
constexpr std::array<int, 3> kWater{0x1b, 0x3a, 0x5c};
constexpr std::array<int, 3> kWall{0x8a, 0x8a, 0x8a}, kVessel{0xd6, 0x28, 0x28};

std::string chromiumPath() {
  for (const char* candidate : {"/usr/bin/chromium", "/usr/bin/chromium-browser"})
    if (::access(candidate, X_OK) == 0) return candidate;
  return "";
}

// A small run: the busy channel for 120 steps, a frame every 10, so 13 frames with floes moving,
// the vessel entering, impacts logged and floes breaking.
struct ViewedRun {
  TempDir dir;
  std::filesystem::path run, page;
  int status = -1;
  std::string log;
  ViewedRun() {
    run = dir.path() / "run";
    page = run / "view.html";
    const auto scenario = dir.write("busy.toml", gem::test::kBusyScene);
    const int ran = test::runGem("run " + scenario.string() + " --out " + run.string() + " --quiet --steps 120 --set output.frame_every=10",
                                 dir.path() / "run.log");
    if (ran != 0) {
      log = test::readFile(dir.path() / "run.log");
      return;
    }
    status = test::runGem("view " + run.string(), dir.path() / "view.log");
    log = test::readFile(dir.path() / "view.log");
  }
};

ViewedRun& sharedRun() {
  static ViewedRun run;  // one run for every test here: each gem run costs a second or two
  return run;
}

struct Browsed {
  std::string title, stderrText, dom;
  int status = -1;
};

// Opens the page at `hash` in headless chromium, with a fresh profile; `mode` is "--dump-dom" or
// "--screenshot=PATH". Stopped after 60 s should it hang (killed 5 s later if it ignores that).
Browsed browse(const TempDir& dir, const std::filesystem::path& page, const std::string& hash, const std::string& mode) {
  static int calls = 0;
  const std::string tag = std::to_string(calls++);
  const auto profile = dir.path() / ("profile-" + tag), out = dir.path() / ("dom-" + tag), err = dir.path() / ("stderr-" + tag);
  const std::string command = "timeout -k 5 60 " + chromiumPath() +
                              " --headless --no-sandbox --disable-gpu --enable-logging=stderr --v=0 --window-size=1000,800"
                              " --virtual-time-budget=5000 --user-data-dir=" +
                              profile.string() + " " + mode + " 'file://" + page.string() + "#" + hash + "' > " + out.string() + " 2> " +
                              err.string();
  const int status = std::system(command.c_str());
  Browsed b;
  b.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  b.stderrText = test::readFile(err);
  std::smatch m;
  b.dom = test::readFile(out);
  if (std::regex_search(b.dom, m, std::regex("<title>([^<]*)</title>"))) b.title = m[1];
  return b;
}

// The page's own console lines: it logs nothing, so any line from it is an error or a warning.
void expectNoScriptErrors(const Browsed& b) {
  EXPECT_EQ(b.stderrText.find("Uncaught"), std::string::npos) << b.stderrText;
  EXPECT_EQ(b.stderrText.find("ERROR:CONSOLE"), std::string::npos) << b.stderrText;
  EXPECT_FALSE(std::regex_search(b.stderrText, std::regex("CONSOLE[^\n]*view\\.html"))) << b.stderrText;
}

#ifdef GEM_HAVE_CAIRO
struct Screenshot {
  int width = 0, height = 0;
  std::vector<std::array<int, 3>> pixels;
  const std::array<int, 3>& at(int x, int y) const { return pixels[size_t(y) * size_t(width) + size_t(x)]; }
};

Screenshot readPng(const std::filesystem::path& file) {
  Screenshot s;
  cairo_surface_t* surface = cairo_image_surface_create_from_png(file.c_str());
  if (cairo_surface_status(surface) == CAIRO_STATUS_SUCCESS) {
    cairo_surface_flush(surface);
    s.width = cairo_image_surface_get_width(surface);
    s.height = cairo_image_surface_get_height(surface);
    const int stride = cairo_image_surface_get_stride(surface);
    const unsigned char* data = cairo_image_surface_get_data(surface);
    for (int y = 0; y < s.height; ++y)
      for (int x = 0; x < s.width; ++x) {
        std::uint32_t p;  // ARGB32 / RGB24: one native-endian 32-bit word a pixel
        std::memcpy(&p, data + size_t(y) * size_t(stride) + 4 * size_t(x), 4);
        s.pixels.push_back({int(p >> 16 & 255), int(p >> 8 & 255), int(p & 255)});
      }
  }
  cairo_surface_destroy(surface);
  return s;
}

bool near(const std::array<int, 3>& a, const std::array<int, 3>& b, int tolerance) {
  return std::abs(a[0] - b[0]) <= tolerance && std::abs(a[1] - b[1]) <= tolerance && std::abs(a[2] - b[2]) <= tolerance;
}

// The canvas: the bounding box of the water's pixels.
struct CanvasBox {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  long area() const { return x1 < x0 ? 0 : long(x1 - x0 + 1) * (y1 - y0 + 1); }
};
CanvasBox waterBox(const Screenshot& s) {
  CanvasBox b;
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x)
      if (near(s.at(x, y), kWater, 2))
        b.x0 = std::min(b.x0, x), b.y0 = std::min(b.y0, y), b.x1 = std::max(b.x1, x), b.y1 = std::max(b.y1, y);
  return b;
}
#endif

}  // namespace

TEST(View, PageIsSelfContainedAndHoldsEveryFrame) {
  const ViewedRun& r = sharedRun();
  ASSERT_EQ(r.status, 0) << r.log;
  EXPECT_NE(r.log.find("view.html"), std::string::npos) << r.log;  // it prints the page's path
  const std::string html = test::readFile(r.page);
  const size_t frames = readFrameSeries(r.run / "frames.ice").size();
  ASSERT_EQ(frames, 13u);
  EXPECT_NE(html.find("<meta name=\"gem-frames\" content=\"13\">"), std::string::npos);
  EXPECT_EQ(html.find("http://"), std::string::npos);
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);
  EXPECT_NE(html.find("\"ice_force_x\":\""), std::string::npos);  // the time series are embedded
  EXPECT_NE(html.find("floes <b>"), std::string::npos);           // and the summary's header
}

TEST(View, EveryNthFrameKeepsTheLast) {
  const ViewedRun& r = sharedRun();
  ASSERT_EQ(r.status, 0) << r.log;
  TempDir dir;
  ASSERT_EQ(test::runGem("view " + r.run.string() + " --every 5 --out " + (dir.path() / "thin.html").string(), dir.path() / "log"), 0);
  // Frames 0, 5, 10 and the last, 12.
  const std::string html = test::readFile(dir.path() / "thin.html");
  EXPECT_NE(html.find("<meta name=\"gem-frames\" content=\"4\">"), std::string::npos);
  EXPECT_NE(html.find("\"source\":[0,5,10,12]"), std::string::npos);
}

TEST(View, TooLargeAPageIsThinned) {
  const ViewedRun& r = sharedRun();
  ASSERT_EQ(r.status, 0) << r.log;
  TempDir dir;
  ViewOptions options;
  options.dir = r.run.string();
  options.out = (dir.path() / "thin.html").string();
  options.quiet = true;
  options.maxBytes = 1;  // any page is too large: every frame but the first and the last goes
  EXPECT_EQ(runView(options), 0);
  const std::string html = test::readFile(dir.path() / "thin.html");
  EXPECT_NE(html.find("<meta name=\"gem-frames\" content=\"2\">"), std::string::npos);
  EXPECT_NE(html.find("<meta name=\"gem-frame-every\" content=\""), std::string::npos);
  EXPECT_EQ(html.find("<meta name=\"gem-frame-every\" content=\"1\">"), std::string::npos);
}

TEST(View, FolderWithoutFramesIsRefused) {
  TempDir dir;
  const int status = test::runGem("view " + dir.path().string(), dir.path() / "log");
  const std::string log = test::readFile(dir.path() / "log");
  EXPECT_EQ(status, 2) << log;
  EXPECT_NE(log.find(dir.path().string()), std::string::npos) << log;
  EXPECT_NE(log.find("no frames.ice"), std::string::npos) << log;
  EXPECT_NE(log.find("\"ice\""), std::string::npos) << log;  // the fix: output.formats
}

TEST(View, DrawsInHeadlessChromiumAndStepping) {
  if (chromiumPath().empty()) GTEST_SKIP() << "chromium is not installed (scripts/setup.sh installs it): the page was not opened";
  const ViewedRun& r = sharedRun();
  ASSERT_EQ(r.status, 0) << r.log;
  TempDir dir;
  const std::string last = std::to_string(readFrameSeries(r.run / "frames.ice").size() - 1);

  for (const std::string& frame : {std::string("0"), last}) {
    SCOPED_TRACE("frame " + frame);
    const Browsed dom = browse(dir, r.page, "frame=" + frame, "--dump-dom");
    EXPECT_EQ(dom.status, 0);
    EXPECT_EQ(dom.title, "gem view: frame " + frame + " drawn") << dom.stderrText;
    expectNoScriptErrors(dom);
  }
  // Another colouring draws too (the id colours' path through the script).
  const Browsed byId = browse(dir, r.page, "frame=3&color=id", "--dump-dom");
  EXPECT_EQ(byId.title, "gem view: frame 3 drawn") << byId.stderrText;
  expectNoScriptErrors(byId);

  // Hovering a floe (#hover puts the pointer on a world point) shows its id and mass.
  const FrameState start = readFrameSeries(r.run / "frames.ice").front();
  const auto floe = std::find_if(start.bodies.begin(), start.bodies.end(), [](const FrameBody& b) { return b.kind == BodyKind::Floe; });
  ASSERT_NE(floe, start.bodies.end());
  double cx = 0, cy = 0, area = 0;  // the vertex mean lies inside a convex polygon
  for (size_t k = 0; k < floe->vertices.size(); ++k) {
    const Vec2 p = floe->vertices[k], q = floe->vertices[(k + 1) % floe->vertices.size()];
    cx += p.x / double(floe->vertices.size()), cy += p.y / double(floe->vertices.size());
    area += (p.x * q.y - q.x * p.y) / 2;
  }
  const Browsed hover = browse(dir, r.page, "frame=0&hover=" + std::to_string(cx) + "," + std::to_string(cy), "--dump-dom");
  expectNoScriptErrors(hover);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(hover.dom, m, std::regex("<div id=\"tip\"[^>]*>floe (\\d+)\\s+mass ([0-9.e+]+) t")))
      << hover.dom.substr(0, 3000);
  EXPECT_EQ(std::stoll(m[1]), floe->id);
  EXPECT_NEAR(std::stod(m[2]), area * floe->thickness * kRhoIce / 1000, 1e-3 * area * floe->thickness * kRhoIce / 1000);

#ifdef GEM_HAVE_CAIRO
  const auto firstPng = dir.path() / "first.png", lastPng = dir.path() / "last.png";
  expectNoScriptErrors(browse(dir, r.page, "frame=0", "--screenshot=" + firstPng.string()));
  expectNoScriptErrors(browse(dir, r.page, "frame=" + last, "--screenshot=" + lastPng.string()));
  const Screenshot first = readPng(firstPng), end = readPng(lastPng);
  ASSERT_EQ(first.width, 1000);
  ASSERT_EQ(end.height, first.height);

  // The canvas is there and large, and it shows ice: floes of 45 % concentration over a third of
  // the canvas cover about a tenth of it; the frame's caption, well under 1 %. The water, the
  // walls and the vessel are not counted.
  const CanvasBox box = waterBox(first);
  ASSERT_GT(box.area(), 200L * 200L);
  long ice = 0, changed = 0;
  for (int y = box.y0; y <= box.y1; ++y)
    for (int x = box.x0; x <= box.x1; ++x) {
      const auto& p = first.at(x, y);
      if (!near(p, kWater, 12) && !near(p, kWall, 6) && !near(p, kVessel, 6)) ++ice;
      if (!near(p, end.at(x, y), 30)) ++changed;
    }
  EXPECT_GT(ice, box.area() / 20) << "canvas " << box.x1 - box.x0 + 1 << "x" << box.y1 - box.y0 + 1;
  // The vessel sailed about 50 m into the field and pushed floes: far more than the caption changes.
  EXPECT_GT(changed, box.area() / 100);
#else
  GTEST_SKIP() << "built without Cairo (libcairo2-dev): the screenshots were not checked";
#endif
}
