// runView: packs the run's files into the page's JSON and writes the page (view_page.hpp).
#include "framework/analysis/view_page.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <numeric>
#include <ostream>
#include <vector>

#include "framework/output/csv.hpp"
#include "framework/analysis/sweep_summary.hpp"
#include "framework/analysis/view_pack.hpp"
#include "framework/api/input_size.hpp"
#include "framework/analysis/view_script.hpp"
#include "framework/api/errors.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/world/constants.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

// Appends the base64 of size bytes to out (appended in place: a 10^5-floe frame is 2 MB of text).
void appendBase64(std::string& out, const void* data, size_t size) {
  static constexpr char kDigits[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  out.reserve(out.size() + (size + 2) / 3 * 4);
  size_t k = 0;
  for (; k + 2 < size; k += 3) {
    const unsigned v = unsigned(p[k]) << 16 | unsigned(p[k + 1]) << 8 | p[k + 2];
    out += {kDigits[v >> 18], kDigits[(v >> 12) & 63], kDigits[(v >> 6) & 63], kDigits[v & 63]};
  }
  if (k + 1 == size) {
    const unsigned v = unsigned(p[k]) << 16;
    out += {kDigits[v >> 18], kDigits[(v >> 12) & 63], '=', '='};
  } else if (k + 2 == size) {
    const unsigned v = unsigned(p[k]) << 16 | unsigned(p[k + 1]) << 8;
    out += {kDigits[v >> 18], kDigits[(v >> 12) & 63], kDigits[(v >> 6) & 63], '='};
  }
}

// The vector's bytes as a quoted base64 JSON string (the page reads them as a typed array).
template <class T>
std::string base64(const std::vector<T>& v) {
  std::string out(1, '"');
  appendBase64(out, v.data(), v.size() * sizeof(T));
  out += '"';
  return out;
}

template <class T>
std::vector<float> asFloats(const std::vector<T>& v) {
  return std::vector<float>(v.begin(), v.end());
}

// A JSON string; "</" is written "<\/" so that no text can close the page's <script> element.
std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (size_t k = 0; k < s.size(); ++k) {
    const unsigned char c = static_cast<unsigned char>(s[k]);
    if (c == '"' || c == '\\')
      out += {'\\', char(c)};
    else if (c == '/' && k > 0 && s[k - 1] == '<')
      out += "\\/";
    else if (c < 0x20)
      out += fmt::format("\\u{:04x}", c);
    else
      out += char(c);
  }
  return out + "\"";
}

// HTML text: the run folder's name may hold any character.
std::string htmlText(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else if (c == '"')
      out += "&quot;";
    else
      out += c;
  }
  return out;
}

std::string shapesJson(const ViewPack& pack) {
  std::vector<double> ids;
  std::vector<std::uint8_t> kinds, pieces;
  std::vector<float> thickness, area, radius, xy;
  std::vector<std::uint32_t> start{0};
  for (const ViewShape& s : pack.shapes) {
    ids.push_back(double(s.id));
    kinds.push_back(std::uint8_t(s.kind));
    pieces.push_back(s.piece ? 1 : 0);
    thickness.push_back(s.thickness);
    area.push_back(s.area);
    radius.push_back(s.radius);
    xy.insert(xy.end(), s.local.begin(), s.local.end());
    start.push_back(std::uint32_t(xy.size() / 2));
  }
  return fmt::format(R"({{"id":{},"kind":{},"piece":{},"thickness":{},"area":{},"radius":{},"start":{},"xy":{}}})", base64(ids),
                     base64(kinds), base64(pieces), base64(thickness), base64(area), base64(radius), base64(start), base64(xy));
}

// The frames' times and poses, straight to the page: they are most of a large page, and building
// them as one string first would hold the page in memory twice.
void writeFramesJson(std::ostream& os, const ViewPack& pack) {
  std::string times, lists, sources;
  for (const ViewFrame& f : pack.frames) {
    const char* comma = times.empty() ? "" : ",";
    times += fmt::format("{}{}", comma, f.time);
    lists += fmt::format("{}{}", comma, f.list);
    sources += fmt::format("{}{}", comma, f.source);
  }
  os << fmt::format(R"({{"time":[{}],"list":[{}],"source":[{}],"poses":[)", times, lists, sources);
  for (size_t k = 0; k < pack.frames.size(); ++k) os << (k ? "," : "") << base64(pack.frames[k].poses);
  os << "]}";
}

std::string listsJson(const ViewPack& pack) {
  std::string out = "[";
  for (const auto& l : pack.lists) {
    if (out.size() > 1) out += ',';
    out += base64(l);
  }
  out += ']';
  return out;
}

// timeseries.csv's three columns the page plots; null when the file is absent.
std::string seriesJson(const fs::path& dir) {
  const fs::path file = dir / "timeseries.csv";
  if (!holdsFile(file, "timeseries.csv")) return "null";
  // readColumns refuses values outside what GEM writes (NaN, inf, a negative time), as gem plot
  // and gem analyze do; empty cells (a run without a vessel) stay NaN.
  const std::vector<std::vector<double>> c = readColumns(file, {"t", "ship_speed", "net_thrust", "ice_force_x"}, true);
  std::string out = "{\"t\":" + base64(asFloats(c[0]));
  const char* names[] = {"ship_speed", "net_thrust", "ice_force_x"};
  for (int k = 0; k < 3; ++k) out += fmt::format(",\"{}\":{}", names[k], base64(asFloats(c[static_cast<size_t>(k) + 1])));
  return out + "}";
}

// impacts.csv's times, places and forces, sorted by time (the page searches them by time).
std::string impactsJson(const fs::path& dir) {
  const fs::path file = dir / "impacts.csv";
  if (!holdsFile(file, "impacts.csv")) return "null";
  const std::vector<std::vector<double>> c = readColumns(file, {"t", "x", "y", "fn"});
  const std::vector<double>&t = c[0], &x = c[1], &y = c[2], &fn = c[3];
  std::vector<size_t> order(t.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return t[a] < t[b]; });
  std::vector<float> st, sx, sy, sf;
  for (size_t k : order) st.push_back(float(t[k])), sx.push_back(float(x[k])), sy.push_back(float(y[k])), sf.push_back(float(fn[k]));
  return fmt::format(R"({{"t":{},"x":{},"y":{},"fn":{}}})", base64(st), base64(sx), base64(sy), base64(sf));
}

// The summary facts the header shows; an empty map when summary.json is absent (a run that failed).
std::map<std::string, std::string> readSummary(const fs::path& dir) {
  const fs::path file = dir / "summary.json";
  return fs::exists(file) ? readSummaryJson(file, "run the scenario again, or delete it and the page shows the run without its summary")
                          : std::map<std::string, std::string>{};
}

std::string summaryHtml(const std::map<std::string, std::string>& summary) {
  if (summary.empty()) return "<span>no summary.json (the run did not finish)</span>";
  const auto get = [&](const std::string& key) {
    const auto it = summary.find(key);
    return it == summary.end() || it->second.empty() ? std::string("-") : it->second;
  };
  const auto number = [&](const std::string& key, const char* format) {
    const std::string v = get(key);
    char* end = nullptr;
    const double d = std::strtod(v.c_str(), &end);
    return end && *end == 0 && v != "-" ? fmt::format(fmt::runtime(format), d) : v;
  };
  const std::pair<const char*, std::string> facts[] = {
      {"floes", get("floes_initial") + " &rarr; " + get("floes_final")},
      {"broken", get("floes_broken")},
      {"impacts", get("impacts")},
      {"mean ship speed", number("ship_speed.mean", "{:.3g}") + " m/s"},
      {"mean resistance", number("resistance_mean_n", "{:.3g}") + " N"},
      {"simulated", number("sim_time_s", "{:.4g}") + " s in " + get("steps") + " steps"},
      {"wall time", number("wall_time_s", "{:.3g}") + " s"},
      {"backend", htmlText(get("backend") + " / " + get("driver") + " (" + get("device") + "), " + get("broadphase"))},
  };
  std::string out;
  for (const auto& [name, value] : facts) out += fmt::format("<span>{} <b>{}</b></span> ", name, value);  // the space lets the line wrap
  return out;
}

}  // namespace

int runView(const ViewOptions& options) {
  const fs::path dir = options.dir;
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    if (fs::is_symlink(fs::symlink_status(dir, ec))) requireFolder(dir, "run folder");  // a loop, a link to nothing
    throw InputError(options.dir + ": not a folder; gem view takes a run folder (gem run ... --out DIR)");
  }
  if (!holdsFile(dir / "frames.ice", "frames.ice"))
    throw InputError(options.dir +
                     ": no frames.ice in this folder; run the scenario with [output] formats including \"ice\" (the default) and "
                     "frame_every > 0, then gem view the run folder");
  if (options.every < 0) throw InputError(fmt::format("--every {}: must be 1 or more", options.every));

  ViewPack pack = packFrames(dir / "frames.ice", std::max(options.every, 1));
  const size_t framesRead = pack.frames.size();
  // Base64 makes 4 bytes of 3; the script, series and impacts are small beside the frames.
  const std::uint64_t estimate = pack.payloadBytes() * 4 / 3;
  if (options.every == 0 && estimate > options.maxBytes) {
    const int thin = int(estimate / std::max<std::uint64_t>(options.maxBytes, 1)) + 1;
    thinFrames(pack, thin);
    if (!options.quiet)
      std::printf("gem view: all %zu frames would make a page of about %llu MB; keeping every %d-th (--every N to choose)\n", framesRead,
                  static_cast<unsigned long long>(estimate >> 20), thin);
  }

  const std::map<std::string, std::string> summary = readSummary(dir);
  // "runs/x/" has an empty filename(): the folder's name is then its parent_path's.
  fs::path absolute = fs::absolute(dir).lexically_normal();
  if (absolute.filename().empty()) absolute = absolute.parent_path();
  const std::string title = absolute.filename().string();
  std::string summaryFacts;
  for (const auto& [key, value] : summary) {
    if (!summaryFacts.empty()) summaryFacts += ',';
    summaryFacts += jsonString(key);
    summaryFacts += ':';
    summaryFacts += jsonString(value);
  }
  const std::string data =
      fmt::format(R"({{"run":{},"every":{},"bounds":[{},{},{},{}],"speedScale":{},"thickness":[{},{}],"rhoIce":{},)"
                  R"("shapes":{},"lists":{},"series":{},"impacts":{},"summary":{{{}}},"frames":)",
                  jsonString(title), pack.every, pack.minX, pack.minY, pack.maxX, pack.maxY, pack.speedScale, pack.minThickness,
                  pack.maxThickness, double(kRhoIce), shapesJson(pack), listsJson(pack), seriesJson(dir), impactsJson(dir), summaryFacts);

  std::string head = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  head += fmt::format("<meta name=\"gem-frames\" content=\"{}\">\n<meta name=\"gem-frame-every\" content=\"{}\">\n", pack.frames.size(),
                      pack.every);
  head += "<title>gem view: loading " + htmlText(title) + "</title>\n<style>" + std::string(viewStyle()) + "</style>\n</head>\n<body>\n";
  head += "<header><h1>gem view: " + htmlText(title) + "</h1><div class=\"facts\">" + summaryHtml(summary) + "</div></header>\n";
  head += R"H(<div id="bar"><button id="back" title="step back (left arrow)">&#9664;</button>)H"
          R"H(<button id="play" title="play or pause (space)">play</button>)H"
          R"H(<button id="forward" title="step forward (right arrow)">&#9654;</button>)H"
          R"H(<input id="seek" type="range" min="0" value="0" step="1"><span id="clock"></span>)H"
          R"H(<label>fps <select id="fps"><option>2</option><option>5</option><option selected>10</option><option>20</option>)H"
          R"H(<option>30</option><option>60</option></select></label>)H"
          R"H(<label>colour by <select id="colour"><option value="speed">speed</option><option value="thickness">thickness</option>)H"
          R"H(<option value="id">id</option></select></label><button id="fit" title="zoom to the whole field">fit</button></div>)H"
          "\n";
  head += R"H(<div id="legend"><span id="scale-lo"></span><canvas id="bar-scale" width="160" height="12"></canvas>)H"
          R"H(<span id="scale-hi"></span><span class="note">vessel: red; walls: grey; broken pieces: dark outline;)H"
          R"H( impacts since the last frame: cyan rings; wheel: zoom, drag: pan, hover: a body's facts</span>)H";
  if (pack.every > 1) head += fmt::format(R"H(<span class="note">every {}-th frame of frames.ice</span>)H", pack.every);
  head += "</div>\n<canvas id=\"view\"></canvas>\n<canvas id=\"series\"></canvas>\n<div id=\"tip\"></div>\n";

  // Atomically, as every output: an interrupted gem view leaves no half page.
  const fs::path out = options.out.empty() ? dir / "view.html" : fs::path(options.out);
  AtomicFile file(out);
  std::ostream& os = file.stream();
  os << head << "<script id=\"gem-data\" type=\"application/json\">" << data;
  writeFramesJson(os, pack);
  os << "}</script>\n<script>" << viewScript() << "</script>\n</body>\n</html>\n";
  file.commit();
  if (!options.quiet) std::printf("%s\n", out.string().c_str());
  return 0;
}

}  // namespace gem
