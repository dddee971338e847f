// Fuzz targets for GEM's readers of untrusted files (docs/reliability.md "Fuzzing"): the scenario
// loader, the .ice reader, the sweep file, a case's summary.json and impacts.csv (gem analyze).
// One source, the target chosen at build time by GEM_FUZZ_TARGET. Each input is written to a file
// of this process (the readers take paths, as users give them) and read: bad input must end in an
// InputError (exit 2 for a user); a crash, a sanitizer report, a hang or any other exception is a
// finding. Built two ways (tests/CMakeLists.txt): with libFuzzer by scripts/fuzz.sh (clang), and
// as gem_fuzz_replay_TARGET, which runs every file of the seed corpus in the test suite.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "framework/analysis/analyze.hpp"
#include "framework/analysis/sweep_summary.hpp"
#include "framework/api/errors.hpp"
#include "framework/field/ice_file.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/scenario/sweep_file.hpp"

namespace fs = std::filesystem;

namespace {

const std::string kTarget = GEM_FUZZ_TARGET;

// This process's scratch folder: /dev/shm when it exists (no disk writes per input).
const fs::path& scratch() {
  static const fs::path dir = [] {
    const fs::path base = fs::exists("/dev/shm") ? fs::path("/dev/shm") : fs::temp_directory_path();
    const fs::path d = base / ("gem-fuzz-" + kTarget + "-" + std::to_string(getpid()));
    fs::create_directories(d);
    return d;
  }();
  return dir;
}

fs::path writeInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const fs::path file = scratch() / name;
  std::ofstream(file, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return file;
}

void readOne(const std::uint8_t* data, std::size_t size) {
  if (kTarget == "scenario") {
    (void)gem::loadScenario(writeInput("case.toml", data, size));
  } else if (kTarget == "ice") {
    (void)gem::readIceFile(writeInput("field.ice", data, size));
  } else if (kTarget == "sweep") {
    (void)gem::readSweepFile(writeInput("sweep.toml", data, size));
  } else if (kTarget == "summary_json") {
    (void)gem::readSummaryJson(writeInput("summary.json", data, size));
  } else if (kTarget == "impacts_csv") {
    const fs::path run = scratch() / "run";
    fs::remove_all(run);
    fs::create_directories(run);
    std::ofstream(run / "impacts.csv", std::ios::binary).write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
    gem::AnalyzeOptions options;
    options.dir = run.string();
    options.quiet = true;
    (void)gem::runAnalyze(options);
  } else {
    std::fprintf(stderr, "unknown fuzz target %s\n", kTarget.c_str());
    std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    readOne(data, size);
  } catch (const gem::InputError&) {
    // Refused with a message: what bad input must do.
  }
  return 0;
}
