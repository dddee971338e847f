// A run's scenario.toml (recordScenario) is the scenario as it took effect: loading it gives the
// same scenario and the same bodies bit for bit, and recording that again gives the same text.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <set>
#include <sstream>
#include <string>

#include "framework/output/run_folder.hpp"
#include "framework/scenario/sweep_file.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "test_support.hpp"

using namespace gem;
namespace fs = std::filesystem;

namespace {

struct ScenarioSource {
  std::string label;
  fs::path file;
  std::vector<std::string> overrides;
};

// Every scenario under scenarios/: each plain file, and each sweep's cases as the sweep loads
// them (base + overrides). Cases of one base that set the same keys differ only in values: one of
// each base and set of keys is enough to meet every combination of choices, and keeps the test fast.
std::vector<ScenarioSource> everyScenario() {
  std::vector<ScenarioSource> out;
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(GEM_SOURCE_DIR) / "scenarios"))
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    if (!toml::parse_file(file.string()).contains("sweep")) {
      out.push_back({file.string(), file, {}});
      continue;
    }
    std::set<std::set<std::string>> keySetsSeen;
    for (const SweepCase& c : readSweepFile(file).cases) {
      std::set<std::string> keys{"base " + c.base.string()};
      std::vector<std::string> overrides;
      for (const SweepOverride& o : c.overrides) keys.insert(o.key), overrides.push_back(o.key + "=" + o.toml);
      if (keySetsSeen.insert(keys).second) out.push_back({file.string() + " case " + c.name, c.base, overrides});
    }
  }
  return out;
}

// The scenario's text below its opening comments (which name the file it was read from).
std::string recordedBody(const fs::path& dir) {
  std::istringstream in(test::readFile(dir / "scenario.toml"));
  std::string line, body;
  bool opening = true;
  while (std::getline(in, line)) {
    if (opening && (line.empty() || line[0] == '#')) continue;
    opening = false;
    body += line + "\n";
  }
  return body;
}

void expectSameBodies(const World& a, const World& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.id, b.id);
  EXPECT_EQ(a.kind, b.kind);
  EXPECT_EQ(a.vertexCount, b.vertexCount);
  auto same = [](const auto& u, const auto& v, const char* what) {
    ASSERT_EQ(u.size(), v.size()) << what;
    EXPECT_EQ(0, std::memcmp(u.data(), v.data(), u.size() * sizeof(u[0]))) << what;
  };
  same(a.localVertices, b.localVertices, "localVertices");
  same(a.x, b.x, "x"), same(a.y, b.y, "y"), same(a.angle, b.angle, "angle");
  same(a.vx, b.vx, "vx"), same(a.vy, b.vy, "vy"), same(a.omega, b.omega, "omega");
  same(a.area, b.area, "area"), same(a.thickness, b.thickness, "thickness"), same(a.mass, b.mass, "mass");
  same(a.invMass, b.invMass, "invMass"), same(a.invInertia, b.invInertia, "invInertia");
}

bool samePoint(Vec2 a, Vec2 b) { return a.x == b.x && a.y == b.y; }
bool samePoints(const std::vector<Vec2>& a, const std::vector<Vec2>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), samePoint);
}

void expectSameDomain(const Domain& a, const Domain& b) {
  EXPECT_EQ(a.x0, b.x0);
  EXPECT_EQ(a.x1, b.x1);
  EXPECT_EQ(a.y0, b.y0);
  EXPECT_EQ(a.y1, b.y1);
}

// Every value of a Scenario that a run uses (duration aside: the record gives steps).
void expectSameScenario(const Scenario& a, const Scenario& b) {
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_EQ(a.steps, b.steps);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.backend, b.backend);
  EXPECT_EQ(a.broadphase, b.broadphase);
  EXPECT_EQ(a.broadphaseSettings.skin, b.broadphaseSettings.skin);
  EXPECT_EQ(a.broadphaseSettings.fixedRadius, b.broadphaseSettings.fixedRadius);
  EXPECT_EQ(a.broadphaseSettings.cellSize, b.broadphaseSettings.cellSize);
  EXPECT_EQ(a.broadphaseSettings.given, b.broadphaseSettings.given);
  EXPECT_EQ(a.mortonSort, b.mortonSort);
  EXPECT_EQ(a.copyBackEvery, b.copyBackEvery);
  EXPECT_EQ(a.cudaBlockSize, b.cudaBlockSize);
  EXPECT_EQ(a.cudaDriver, b.cudaDriver);
  EXPECT_EQ(a.threads, b.threads);
  EXPECT_EQ(a.stopWhen, b.stopWhen);
  EXPECT_EQ(a.stopDistance, b.stopDistance);
  EXPECT_EQ(a.hasDomain, b.hasDomain);
  expectSameDomain(a.domain, b.domain);
  EXPECT_EQ(a.walls, b.walls);
  EXPECT_EQ(a.wallThickness, b.wallThickness);
  EXPECT_EQ(a.fieldKind, b.fieldKind);
  const RandomFieldSpec &r = a.randomField, &q = b.randomField;
  expectSameDomain(r.domain, q.domain);
  EXPECT_EQ(r.concentration, q.concentration);
  EXPECT_EQ(r.count, q.count);
  EXPECT_EQ(r.sizeMean, q.sizeMean);
  EXPECT_EQ(r.sizeSd, q.sizeSd);
  EXPECT_EQ(r.sizeMin, q.sizeMin);
  EXPECT_EQ(r.sizeMax, q.sizeMax);
  EXPECT_EQ(r.minSides, q.minSides);
  EXPECT_EQ(r.maxSides, q.maxSides);
  EXPECT_EQ(r.maxAspect, q.maxAspect);
  EXPECT_EQ(r.thickness, q.thickness);
  EXPECT_EQ(r.minGap, q.minGap);
  EXPECT_EQ(r.seed, q.seed);
  ASSERT_EQ(r.groups.size(), q.groups.size());
  for (size_t g = 0; g < r.groups.size(); ++g) {
    EXPECT_EQ(r.groups[g].coverage, q.groups[g].coverage);
    EXPECT_EQ(r.groups[g].thickness, q.groups[g].thickness);
  }
  const HexagonFieldSpec &h = a.hexagonField, &k = b.hexagonField;
  expectSameDomain(h.domain, k.domain);
  EXPECT_EQ(h.concentration, k.concentration);
  EXPECT_EQ(h.size, k.size);
  EXPECT_EQ(h.rotationJitterDeg, k.rotationJitterDeg);
  EXPECT_EQ(h.thickness, k.thickness);
  EXPECT_EQ(h.minGap, k.minGap);
  EXPECT_EQ(h.count, k.count);
  EXPECT_EQ(h.seed, k.seed);
  EXPECT_EQ(a.fieldFile.lexically_normal(), b.fieldFile.lexically_normal());
  ASSERT_EQ(a.floes.size(), b.floes.size());
  for (size_t f = 0; f < a.floes.size(); ++f) {
    EXPECT_TRUE(samePoints(a.floes[f].vertices, b.floes[f].vertices));
    EXPECT_EQ(a.floes[f].thickness, b.floes[f].thickness);
    EXPECT_TRUE(samePoint(a.floes[f].velocity, b.floes[f].velocity));
    EXPECT_EQ(a.floes[f].angularVelocity, b.floes[f].angularVelocity);
  }
  const VesselSpec &v = a.vessel, &w = b.vessel;
  EXPECT_EQ(v.present, w.present);
  EXPECT_EQ(v.length, w.length);
  EXPECT_EQ(v.beam, w.beam);
  EXPECT_EQ(v.mass, w.mass);
  EXPECT_EQ(v.draft, w.draft);
  EXPECT_TRUE(samePoint(v.position, w.position));
  EXPECT_EQ(v.headingDeg, w.headingDeg);
  EXPECT_EQ(v.dof, w.dof);
  EXPECT_EQ(v.bollardThrust, w.bollardThrust);
  EXPECT_EQ(v.openWaterSpeed, w.openWaterSpeed);
  EXPECT_EQ(v.speed, w.speed);
  EXPECT_TRUE(samePoints(v.hull, w.hull));
  EXPECT_EQ(v.frameAnglesDeg, w.frameAnglesDeg);
  ASSERT_EQ(a.plugins.size(), b.plugins.size());
  for (size_t p = 0; p < a.plugins.size(); ++p) {
    EXPECT_EQ(a.plugins[p].path, b.plugins[p].path);
    EXPECT_EQ(a.plugins[p].override, b.plugins[p].override);
  }
  EXPECT_EQ(a.output.dir, b.output.dir);
  EXPECT_EQ(a.output.frameEvery, b.output.frameEvery);
  EXPECT_EQ(a.output.timeseriesEvery, b.output.timeseriesEvery);
  EXPECT_EQ(a.output.formats, b.output.formats);
  EXPECT_EQ(a.output.vtkBinary, b.output.vtkBinary);
}

// Loads the scenario and its record, and checks that they are the same scenario with the same
// bodies, that two steps take both to the same state (the events' parameters agree), and that the
// record of the record is the record.
void expectRecordLoadsBackTheSame(const ScenarioSource& source) {
  SCOPED_TRACE(source.label);
  test::TempDir first, second;
  const Scenario original = loadScenario(source.file, source.overrides);
  CpuStepper originalRun(original);  // parses the events: their defaults join the record
  recordScenario(first.path(), original);
  const Scenario recorded = loadScenario(first.path() / "scenario.toml");
  CpuStepper recordedRun(recorded);
  recordScenario(second.path(), recorded);

  expectSameScenario(original, recorded);
  std::vector<std::string> originalEvents, recordedEvents;
  for (const EnabledEvent& e : originalRun.events()) originalEvents.push_back(e.name);
  for (const EnabledEvent& e : recordedRun.events()) recordedEvents.push_back(e.name);
  EXPECT_EQ(originalEvents, recordedEvents);
  expectSameBodies(originalRun.world(), recordedRun.world());
  for (int k = 0; k < 2; ++k) originalRun.step(), recordedRun.step();
  expectSameBodies(originalRun.world(), recordedRun.world());
  EXPECT_EQ(recordedBody(first.path()), recordedBody(second.path())) << test::readFile(first.path() / "scenario.toml");
}

}  // namespace

TEST(ScenarioRecord, EveryScenarioLoadsBackTheSameAndRecordsTheSame) {
  const std::vector<ScenarioSource> sources = everyScenario();
  ASSERT_GE(sources.size(), 13u);  // the thesis's scenarios and the sweeps' cases
  for (const ScenarioSource& source : sources) expectRecordLoadsBackTheSame(source);
}

// The choices scenarios/ does not make, each with the keys that exclude each other: a stop by
// distance, a .ice field beside walls, hexagons by concentration, explicit floes with their
// defaults, the broadphase's settings in [simulation] and in its own table, a hull of its own.
TEST(ScenarioRecord, EveryChoiceOfKeysLoadsBackTheSame) {
  test::TempDir dir;
  dir.write("two.ice",
            "<iceFloeSim numFrames=\"1\"><frame index=\"0\"><object index=\"4\"><coordinates>0 0 4 0 4 4 0 4</coordinates>"
            "<velocity x=\"1\" y=\"0\" a=\"0\"/><thickness>0.5</thickness></object></frame></iceFloeSim>");
  const std::vector<std::pair<std::string, std::string>> scenarios{
      {"distance",
       "[simulation]\nduration = 30.0\nstop_when = \"distance\"\nstop_distance = 40.0\nskin = 1.5\n"
       "[vessel]\nbollard_thrust = 92e3\n[[floes]]\nvertices = [[20.0, -3.0], [26.0, -3.0], [26.0, 3.0], [20.0, 3.0]]\n"
       "[[floes]]\nvertices = [[40.0, -3.0], [46.0, -3.0], [46.0, 3.0]]\nthickness = 1.1\nangular_velocity = 0.1\n"},
      {"ice_file",
       "[simulation]\nsteps = 5\nbroadphase = \"uniform_grid\"\n[broadphase.uniform_grid]\ncell_size = 30.0\n"
       "[domain]\nx = [-10.0, 60.0]\ny = [-20.0, 20.0]\nwalls = true\n[field]\nkind = \"file\"\nfile = \"two.ice\"\n"},
      {"hexagons",
       "[simulation]\nsteps = 5\nseed = 7\n[domain]\nx = [0.0, 120.0]\n[field]\nkind = \"hexagons\"\n"
       "[vessel]\ndof = 3\nvertices = [[-20.0, -4.0], [20.0, -4.0], [25.0, 0.0], [20.0, 4.0], [-20.0, 4.0]]\n"
       "frame_angle_deg = [0.0, 40.0, 40.0, 0.0, 0.0]\n[output]\nformats = [\"ice\"]\n"},
  };
  for (const auto& [label, text] : scenarios) expectRecordLoadsBackTheSame({label, dir.write(label + ".toml", text), {}});
}
