// gem movie (issue "The user's day", item 3): a run's frames drawn with Cairo and encoded by
// ffmpeg into an H.264 MP4 with one movie frame per saved frame; --still writes one frame as a PNG;
// a folder without frames.ice, a bad option or a missing ffmpeg is refused and leaves no movie.
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <sstream>

#include <fmt/format.h>

#include "picture_support.hpp"

using namespace gem;
using gem::test::TempDir;
namespace fs = std::filesystem;

namespace {

bool onPath(const std::string& program) {
  std::stringstream dirs(std::getenv("PATH") ? std::getenv("PATH") : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    if (::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

#define SKIP_WITHOUT_FFMPEG() \
  if (!onPath("ffmpeg") || !onPath("ffprobe")) GTEST_SKIP() << "ffmpeg and ffprobe are not installed (scripts/setup.sh installs them)"

// What ffprobe says of the video stream: "codec_name=h264\nwidth=...\n...".
std::string probe(const fs::path& movie) {
  const std::string command =
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=codec_name,width,height,nb_read_frames -of default=noprint_wrappers=1 '" +
      movie.string() + "' 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(::popen(command.c_str(), "r"), ::pclose);
  std::string out;
  char buffer[256];
  while (pipe && std::fgets(buffer, sizeof buffer, pipe.get())) out += buffer;
  return out;
}

// The frames frames.ice holds.
size_t frameCount(const fs::path& run) {
  const std::string ice = test::readFile(run / "frames.ice");
  size_t n = 0;
  for (size_t at = ice.find("<frame "); at != std::string::npos; at = ice.find("<frame ", at + 1)) ++n;
  return n;
}

bool leftTemporaries(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir))
    if (entry.path().filename().string().find(".tmp-") != std::string::npos) return true;
  return false;
}

constexpr std::uint32_t kVessel = 0xC0392B, kWater = 0xCFE2F3, kThinnest = 0x440154;  // frame_picture.cpp

}  // namespace

TEST(Movie, IsH264WithOneFrameForEachSavedFrame) {
  SKIP_WITHOUT_FFMPEG();
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  const size_t frames = frameCount(run);
  ASSERT_GT(frames, 20u);
  ASSERT_EQ(test::runGem("movie " + run.string() + " --size 320x240 --fps 12", dir.path() / "movie.log"), 0)
      << test::readFile(dir.path() / "movie.log");
  const std::string info = probe(run / "movie.mp4");
  EXPECT_NE(info.find("codec_name=h264"), std::string::npos) << info;
  EXPECT_NE(info.find("width=320"), std::string::npos) << info;
  EXPECT_NE(info.find("height=240"), std::string::npos) << info;
  EXPECT_NE(info.find("nb_read_frames=" + std::to_string(frames) + "\n"), std::string::npos) << info << "expected " << frames << " frames";
  EXPECT_FALSE(leftTemporaries(run));
  // A re-run of the case removes the movie, which would show the old run.
  ASSERT_FALSE(test::makeBusyRun(dir).empty());
  EXPECT_FALSE(fs::exists(run / "movie.mp4"));
}

TEST(Movie, StillShowsTheFloesAndTwoFramesDiffer) {
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  const fs::path first = dir.path() / "first.png", later = dir.path() / "later.png";
  // Every floe of kBusyScene is 0.4 m thick: coloured by thickness, all take the scale's lowest colour.
  for (const auto& [k, png] : {std::pair{0, first}, std::pair{25, later}})
    ASSERT_EQ(test::runGem(fmt::format("movie {} --still {} --out {} --color thickness --size 640x360", run.string(), k, png.string()),
                           dir.path() / "still.log"),
              0)
        << test::readFile(dir.path() / "still.log");
  const test::Picture a = test::readPng(first), b = test::readPng(later);
  ASSERT_EQ(a.width, 640);
  ASSERT_EQ(a.height, 360);
  ASSERT_EQ(b.argb.size(), a.argb.size());
  EXPECT_GT(a.count(kThinnest, 8), 5000) << "no floes drawn";
  EXPECT_GT(a.count(kWater), 5000) << "no open water drawn";
  EXPECT_GT(b.count(kVessel), 300) << "no vessel drawn";  // at frame 0 its bow only enters the view
  long differing = 0;
  for (size_t i = 0; i < a.argb.size(); ++i) differing += a.argb[i] != b.argb[i];
  EXPECT_GT(differing, 2000) << "frames 0 and 25 look alike: the vessel has moved 15 s between them";
  // Coloured by id, the floes take many colours and the thickness scale's is gone (no colour bar).
  const fs::path byId = dir.path() / "id.png";
  ASSERT_EQ(test::runGem("movie " + run.string() + " --still 0 --color id --size 640x360 --out " + byId.string(), dir.path() / "still.log"),
            0)
      << test::readFile(dir.path() / "still.log");
  const test::Picture c = test::readPng(byId);
  EXPECT_LT(c.count(kThinnest, 8), 50);
  EXPECT_GT(c.count(kWater), 5000);
}

TEST(Movie, AFolderWithoutFramesIsRefusedByName) {
  TempDir dir;
  const fs::path empty = dir.path() / "no-frames";
  fs::create_directories(empty);
  EXPECT_EQ(test::runGem("movie " + empty.string(), dir.path() / "movie.log"), 2);
  const std::string log = test::readFile(dir.path() / "movie.log");
  EXPECT_NE(log.find(empty.string()), std::string::npos) << log;
  EXPECT_NE(log.find("frames.ice"), std::string::npos) << log;
  EXPECT_FALSE(fs::exists(empty / "movie.mp4"));
}

TEST(Movie, BadOptionsAreRefused) {
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  for (const char* options : {"--size 321x240", "--size big", "--fps 0", "--color salinity", "--still 999 --out x.png", "--still 0"}) {
    EXPECT_EQ(test::runGem("movie " + run.string() + " " + std::string(options), dir.path() / "movie.log"), 2) << options;
    EXPECT_NE(test::readFile(dir.path() / "movie.log").find("error"), std::string::npos) << options;
  }
  EXPECT_FALSE(fs::exists(run / "movie.mp4"));
}

TEST(Movie, WithoutFfmpegFailsAndLeavesNoMovie) {
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", dir.path().c_str(), 1);  // gem is started by its full path; ffmpeg is not found
  const int status = test::runGem("movie " + run.string() + " --size 64x48", dir.path() / "movie.log");
  ::setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(status, 1);
  EXPECT_NE(test::readFile(dir.path() / "movie.log").find("ffmpeg not found"), std::string::npos)
      << test::readFile(dir.path() / "movie.log");
  EXPECT_FALSE(fs::exists(run / "movie.mp4"));
  EXPECT_FALSE(leftTemporaries(run));
}

TEST(Movie, AFailingFfmpegLeavesNoHalfMovie) {
  SKIP_WITHOUT_FFMPEG();
  TempDir dir;
  const fs::path run = test::makeBusyRun(dir);
  ASSERT_FALSE(run.empty()) << test::readFile(dir.path() / "run.log");
  // An ffmpeg that reads a little, writes a partial file where the movie's temporary goes, and fails.
  const fs::path bin = dir.path() / "bin";
  fs::create_directories(bin);
  std::ofstream(bin / "ffmpeg") << "#!/bin/sh\nfor last; do :; done\nhead -c 1000 > \"$last\"\necho 'broken encoder' >&2\nexit 3\n";
  fs::permissions(bin / "ffmpeg", fs::perms::owner_all);
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", (bin.string() + ":" + path).c_str(), 1);
  const int status = test::runGem("movie " + run.string() + " --size 64x48", dir.path() / "movie.log");
  ::setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(status, 1);
  EXPECT_NE(test::readFile(dir.path() / "movie.log").find("broken encoder"), std::string::npos) << test::readFile(dir.path() / "movie.log");
  EXPECT_FALSE(fs::exists(run / "movie.mp4"));
  EXPECT_FALSE(leftTemporaries(run));
}
