// Running the gem binary from a test and comparing two run folders (the checkpoint tests, CPU and
// CUDA: a resumed run must end with the files of the run that was never stopped).
#pragma once
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <pugixml.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "framework/analysis/sweep_summary.hpp"
#include "test_support.hpp"

namespace gem::test {

inline std::string gemBinary() {
  return std::string(std::getenv("GEM_BINARY_DIR") ? std::getenv("GEM_BINARY_DIR") : GEM_BINARY_DIR) + "/gem";
}

// Runs a shell script; returns its exit status (-1 when it did not exit).
inline int shell(const std::string& script) {
  const std::string command = "bash -c '" + script + "'";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The files a run folder holds (frames/ included), relative, sorted; gem.log and the plots aside.
inline std::vector<std::string> filesOf(const std::filesystem::path& dir) {
  std::vector<std::string> files;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(std::filesystem::relative(entry.path(), dir).string());
  std::sort(files.begin(), files.end());
  return files;
}

// Every output of `resumed` is byte for byte that of `whole`, summary.json but for the wall time.
inline void expectSameRun(const std::filesystem::path& whole, const std::filesystem::path& resumed) {
  const std::vector<std::string> files = filesOf(whole);
  EXPECT_EQ(filesOf(resumed), files);
  for (const std::string& f : files) {
    // scenario.toml records the runs' own settings (output.checkpoint_every) and gem.log their commands.
    if (f == "gem.log" || f == "summary.json" || f == ".gem-run.lock" || f == "scenario.toml") continue;
    EXPECT_TRUE(readFile(whole / f) == readFile(resumed / f)) << f << " differs";
  }
  auto summary = readSummaryJson(whole / "summary.json"), again = readSummaryJson(resumed / "summary.json");
  for (const char* key : {"wall_time_s", "real_time_factor"}) summary.erase(key), again.erase(key);
  EXPECT_EQ(summary, again);
}

// A shell loop that waits (at most 30 s) until `file` exists: a signal is sent only once the run
// has got that far, whatever the machine's speed.
inline std::string waitFor(const std::filesystem::path& file) {
  return "for i in $(seq 6000); do [ -e " + file.string() + " ] && break; sleep 0.005; done; ";
}

// The vessel pushing one floe, a second floe far off its path, a frame every step (ParaView only):
// the frames' contact_force (expectContactForcesInFrames), on every backend.
inline constexpr const char* kContactForceScene = R"(
[simulation]
dt = 0.1
steps = 30
[vessel]
position = [-60.0, 0.0]
open_water_speed = 5.0
[[floes]]
vertices = [[0.0, -3.0], [6.0, -3.0], [6.0, 3.0], [0.0, 3.0]]
[[floes]]
vertices = [[40.0, 20.0], [44.0, 20.0], [44.0, 24.0], [40.0, 24.0]]
[events.flexural_breaking]
enabled = false  # a floe split after the gather has new ids, whose force the frame cannot carry
[output]
frame_every = 1
formats = ["vtk"]
)";

// Frames 1 to 30 of a run of kContactForceScene: each body's contact_force is there, the far floe
// never has any, the vessel's is at most the floes' sum, and with one floe on the vessel alone the
// two sides are equal (equal and opposite impulses).
inline void expectContactForcesInFrames(const std::filesystem::path& out) {
  double far = 0;
  int framesOneOnOne = 0, framesWithContact = 0;
  for (int f = 1; f <= 30; ++f) {
    pugi::xml_document vtp;
    ASSERT_TRUE(vtp.load_file((out / "frames" / fmt::format("frame_{:06d}.vtp", f)).c_str()));
    pugi::xml_node cells = vtp.child("VTKFile").child("PolyData").child("Piece").child("CellData");
    auto values = [&](const char* name) {
      std::istringstream in(cells.find_child_by_attribute("DataArray", "Name", name).text().get());
      std::vector<double> v;
      for (double x; in >> x;) v.push_back(x);
      return v;
    };
    const std::vector<double> areas = values("area"), kinds = values("kind"), force = values("contact_force");
    ASSERT_EQ(force.size(), areas.size());
    double vessel = 0, floes = 0;
    int touching = 0;
    for (size_t i = 0; i < areas.size(); ++i) {
      if (kinds[i] == 1) {
        vessel = force[i];
      } else if (std::abs(areas[i] - 16.0) < 1e-9) {  // the 4 m x 4 m floe far off the vessel's path
        far = std::max(far, force[i]);
      } else {
        floes += force[i];
        touching += force[i] > 0;
      }
    }
    framesWithContact += vessel > 0;
    EXPECT_LE(vessel, floes * (1 + 1e-9) + 1e-9) << "frame " << f;  // |sum| <= sum of magnitudes
    // One floe (or piece) on the vessel alone: the pair's two sides, equal and opposite.
    if (touching == 1 && vessel > 0) {
      ++framesOneOnOne;
      EXPECT_NEAR(vessel, floes, 1e-9 * floes) << "frame " << f;
    }
  }
  EXPECT_GT(framesWithContact, 0);
  EXPECT_GT(framesOneOnOne, 0);
  EXPECT_EQ(far, 0);
}

}  // namespace gem::test
