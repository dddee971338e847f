// The scenes whose golden hashes guard refactorings (tests/golden_test.cpp on the CPU,
// tests/cuda/golden_cuda_test.cpp on the device): every scenario under scenarios/, the first two
// cases of every sweep there, and the tests' busy channel under each built-in broadphase.
#pragma once
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "framework/scenario/scenario.hpp"
#include "framework/scenario/sweep_file.hpp"
#include "framework/step/stepper.hpp"
#include "tests/golden_hash.hpp"
#include "tests/test_support.hpp"

namespace gem::test {

struct GoldenScene {
  std::string name;            // letters, digits and '_' (a test name)
  std::filesystem::path file;  // the scenario (empty: the busy scene)
  std::vector<std::string> overrides;
};

// gtest names a parameter by this (not by its bytes) in ctest's listing.
inline void PrintTo(const GoldenScene& scene, std::ostream* os) { *os << scene.name; }

// At most this many steps of each scene: long enough for the vessel to meet the ice, re-sort
// three or more times and break floes; short enough for a test of a few seconds.
inline constexpr long kGoldenSteps = 1000;

inline std::string sceneName(std::string text) {
  for (char& c : text)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return text;
}

// The source tree: $GEM_SOURCE_DIR where set (a staged copy on the GPU machine), else the build's.
inline std::filesystem::path sourceDir() {
  const char* staged = std::getenv("GEM_SOURCE_DIR");
  return staged ? std::filesystem::path(staged) : std::filesystem::path(GEM_SOURCE_DIR);
}

inline std::vector<GoldenScene> goldenScenes() {
  namespace fs = std::filesystem;
  std::vector<GoldenScene> scenes;
  const fs::path root = sourceDir() / "scenarios";
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(root))
    if (entry.is_regular_file() && entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    const std::string stem = sceneName(fs::relative(file, root).replace_extension().string());
    const bool sweep = readFile(file).find("[sweep]") != std::string::npos;
    if (!sweep) {
      GoldenScene scene{stem, file, {}};
      // The calibration base has no ice of its own (gem calibrate adds each case's floe): one
      // floe off the starboard bow, struck as in the calibration's cases.
      if (file.filename() == "calibration.toml")
        scene.overrides.push_back("floes=[{vertices=[[56.0,-9.0],[66.0,-9.0],[66.0,1.0],[56.0,1.0]],thickness=0.7}]");
      scenes.push_back(scene);
      continue;
    }
    const SweepDefinition sweepFile = readSweepFile(file);
    for (size_t k = 0; k < std::min<size_t>(2, sweepFile.cases.size()); ++k) {
      GoldenScene scene{stem + "_" + sceneName(sweepFile.cases[k].name), sweepFile.cases[k].base, {}};
      for (const SweepOverride& o : sweepFile.cases[k].overrides) scene.overrides.push_back(o.key + "=" + o.toml);
      scenes.push_back(scene);
    }
  }
  for (const char* broadphase : {"all_pairs", "fixed_radius", "variable_radius", "uniform_grid", "triangulation_mesh"})
    scenes.push_back({std::string("busy_") + broadphase, {}, {std::string("simulation.broadphase=\"") + broadphase + "\""}});
  return scenes;
}

// The scene's scenario on `backend`, its outputs in `dir` and none written but what a run needs.
inline Scenario loadGoldenScene(const GoldenScene& scene, const TempDir& dir, const std::string& backend,
                                const std::vector<std::string>& extra = {}) {
  std::vector<std::string> overrides = scene.overrides;
  overrides.insert(overrides.end(), extra.begin(), extra.end());
  overrides.push_back("simulation.backend=\"" + backend + "\"");
  overrides.push_back("output.frame_every=0");
  overrides.push_back("output.dir=\"" + dir.path().string() + "\"");
  if (scene.file.empty()) return scenarioFromToml(dir, kBusyScene, overrides);
  return loadScenario(scene.file, overrides);
}

// The test of one scene on one backend: its hash against the recorded one in `goldenFile`
// (relative to the source tree). GEM_GOLDEN_RECORD=FILE appends "scene hash" lines to FILE
// instead: how the golden files were made, on a commit whose behaviour is the reference. extra:
// overrides of every scene (the CUDA driver, say), which must step to the same hash.
inline void expectGoldenHash(const GoldenScene& scene, const std::string& backend, const std::string& goldenFile,
                             const std::vector<std::string>& extra = {}) {
  if (sizeof(Real) != sizeof(double)) GTEST_SKIP() << "the golden hashes are recorded for GEM_REAL=double";
  TempDir dir;
  const Scenario s = loadGoldenScene(scene, dir, backend, extra);
  auto stepper = makeStepper(s);
  RunActivity activity;
  const std::string hash = hex(fingerprintRun(*stepper, std::min(s.steps, kGoldenSteps), &activity));
  if (const char* record = std::getenv("GEM_GOLDEN_RECORD")) {
    std::ofstream(record, std::ios::app) << scene.name << " " << hash << "  # contacts " << activity.contacts << ", impacts "
                                         << activity.impacts << ", floes broken " << activity.floesBroken << "\n";
    return;
  }
  EXPECT_GT(activity.contacts, 0) << "scene " << scene.name << " never touches: it guards nothing";
  const auto golden = readGoldenFile(sourceDir() / goldenFile);
  const auto it = golden.find(scene.name);
  ASSERT_NE(it, golden.end()) << "no golden hash for scene " << scene.name << " in " << goldenFile;
  EXPECT_EQ(hash, it->second) << "scene " << scene.name << " on " << backend << (extra.empty() ? "" : " with " + extra.front())
                              << " no longer steps as it did when its hash was recorded";
}

}  // namespace gem::test
