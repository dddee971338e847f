// gem movie (movie.hpp): frames drawn through Cairo, piped raw to ffmpeg.
#include "framework/analysis/movie.hpp"

#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstring>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "framework/analysis/cairo_canvas.hpp"
#include "framework/analysis/frame_picture.hpp"
#include "framework/analysis/frame_series.hpp"
#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/output/run_folder.hpp"

namespace gem {

namespace fs = std::filesystem;

namespace {

// "WxH", each even (H.264 in yuv420p halves both) and 16 to 7680.
std::pair<int, int> parseSize(const std::string& text) {
  int w = 0, h = 0;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%dx%d%c", &w, &h, &tail) != 2 || w < 16 || h < 16 || w > 7680 || h > 7680 || w % 2 || h % 2)
    throw InputError(fmt::format("--size {}: expected WxH, each an even number of pixels from 16 to 7680 (e.g. 1280x720)", text));
  return {w, h};
}

bool onPath(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

std::string shellQuoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// While alive, a write to a pipe whose reader died fails with EPIPE instead of killing gem.
class PipeSignalIgnored {
 public:
  PipeSignalIgnored() : m_previous(std::signal(SIGPIPE, SIG_IGN)) {}
  ~PipeSignalIgnored() { std::signal(SIGPIPE, m_previous); }

 private:
  void (*m_previous)(int);
};

std::string lastLines(const fs::path& file) {
  std::ifstream in(file);
  std::string text((std::istreambuf_iterator<char>(in)), {});
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text.size() > 600 ? "..." + text.substr(text.size() - 600) : text;
}

void encode(const fs::path& ice, FramePainter& painter, CairoCanvas& canvas, int fps, const fs::path& out) {
  if (!onPath("ffmpeg"))
    throw std::runtime_error(
        "ffmpeg not found on PATH: gem movie encodes with it (Debian: apt-get install ffmpeg; scripts/setup.sh installs it)");
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  const fs::path temp = out.string() + suffix, log = fs::temp_directory_path() / ("gem-ffmpeg" + suffix + ".log");
  const std::string command = fmt::format(
      "ffmpeg -hide_banner -loglevel error -nostdin -f rawvideo -pix_fmt bgra -s {}x{} -r {} -i - -c:v libx264 -pix_fmt yuv420p "
      "-movflags +faststart -f mp4 -y {} 2> {}",
      canvas.width(), canvas.height(), fps, shellQuoted(temp.string()), shellQuoted(log.string()));
  std::error_code ec;
  bool written = true;
  int status = -1;
  {
    const PipeSignalIgnored guard;
    FILE* pipe = ::popen(command.c_str(), "w");
    if (!pipe) throw std::runtime_error(fmt::format("cannot start ffmpeg: {}", std::strerror(errno)));
    const size_t row = size_t(canvas.width()) * 4;
    size_t k = 0;
    try {
      forEachFrame(ice, [&](const FrameState& frame) {
        if (!written) return;  // ffmpeg has stopped reading: nothing more to draw
        painter.draw(canvas, frame, k++);
        const std::uint8_t* pixels = canvas.pixels();
        for (int y = 0; y < canvas.height() && written; ++y)
          written = std::fwrite(pixels + size_t(y) * size_t(canvas.stride()), 1, row, pipe) == row;
      });
    } catch (...) {
      ::pclose(pipe);
      fs::remove(temp, ec);
      fs::remove(log, ec);
      throw;
    }
    status = ::pclose(pipe);
  }
  const bool ok = written && status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!ok) {
    const std::string why = lastLines(log);
    fs::remove(temp, ec);
    fs::remove(log, ec);
    throw std::runtime_error(fmt::format("ffmpeg failed to encode {} ({}){}{}", out.string(),
                                         WIFEXITED(status) ? fmt::format("exit status {}", WEXITSTATUS(status)) : "killed",
                                         why.empty() ? "" : ": ", why));
  }
  fs::remove(log, ec);
  fs::rename(temp, out, ec);
  if (ec) {
    fs::remove(temp);
    throw std::runtime_error(fmt::format("cannot rename the movie onto {}: {}", out.string(), ec.message()));
  }
}

}  // namespace

MovieResult writeMovie(const MovieOptions& o) {
  const auto [width, height] = parseSize(o.size);
  if (o.fps < 1 || o.fps > 240) throw InputError(fmt::format("--fps {}: expected 1 to 240 frames per second", o.fps));
  const FrameColor color = parseFrameColor(o.color);
  if (o.still && o.out.empty()) throw InputError("--still needs --out FILE.png: where to write the picture");
  if (o.still && o.out.extension() != ".png" && o.out.extension() != ".PNG")
    throw InputError(fmt::format("--out {}: --still writes a PNG picture: give a name ending in .png", o.out.string()));
  requireFolder(o.runDir, "run folder");
  const fs::path ice = o.runDir / "frames.ice";
  if (!holdsFile(ice, "frames.ice"))
    throw InputError(
        fmt::format("{}: no frames.ice to draw (run with output.frame_every > 0 and \"ice\" in output.formats)", o.runDir.string()));
  // Two passes over the file: one to fit the view and the colour range, one to draw; a large run's
  // frames never sit in memory together.
  FramePainter painter(color, width, height);
  forEachFrame(ice, [&](const FrameState& frame) { painter.survey(frame); });
  const size_t frames = painter.frameCount();
  if (frames == 0) throw InputError(ice.string() + ": holds no frame");
  CairoCanvas canvas(width, height);
  MovieResult result{o.out, 0, width, height};
  if (o.still) {
    const long k = *o.still;
    if (k < 0 || size_t(k) >= frames) throw InputError(fmt::format("--still {}: {} holds frames 0 to {}", k, ice.string(), frames - 1));
    size_t index = 0;
    forEachFrame(ice, [&](const FrameState& frame) {
      if (index == size_t(k)) painter.draw(canvas, frame, index);
      ++index;
    });
    canvas.writePng(o.out);
    result.frames = 1;
    return result;
  }
  if (result.file.empty()) result.file = o.runDir / kMovieFile;
  encode(ice, painter, canvas, o.fps, result.file);
  result.frames = frames;
  return result;
}

}  // namespace gem
