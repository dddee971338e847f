// Helpers shared by the tests: scenarios from TOML text, temporary folders, running the gem binary.
#pragma once
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <initializer_list>
#include <string>

#include "events/ship_impact.hpp"
#include "framework/output/csv.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/step/stepper.hpp"

namespace gem::test {

// A fresh folder under the system's temporary directory, removed when the object goes.
class TempDir {
 public:
  TempDir() {
    static int counter = 0;
    m_path = std::filesystem::temp_directory_path() /
             ("gem-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + "-" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(m_path);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(m_path, ec);
  }
  const std::filesystem::path& path() const { return m_path; }
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    std::ofstream(m_path / name) << text;
    return m_path / name;
  }

 private:
  std::filesystem::path m_path;
};

// A busy little channel: 40 % ice in 120 m x 80 m between walls, the vessel entering it at 740 kN,
// floes breaking. The CPU and the CUDA tests share it.
inline constexpr const char* kBusyScene = R"(
[simulation]
dt = 0.1
steps = 300
seed = 3
[domain]
x = [0.0, 120.0]
y = [-40.0, 40.0]
walls = true
[field]
kind = "random_convex"
concentration = 0.45
size_mean = 5.0
size_sd = 2.0
size_min = 2.0
size_max = 12.0
thickness = 0.4
[vessel]
position = [-56.0, 0.0]
bollard_thrust = 740e3
open_water_speed = 6.5
[events.flexural_breaking]
min_area = 2.0
)";

inline Scenario scenarioFromToml(const TempDir& dir, const std::string& text, const std::vector<std::string>& overrides = {}) {
  return loadScenario(dir.write("scenario.toml", text), overrides);
}

// Runs the gem binary ($GEM_BINARY_DIR when set: a staged copy on the GPU machine; else the
// build's); returns its exit status. Output goes to `log`.
inline int runGem(const std::string& arguments, const std::filesystem::path& log) {
  const char* staged = std::getenv("GEM_BINARY_DIR");
  const std::string command = std::string(staged ? staged : GEM_BINARY_DIR) + "/gem " + arguments + " > " + log.string() + " 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// The impacts the last step logged (ship_impact's record stream).
inline std::vector<ImpactRecord> impactsOf(const Stepper& stepper) { return stepper.records().rows<ImpactRecord>(kImpactStream); }

// One CSV line's cells, through GEM's CSV module (quoted fields hold commas and doubled quotes).
inline std::vector<std::string> csvCells(const std::string& line) {
  CsvRecords records = parseCsvRecords(line);
  return records.cells.empty() ? std::vector<std::string>(1) : std::move(records.cells.front());
}

// A tiny channel for sweep tests: 20 floes, a small vessel entering them; milliseconds per run.
inline const char* const kTinyChannel = R"(
[simulation]
dt = 0.1
steps = 40
seed = 2
[domain]
x = [0.0, 60.0]
y = [-20.0, 20.0]
walls = true
[field]
kind = "random_convex"
count = 20
concentration = 0.3
size_mean = 4.0
size_sd = 1.0
size_min = 2.0
size_max = 7.0
thickness = 0.5
[vessel]
length = 30.0
beam = 8.0
mass = 5e5
position = [-16.0, 0.0]
bollard_thrust = 92e3
[output]
frame_every = 0
)";

inline std::string readFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// A square floe of the given side, centred at centre, at thickness m, moving at velocity, turning
// at omega.
inline BodySpec squareFloe(Vec2 centre, Real side, Real thickness, Vec2 velocity = {0, 0}, Real omega = 0) {
  BodySpec s;
  s.kind = BodyKind::Floe;
  const Real h = side / 2;
  s.vertices = {{centre.x - h, centre.y - h}, {centre.x + h, centre.y - h}, {centre.x + h, centre.y + h}, {centre.x - h, centre.y + h}};
  s.thickness = thickness;
  s.velocity = velocity;
  s.angularVelocity = omega;
  return s;
}

// Event tables that switch on only the built-in events named: every other one is off.
inline std::string eventsOnly(std::initializer_list<const char*> on) {
  std::string text;
  for (const char* name : {"drag", "impact", "elastic_contact", "ship_impact", "flexural_breaking", "propulsion", "autopilot"}) {
    bool enabled = false;
    for (const char* o : on) enabled |= std::string(o) == name;
    text += std::string("[events.") + name + "]\nenabled = " + (enabled ? "true" : "false") + "\n";
  }
  return text;
}

// A sweep over kTinyChannel (written as base.toml beside it): two thrusts by two concentrations.
inline constexpr const char* kProductSweep = R"([sweep]
base = "base.toml"
set = { "simulation.steps" = 30 }
[parameters]
"vessel.bollard_thrust" = [46e3, 92e3]
field.concentration = [0.25, 0.3]
)";

}  // namespace gem::test
