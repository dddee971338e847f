// `gem movie RUN` (docs/scenario.md "Plots and movie"): the frames of RUN/frames.ice drawn with
// FramePainter and encoded by ffmpeg (Debian's, from PATH) into an H.264 MP4, or one frame as a
// PNG (--still). The movie is written under a temporary name and renamed when ffmpeg succeeds, so
// a failed or interrupted encoding never leaves a half movie.
#pragma once
#include <filesystem>
#include <optional>
#include <string>

namespace gem {

struct MovieOptions {
  std::filesystem::path runDir;
  std::filesystem::path out;  // default RUN/movie.mp4; with still, required (a .png)
  int fps = 10;
  std::string color = "speed";  // speed, thickness or id
  std::string size = "1280x720";
  std::optional<long> still;  // a frame index: one PNG instead of the movie
};

struct MovieResult {
  std::filesystem::path file;
  std::size_t frames = 0;  // frames drawn
  int width = 0, height = 0;
};

// Throws InputError naming the folder when it holds no frames.ice, or for a bad option (size,
// fps, still index out of range); std::runtime_error when ffmpeg is missing or fails (its last
// message quoted).
MovieResult writeMovie(const MovieOptions& options);

}  // namespace gem
