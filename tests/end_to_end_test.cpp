// End to end: whole scenarios through the scheduler and the gem binary.
#include <gtest/gtest.h>
#include <toml++/toml.h>
#include <pugixml.hpp>
#include <fmt/format.h>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <set>
#include <sstream>
#include <string>

#include "framework/analysis/sweep_summary.hpp"
#include "framework/app/runner.hpp"
#include "framework/field/ice_file.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "run_compare.hpp"
#include "test_support.hpp"

using namespace gem;
using gem::test::kBusyScene;
using gem::test::TempDir;

namespace {

// A run with no progress line and no closing summary (the other options as a run has them).
RunOptions quietRun() {
  RunOptions options;
  options.quiet = true;
  return options;
}

struct Trajectory {
  std::vector<std::int64_t> ids;
  std::vector<Real> state;
  std::vector<Real> impacts;
  long broken = 0;
};

Trajectory runWith(const std::string& broadphase, const TempDir& dir) {
  Scenario s = test::scenarioFromToml(dir, kBusyScene, {"simulation.broadphase=\"" + broadphase + "\""});
  CpuStepper sim(s);
  Trajectory t;
  for (long k = 0; k < s.steps; ++k) {
    sim.step();
    for (const ImpactRecord& r : ::gem::test::impactsOf(sim)) t.impacts.insert(t.impacts.end(), {r.time, r.force, r.point.x, r.point.y});
  }
  const World& w = sim.world();
  t.ids = w.id;
  for (int i = 0; i < w.size(); ++i) t.state.insert(t.state.end(), {w.x[i], w.y[i], w.angle[i], w.vx[i], w.vy[i], w.omega[i]});
  t.broken = sim.floesBroken();
  return t;
}

}  // namespace

TEST(Broadphase, EveryStrategyGivesBitIdenticalTrajectories) {
  TempDir dir;
  const Trajectory reference = runWith("all_pairs", dir);
  ASSERT_GT(reference.impacts.size(), 10u);  // the scene really has ship impacts
  ASSERT_GT(reference.broken, 0);            // and breaks: topology changes are covered too
  for (const std::string& name : Registry::global().broadphaseNames()) {
    SCOPED_TRACE(name);
    const Trajectory t = runWith(name, dir);
    ASSERT_EQ(t.ids, reference.ids);
    ASSERT_EQ(t.state.size(), reference.state.size());
    EXPECT_EQ(0, std::memcmp(t.state.data(), reference.state.data(), t.state.size() * sizeof(Real)));
    ASSERT_EQ(t.impacts.size(), reference.impacts.size());
    EXPECT_EQ(0, std::memcmp(t.impacts.data(), reference.impacts.data(), t.impacts.size() * sizeof(Real)));
  }
}

TEST(Scenario, EveryEventCanBeTurnedOff) {
  TempDir dir;
  for (const EventEntry* e : Registry::global().events()) {
    SCOPED_TRACE(e->name);
    Scenario on = test::scenarioFromToml(dir, kBusyScene, {"events." + e->name + ".enabled=true"});
    Scenario off = test::scenarioFromToml(dir, kBusyScene, {"events." + e->name + ".enabled=false"});
    auto has = [&](const CpuStepper& sim) {
      for (const auto& x : sim.events())
        if (x.name == e->name) return true;
      return false;
    };
    EXPECT_TRUE(has(CpuStepper(on)));
    EXPECT_FALSE(has(CpuStepper(off)));
  }
}

TEST(Scenario, RelativeFieldFileResolvesAgainstTheScenarioFolder) {
  TempDir dir;
  std::filesystem::create_directories(dir.path() / "sub" / "fields");
  std::ofstream(dir.path() / "sub" / "fields" / "two.ice") << "<iceFloeSim numFrames=\"1\"><frame index=\"0\">"
                                                              "<object index=\"4\"><coordinates>0 0 4 0 4 4 0 4</coordinates><velocity "
                                                              "x=\"1\" y=\"0\" a=\"0\"/><thickness>0.5</thickness></object>"
                                                              "<object index=\"9\"><coordinates>10 0 14 0 12 3</coordinates><velocity "
                                                              "x=\"0\" y=\"0\" a=\"0.1\"/><thickness>1.5</thickness></object>"
                                                              "</frame></iceFloeSim>";
  const auto file = dir.write("sub/s.toml", "[simulation]\nsteps = 3\n[field]\nkind = \"file\"\nfile = \"fields/two.ice\"\n");
  CpuStepper sim(loadScenario(file));
  ASSERT_EQ(sim.world().size(), 2);
  EXPECT_EQ(sim.world().count(BodyKind::Floe), 2);
  EXPECT_NEAR(sim.world().floeMass(), 900 * (16 * 0.5 + 6 * 1.5), 1e-6);
}

TEST(GemRun, WritesEveryOutputOfTheContract) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto out = dir.path() / "run";
  const int status = test::runGem("run " + scenario.string() + " --steps 60 --backend cpu --out " + out.string() +
                                      " --set output.frame_every=20 --broadphase uniform_grid",
                                  dir.path() / "log.txt");
  const std::string log = test::readFile(dir.path() / "log.txt");
  ASSERT_EQ(status, 0) << log;
  EXPECT_NE(log.find("real time"), std::string::npos);
  EXPECT_NE(log.find(out.string()), std::string::npos);  // says where the outputs are

  const std::string summary = test::readFile(out / "summary.json");
  for (const char* key : {"\"steps\": 60", "\"sim_time_s\"", "\"wall_time_s\"", "\"backend\": \"cpu\"", "\"broadphase\": \"uniform_grid\"",
                          "\"device\"", "\"floes_initial\"", "\"floes_final\"", "\"ice_mass_initial_kg\"", "\"ice_mass_final_kg\"",
                          "\"rubble_mass_kg\"", "\"impacts\"", "\"ship_speed\": {\"min\"", "\"impact_force_n\"", "\"gem_version\""})
    EXPECT_NE(summary.find(key), std::string::npos) << key;
  auto header = [&](const char* file) {
    std::ifstream in(out / file);
    std::string line;
    std::getline(in, line);
    return line;
  };
  EXPECT_EQ(header("state.csv"), "id,kind,x,y,angle,vx,vy,omega,area,thickness,mass,vertices");
  EXPECT_EQ(header("timeseries.csv"), "t,ship_x,ship_y,ship_heading,ship_speed,net_thrust,ice_force_x,contacts");
  EXPECT_EQ(header("impacts.csv"),
            "t,floe_id,floe_mass,thickness,apex_deg,frame_angle_deg,x,y,nx,ny,x_from_stem,y_from_centerline,vn,fn,flim,broke");
  const std::string series = test::readFile(out / "timeseries.csv");
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), 61);  // header + one row per step
  const std::string pvd = test::readFile(out / "frames.pvd");
  EXPECT_NE(pvd.find("frames/frame_000003.vtp"), std::string::npos);  // frames at steps 0, 20, 40, 60
  EXPECT_TRUE(std::filesystem::exists(out / "frames" / "frame_000003.vtp"));
  const auto frames = readIceFile(out / "frames.ice");
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_GT(frames[0].objects.size(), frames[1].objects.size() / 2);
  // No temporary file is left behind.
  for (const auto& entry : std::filesystem::recursive_directory_iterator(out))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
}

// The terminal shows the in-ice figures the studies use (the steps with the whole hull inside the
// domain's x range) before the whole run's, and they are summary.json's.
TEST(GemRun, TheTerminalShowsTheInIceSpeedAndResistance) {
  TempDir dir;
  const auto scenario = dir.write("busy.toml", kBusyScene);
  const auto out = dir.path() / "run";
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --steps 300 --out " + out.string() + " --set output.frame_every=0",
                         dir.path() / "log.txt"),
            0)
      << test::readFile(dir.path() / "log.txt");
  const std::string log = test::readFile(dir.path() / "log.txt");
  const size_t inIce = log.find("  in ice         speed mean "), whole = log.find("  whole run      speed mean ");
  ASSERT_NE(inIce, std::string::npos) << log;
  ASSERT_NE(whole, std::string::npos) << log;
  EXPECT_LT(inIce, whole) << log;
  const std::string summary = test::readFile(out / "summary.json");
  const size_t key = summary.find("\"ship_speed_in_ice\": {\"min\": ");
  ASSERT_NE(key, std::string::npos) << summary;
  const size_t mean = summary.find("\"mean\": ", key);
  const double fromSummary = std::stod(summary.substr(mean + 8));
  const double fromTerminal = std::stod(log.substr(inIce + 27));
  EXPECT_NEAR(fromTerminal, fromSummary, 0.0005) << log << summary;
}

TEST(GemInfo, ListsEveryBuiltInEventAndBroadphase) {
  TempDir dir;
  ASSERT_EQ(test::runGem("info", dir.path() / "log.txt"), 0);
  const std::string log = test::readFile(dir.path() / "log.txt");
  for (const char* name : {"motion", "drag", "wind", "current", "propulsion", "autopilot", "impact", "elastic_contact", "ship_impact",
                           "flexural_breaking", "all_pairs", "fixed_radius", "variable_radius", "uniform_grid", "triangulation_mesh"})
    EXPECT_NE(log.find(std::string("  ") + name + " "), std::string::npos) << name;
  EXPECT_NE(log.find("built-in"), std::string::npos);
}

TEST(GemCheck, ValidatesEveryThesisScenario) {
  TempDir dir;
  for (const char* name : {"random_35", "random_39", "random_41", "random_42", "hexagons_46", "random_50", "hexagons_60", "random_69"}) {
    const std::string file = std::string(GEM_SOURCE_DIR) + "/scenarios/thesis/" + name + ".toml";
    EXPECT_EQ(test::runGem("check " + file, dir.path() / "log.txt"), 0) << test::readFile(dir.path() / "log.txt");
  }
}

// A .ice field's floe thinner than any ice (a 1e-200 m object once passed and blew up at its first
// impulse) is refused at load, naming the file and the object.
TEST(GemCheck, AnIceFieldsFloeThinnerThanAnyIceIsRefusedNamingTheObject) {
  test::TempDir dir;
  dir.write("thin.ice",
            "<iceFloeSim numFrames=\"1\">\n<frame index=\"0\" time=\"0\">\n"
            "<object index=\"7\"><coordinates>10 0 20 0 20 10 10 10</coordinates><thickness>1e-200</thickness></object>\n"
            "</frame>\n</iceFloeSim>\n");
  const auto scenario = dir.write("thin.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 5\n[domain]\nx = [0.0, 100.0]\ny = [-20.0, 30.0]\n"
                                  "[field]\nkind = \"file\"\nfile = \"thin.ice\"\n");
  for (const std::string& command :
       {"check " + scenario.string(), "run " + scenario.string() + " --quiet --out " + (dir.path() / "out").string()}) {
    EXPECT_EQ(test::runGem(command, dir.path() / "log"), 2) << command;
    const std::string log = test::readFile(dir.path() / "log");
    EXPECT_NE(log.find("thin.ice:3:1: object 7: a floe's thickness must be from 0.01 to 1000 m, got 1e-200"), std::string::npos) << log;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "summary.json"));
}

// A .ice field (object indices 0, 1) with the domain's walls: the floes keep their ids, the walls
// get ids after them, and gem check and gem run agree (run used to fail on duplicate ids).
TEST(GemRun, AnIceFieldWithWallsHasUniqueIds) {
  test::TempDir dir;
  dir.write("pack.ice",
            "<iceFloeSim numFrames=\"1\">\n<frame index=\"0\" time=\"0\">\n"
            "<object index=\"0\"><coordinates>10 0 20 0 20 10 10 10</coordinates><thickness>1</thickness></object>\n"
            "<object index=\"1\"><coordinates>30 0 40 0 40 10 30 10</coordinates><thickness>1</thickness></object>\n"
            "</frame>\n</iceFloeSim>\n");
  const auto scenario = dir.write("walls.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 5\n[domain]\nx = [0.0, 100.0]\ny = [-20.0, 30.0]\nwalls = true\n"
                                  "[field]\nkind = \"file\"\nfile = \"pack.ice\"\n");
  EXPECT_EQ(test::runGem("check " + scenario.string() + " --quiet", dir.path() / "log"), 0) << test::readFile(dir.path() / "log");
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --quiet --out " + (dir.path() / "out").string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  const std::vector<double> idColumn = readCsvTable(dir.path() / "out" / "state.csv").numbers("id");
  std::set<long> ids;
  int count = 0;
  for (double id : idColumn) ++count, ids.insert(std::lround(id));
  EXPECT_EQ(count, 4);
  EXPECT_EQ(ids, (std::set<long>{0, 1, 2, 3}));  // the floes 0 and 1 as in the file, then the walls
}

// A state that is no longer finite stops the run: exit 1, the body and the step named with its
// whole state (an infinite angular velocity once showed only the finite x, y, vx, vy), what was
// written kept whole (no NaN in any file), and no summary.json. The test plugin spins every floe
// infinitely from step 4 on (tests/plugins/spin_up.cpp): no scenario value within its range does.
// gem check takes only the first step, which is finite, and passes it.
TEST(GemRun, ANonFiniteStateStopsTheRunNamingTheBodyAndStep) {
  test::TempDir dir;
  const auto scenario = dir.write("spin.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 50\n[[floes]]\n"
                                  "vertices = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\nvelocity = [1.0, 0.0]\n"
                                  "[[plugins]]\npath = \"" GEM_TEST_PLUGIN_DIR
                                  "/libspin_up.so\"\n"
                                  "[events.spin_past_any_finite_rate]\nat_step = 3\n");
  const auto out = dir.path() / "out";
  EXPECT_EQ(test::runGem("check " + scenario.string() + " --quiet", dir.path() / "check.log"), 0)
      << test::readFile(dir.path() / "check.log");
  EXPECT_EQ(test::runGem("run " + scenario.string() + " --quiet --out " + out.string(), dir.path() / "log"), 1);
  const std::string log = test::readFile(dir.path() / "log");
  EXPECT_NE(log.find("step 4 (t = 0.4 s): body 0 (floe) has a state that is no longer finite (x "), std::string::npos) << log;
  EXPECT_NE(log.find(", omega inf); the run stops here"), std::string::npos) << log;
  EXPECT_NE(log.find("angle inf"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  const std::string series = test::readFile(out / "timeseries.csv");
  EXPECT_EQ(series.rfind("t,", 0), 0u) << series;
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), 1 + 3) << series;  // header + steps 1..3
  EXPECT_EQ(series.find("nan"), std::string::npos) << series;
  EXPECT_EQ(series.find("inf"), std::string::npos) << series;
}

// A finite state can still make a timeseries.csv column infinite: a 1 kg vessel under 1e8 N of
// thrust struck by a 1000 m thick floe at 100 m/s (every value within its range) reaches ship
// speeds whose quadratic net thrust overflows. The
// run stops at that step, naming the column, before the row is written: no inf in the file.
TEST(GemRun, AnInfiniteTimeseriesColumnStopsTheRunBeforeItsRow) {
  test::TempDir dir;
  const auto scenario = dir.write("light.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 50\n[[floes]]\n"
                                  "vertices = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\nthickness = 1000.0\n"
                                  "velocity = [-100.0, 0.0]\nangular_velocity = 100.0\n[vessel]\nposition = [-60.0, 0.0]\n"
                                  "speed = 100.0\nopen_water_speed = 100.0\nbollard_thrust = 1e8\nmass = 1.0\n");
  const auto out = dir.path() / "out";
  EXPECT_EQ(test::runGem("run " + scenario.string() + " --quiet --out " + out.string(), dir.path() / "log"), 1);
  const std::string log = test::readFile(dir.path() / "log");
  EXPECT_NE(log.find("the vessel's net_thrust is no longer finite"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  const std::string series = test::readFile(out / "timeseries.csv");
  EXPECT_EQ(series.rfind("t,", 0), 0u) << series;
  EXPECT_EQ(series.find("inf"), std::string::npos) << series;
  EXPECT_EQ(series.find("nan"), std::string::npos) << series;
}

// gem check takes one CPU step of the world it built: a scenario whose first step is not finite
// (here a plugin's event, which no range of GEM's can bound) is refused with exit 2 and the words
// gem run stops with, where it once said "ok" and gem run failed at step 1. It writes nothing.
TEST(GemCheck, AFirstStepThatIsNotFiniteIsRefusedWithTheWordsOfGemRun) {
  test::TempDir dir;
  const auto scenario = dir.write("spin.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 50\n[[floes]]\n"
                                  "vertices = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\n"
                                  "[[plugins]]\npath = \"" GEM_TEST_PLUGIN_DIR
                                  "/libspin_up.so\"\n"
                                  "[events.spin_past_any_finite_rate]\n[output]\ndir = \"out\"\n");
  EXPECT_EQ(test::runGem("check " + scenario.string(), dir.path() / "check.log"), 2);
  const std::string check = test::readFile(dir.path() / "check.log");
  const std::string words =
      "step 1 (t = 0.1 s): body 0 (floe) has a state that is no longer finite (x 5, y 5, angle inf, vx 0, vy 0, omega inf)";
  EXPECT_EQ(check, "gem: error: " + scenario.string() + ": " + words + "; gem run stops there\n");
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out")) << "gem check wrote a run folder";
  EXPECT_EQ(test::runGem("run " + scenario.string() + " --quiet", dir.path() / "run.log"), 1);
  EXPECT_NE(test::readFile(dir.path() / "run.log").find(words + "; the run stops here"), std::string::npos)
      << test::readFile(dir.path() / "run.log");
}

// Every input error is found before gem run announces the run: a bad event parameter (read when
// the run builds its events) once came after the "gem run ...: N steps" line. The failed start
// prints the error alone; a good one prints the line first.
TEST(GemRun, AnInputErrorComesBeforeTheRunAnnouncesItself) {
  test::TempDir dir;
  const std::string base =
      "[simulation]\ndt = 0.1\nsteps = 3\n[[floes]]\nvertices = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\n";
  const auto bad = dir.write("bad.toml", base + "[events.drag]\ncd = -1.0\n");
  const auto stdoutFile = dir.path() / "stdout", stderrFile = dir.path() / "stderr";
  const std::string gem = std::string(std::getenv("GEM_BINARY_DIR") ? std::getenv("GEM_BINARY_DIR") : GEM_BINARY_DIR) + "/gem";
  auto run = [&](const std::filesystem::path& scenario, const std::string& out) {
    const int status = std::system((gem + " run " + scenario.string() + " --no-plots --out " + (dir.path() / out).string() + " > " +
                                    stdoutFile.string() + " 2> " + stderrFile.string())
                                       .c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  EXPECT_EQ(run(bad, "bad"), 2);
  EXPECT_EQ(test::readFile(stdoutFile), "") << "printed before the error";
  EXPECT_NE(test::readFile(stderrFile).find("events.drag.cd"), std::string::npos) << test::readFile(stderrFile);
  // A run folder that cannot be made is input too, checked before the line.
  const auto blocked = dir.write("a_file", "x");
  const auto good = dir.write("good.toml", base);
  EXPECT_EQ(run(good, "a_file/run"), 2);
  EXPECT_EQ(test::readFile(stdoutFile), "") << "printed before the error";
  EXPECT_EQ(run(good, "good"), 0) << test::readFile(stderrFile);
  EXPECT_EQ(
      test::readFile(stdoutFile).rfind("gem run " + good.string() + ": 3 steps of 0.1 s, backend cpu, broadphase variable_radius\n", 0), 0u)
      << test::readFile(stdoutFile);
}

// One run writes into a run folder at a time: while another process holds the folder's lock, gem
// run is refused (exit 2, naming the folder); once it is free the run goes ahead and leaves no lock.
TEST(GemRun, ARunFolderInUseIsRefused) {
  test::TempDir dir;
  const auto scenario = dir.write("busy.toml", test::kBusyScene);
  const auto out = dir.path() / "out";
  std::filesystem::create_directories(out);
  const int fd = ::open((out / ".gem-run.lock").c_str(), O_RDWR | O_CREAT, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  EXPECT_EQ(test::runGem("run " + scenario.string() + " --quiet --steps 5 --out " + out.string(), dir.path() / "log"), 2);
  const std::string log = test::readFile(dir.path() / "log");
  EXPECT_NE(log.find("another gem run is writing into this run folder"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(out / "timeseries.csv"));
  ::close(fd);
  EXPECT_EQ(test::runGem("run " + scenario.string() + " --quiet --steps 5 --out " + out.string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  EXPECT_FALSE(std::filesystem::exists(out / ".gem-run.lock"));
}

// A reader of gem run's report that goes away (`| true`) does not kill the run: it ends with the
// status its gem.log records (it exited 141, SIGPIPE, where gem.log said 0).
TEST(GemRun, AReaderThatGoesAwayDoesNotKillTheRun) {
  test::TempDir dir;
  const auto scenario = dir.write("busy.toml", test::kBusyScene);
  const auto out = dir.path() / "out";
  const std::string gem = std::string(std::getenv("GEM_BINARY_DIR") ? std::getenv("GEM_BINARY_DIR") : GEM_BINARY_DIR) + "/gem";
  const std::string command = "bash -c '" + gem + " run " + scenario.string() + " --no-plots --steps 200 --out " + out.string() +
                              " 2>/dev/null | true; exit ${PIPESTATUS[0]}'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_NE(test::readFile(out / "gem.log").find("exit status 0"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(out / "summary.json"));
}

// SIGTERM, Ctrl-C and SIGHUP stop a run between two steps: exit 128 + the signal, a message, the CSVs whole
// under their final names, no temporary left behind, and a summary.json of the steps run that says
// the run did not complete (and why); gem.log records the exit status.
class GemRunSignal : public ::testing::TestWithParam<const char*> {};

TEST_P(GemRunSignal, KeepsTheFilesWholeAndSaysSo) {
  const std::string signal = GetParam();
  const int number = signal == "INT" ? 2 : signal == "HUP" ? 1 : 15;
  test::TempDir dir;
  const auto scenario = dir.write("busy.toml", test::kBusyScene);
  const auto out = dir.path() / "out";
  const std::string gem = std::string(std::getenv("GEM_BINARY_DIR") ? std::getenv("GEM_BINARY_DIR") : GEM_BINARY_DIR) + "/gem";
  const std::string command = "bash -c '" + gem + " run " + scenario.string() +
                              " --quiet --steps 2000000 --set output.frame_every=0 --out " + out.string() + " > " +
                              (dir.path() / "log").string() + " 2>&1 & p=$!; sleep 1; kill -" + signal + " $p; wait $p; exit $?'";
  const int status = std::system(command.c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + number) << test::readFile(dir.path() / "log");
  const std::string log = test::readFile(dir.path() / "log");
  EXPECT_NE(log.find(signal == "INT" ? "interrupted (Ctrl-C)" : "interrupted (SIG" + signal + ")"), std::string::npos) << log;
  const std::string series = test::readFile(out / "timeseries.csv");
  EXPECT_EQ(series.rfind("t,", 0), 0u);
  EXPECT_EQ(series.back(), '\n');  // whole rows
  EXPECT_TRUE(std::filesystem::exists(out / "impacts.csv"));
  EXPECT_TRUE(std::filesystem::exists(out / "state.csv"));
  const auto summary = readSummaryJson(out / "summary.json");
  EXPECT_EQ(summary.at("completed"), "false");
  EXPECT_EQ(summary.at("stop_reason"), "SIG" + signal);
  const long steps = std::stol(summary.at("steps"));
  EXPECT_GT(steps, 0);
  EXPECT_LT(steps, 2000000);
  // The time series holds a row per step run (timeseries_every = 1): the summary counts them.
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), steps + 1);
  EXPECT_NE(test::readFile(out / "gem.log").find("exit status " + std::to_string(128 + number)), std::string::npos);
  for (const auto& entry : std::filesystem::directory_iterator(out))
    EXPECT_EQ(entry.path().filename().string().find(".tmp-"), std::string::npos) << entry.path();
}

// HUP: a closed terminal (it once killed the run outright, with no checkpoint and its rows left in
// temporaries).
INSTANTIATE_TEST_SUITE_P(Signals, GemRunSignal, ::testing::Values("TERM", "INT", "HUP"));

// A reused run folder describes only its last run: a re-run with frames off leaves none of the
// earlier run's frames; the folder records the scenario as read (scenario.toml, overrides applied,
// with its seed) and the run's report (gem.log), and running that record repeats the run.
TEST(GemRun, AReusedRunFolderHoldsOnlyItsLastRunAndRecordsItsScenario) {
  test::TempDir dir;
  const auto scenario = dir.write("busy.toml", test::kBusyScene);
  const auto out = dir.path() / "out";
  const std::string run = "run " + scenario.string() + " --quiet --steps 30 --out " + out.string();
  ASSERT_EQ(test::runGem(run + " --set output.frame_every=10", dir.path() / "log"), 0) << test::readFile(dir.path() / "log");
  ASSERT_TRUE(std::filesystem::exists(out / "frames.pvd"));
  ASSERT_TRUE(std::filesystem::exists(out / "frames.ice"));
  ASSERT_EQ(test::runGem(run + " --set output.frame_every=0", dir.path() / "log"), 0) << test::readFile(dir.path() / "log");
  EXPECT_FALSE(std::filesystem::exists(out / "frames.pvd"));
  EXPECT_FALSE(std::filesystem::exists(out / "frames.ice"));
  EXPECT_FALSE(std::filesystem::exists(out / "frames"));
  const std::string record = test::readFile(out / "scenario.toml");
  EXPECT_NE(record.find("# --set output.frame_every=0"), std::string::npos) << record;
  EXPECT_NE(record.find("seed = 3"), std::string::npos) << record;
  EXPECT_NE(record.find("broadphase = "), std::string::npos) << record;  // a default, resolved
  // Every event's table as it took effect: the scenario sets none of drag's parameters.
  const toml::table recorded = toml::parse(record);
  EXPECT_TRUE(recorded["events"]["drag"]["cd"].is_floating_point()) << record;
  EXPECT_EQ(recorded["events"]["drag"]["enabled"].value<bool>(), true) << record;
  EXPECT_EQ(recorded["events"]["wind"]["enabled"].value<bool>(), false) << record;                 // off unless given
  EXPECT_TRUE(recorded["events"]["flexural_breaking"]["min_area"].is_floating_point()) << record;  // the scene's own value kept
  const std::string gemLog = test::readFile(out / "gem.log");
  EXPECT_NE(gemLog.find("--set output.frame_every=0"), std::string::npos) << gemLog;  // the command line
  EXPECT_NE(gemLog.find("exit status 0"), std::string::npos) << gemLog;
  ASSERT_EQ(
      test::runGem("run " + (out / "scenario.toml").string() + " --quiet --out " + (dir.path() / "again").string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  EXPECT_EQ(test::readFile(dir.path() / "again" / "state.csv"), test::readFile(out / "state.csv"));
}

// A reused run folder loses GEM's own files and their temporaries (NAME.tmp-PID of a killed run),
// never a user's file, whatever its name: every name with ".tmp-" in it once went.
TEST(GemRun, AReusedRunFolderKeepsTheUsersFilesWhateverTheirNames) {
  test::TempDir dir;
  const auto scenario = dir.write("busy.toml", test::kBusyScene);
  const auto out = dir.path() / "out";
  std::filesystem::create_directories(out / "frames");
  for (const char* mine : {"important.tmp-1", "notes.tmp-2.txt", "notes.tmp-", "summary.json.tmp-x", "my.csv.tmp-3"})
    dir.write(std::string("out/") + mine, "the user's\n");
  for (const char* stale :
       {"timeseries.csv.tmp-999999999", "impacts.csv.tmp-999999999", "scenario.toml.tmp-999999999", "frames.ice.frames.tmp-999999999"})
    dir.write(std::string("out/") + stale, "half a file\n");
  dir.write("out/frames/frame_000003.vtp.tmp-999999999", "half a frame\n");
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --quiet --no-plots --steps 5 --out " + out.string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  for (const char* mine : {"important.tmp-1", "notes.tmp-2.txt", "notes.tmp-", "summary.json.tmp-x", "my.csv.tmp-3"})
    EXPECT_EQ(test::readFile(out / mine), "the user's\n") << mine;
  for (const char* stale :
       {"timeseries.csv.tmp-999999999", "impacts.csv.tmp-999999999", "scenario.toml.tmp-999999999", "frames.ice.frames.tmp-999999999"})
    EXPECT_FALSE(std::filesystem::exists(out / stale)) << stale;
  EXPECT_FALSE(std::filesystem::exists(out / "frames" / "frame_000003.vtp.tmp-999999999"));
}

// The run's scenario.toml shows the values the scenario left to their defaults (docs/scenario.md
// 2 documents them): the vessel's size, dof and the speed its thrust gives, the field generator's
// settings, the output's frame_every and formats; and only those the choices made read.
TEST(GemRun, TheRecordedScenarioShowsTheDefaultsTheScenarioLeftOut) {
  test::TempDir dir;
  const auto scenario = dir.write("sparse.toml",
                                  "[simulation]\nsteps = 20\n[domain]\nx = [0.0, 60.0]\ny = [-30.0, 30.0]\n[field]\n"
                                  "concentration = 0.3\n[vessel]\nbollard_thrust = 92e3\n");
  const auto out = dir.path() / "out";
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --quiet --no-plots --steps 2 --out " + out.string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  const std::string record = test::readFile(out / "scenario.toml");
  const toml::table recorded = toml::parse(record);
  EXPECT_EQ(recorded["vessel"]["length"].value<double>(), 100.0) << record;
  EXPECT_EQ(recorded["vessel"]["beam"].value<double>(), 20.0) << record;
  EXPECT_EQ(recorded["vessel"]["dof"].value<std::int64_t>(), 1) << record;
  EXPECT_EQ(recorded["vessel"]["heading_deg"].value<double>(), 0.0) << record;
  const std::optional<double> openWater = recorded["vessel"]["open_water_speed"].value<double>();
  ASSERT_TRUE(openWater) << record;
  EXPECT_NEAR(*openWater, 2.6, 1e-6) << record;  // the thesis's pair for 92 kN
  EXPECT_EQ(recorded["vessel"]["speed"].value<double>(), openWater) << record;
  EXPECT_EQ(recorded["vessel"]["position"][0].value<double>(), -60.0) << record;
  EXPECT_FALSE(recorded["vessel"]["vertices"]) << record;  // the default hull follows length and beam
  EXPECT_EQ(recorded["field"]["kind"].value<std::string>(), "random_convex") << record;
  EXPECT_EQ(recorded["field"]["count"].value<std::int64_t>(), 0) << record;
  EXPECT_NEAR(recorded["field"]["size_mean"].value_or(0.0), 6.9, 1e-6) << record;
  EXPECT_EQ(recorded["field"]["max_sides"].value<std::int64_t>(), 7) << record;
  EXPECT_FALSE(recorded["field"]["size"]) << record;  // the hexagons' key
  EXPECT_EQ(recorded["domain"]["walls"].value<bool>(), false) << record;
  EXPECT_FALSE(recorded["domain"]["wall_thickness"]) << record;  // no walls: it takes no effect
  EXPECT_EQ(recorded["output"]["frame_every"].value<std::int64_t>(), 10) << record;
  EXPECT_EQ(recorded["output"]["timeseries_every"].value<std::int64_t>(), 1) << record;
  EXPECT_EQ(recorded["output"]["vtk_encoding"].value<std::string>(), "ascii") << record;
  const toml::array* formats = recorded["output"]["formats"].as_array();
  ASSERT_TRUE(formats) << record;
  ASSERT_EQ(formats->size(), 2u) << record;
  EXPECT_EQ(formats->get(0)->value<std::string>(), "vtk") << record;
  EXPECT_EQ(recorded["simulation"]["steps"].value<std::int64_t>(), 2) << record;  // --steps, not the file's 20
  EXPECT_EQ(recorded["simulation"]["morton_sort"].value<bool>(), true) << record;
  EXPECT_EQ(recorded["simulation"]["stop_when"].value<std::string>(), "duration") << record;
  EXPECT_FALSE(recorded["simulation"]["duration"]) << record;
  EXPECT_FALSE(recorded["simulation"]["stop_distance"]) << record;
}

TEST(GemCli, VersionNamesTheVersionRealTypeAndPluginAbi) {
  test::TempDir dir;
  EXPECT_EQ(test::runGem("--version", dir.path() / "log"), 0);
  const std::string text = test::readFile(dir.path() / "log");
  EXPECT_NE(text.find(std::string("gem ") + GEM_VERSION), std::string::npos) << text;
  EXPECT_NE(text.find("plugin ABI " + std::to_string(GEM_PLUGIN_ABI_VERSION)), std::string::npos) << text;
}

// simulation.stop_when: a vessel in open water crosses a 40 m field (the domain, no floes).
namespace {

constexpr const char* kCrossing = R"(
[simulation]
dt = 0.1
steps = 3000
[domain]
x = [0.0, 40.0]
y = [-30.0, 30.0]
[vessel]
position = [-60.0, 0.0]
open_water_speed = 5.0
[output]
frame_every = 0
)";

// The vessel's centroid x after each step, from timeseries.csv.
std::vector<double> shipX(const std::filesystem::path& dir) {
  std::istringstream in(test::readFile(dir / "timeseries.csv"));
  std::vector<double> x;
  std::string line;
  std::getline(in, line);  // header
  while (std::getline(in, line)) x.push_back(std::stod(test::csvCells(line)[1]));
  return x;
}

}  // namespace

TEST(StopRule, VesselLeftFieldStopsOnceTheHullIsClearOfTheField) {
  test::TempDir dir;
  Scenario s = test::scenarioFromToml(dir, kCrossing, {"simulation.stop_when=\"vessel_left_field\""});
  s.output.dir = dir.path() / "out";
  const RunSummary r = runScenario(s, quietRun());
  EXPECT_EQ(r.stopReason, "vessel_left_field");
  EXPECT_TRUE(r.completed);
  const std::vector<double> x = shipX(s.output.dir);
  ASSERT_EQ(static_cast<long>(x.size()), r.steps);
  ASSERT_LT(r.steps, 3000);
  // The hull's reach from its centroid (its farthest vertex, from state.csv): the rule fires at the
  // first step with the centroid past x = 40 + reach.
  double reach = 0;
  std::istringstream state(test::readFile(s.output.dir / "state.csv"));
  for (std::string line; std::getline(state, line);) {
    const std::vector<std::string> cells = test::csvCells(line);
    if (cells[1] != "vessel") continue;
    std::istringstream vertices(cells[11]);
    for (double vx, vy; vertices >> vx >> vy;) reach = std::max(reach, std::hypot(vx - std::stod(cells[2]), vy - std::stod(cells[3])));
  }
  ASSERT_GT(reach, 50.0);  // the 100 m hull
  EXPECT_GT(x.back(), 40.0 + reach);
  EXPECT_LE(x[x.size() - 2], 40.0 + reach + 1e-6);
  const auto summary = readSummaryJson(s.output.dir / "summary.json");
  EXPECT_EQ(summary.at("stop_reason"), "vessel_left_field");
  EXPECT_EQ(summary.at("steps"), std::to_string(r.steps));
}

TEST(StopRule, DistanceStopsAtTheFirstStepPastIt) {
  test::TempDir dir;
  Scenario s = test::scenarioFromToml(dir, kCrossing, {"simulation.stop_when=\"distance\"", "simulation.stop_distance=20.0"});
  s.output.dir = dir.path() / "out";
  const RunSummary r = runScenario(s, quietRun());
  EXPECT_EQ(r.stopReason, "distance");
  const std::vector<double> x = shipX(s.output.dir);
  ASSERT_GE(x.size(), 2u);
  EXPECT_GE(x.back() - -60.0, 20.0);
  EXPECT_LT(x[x.size() - 2] - -60.0, 20.0);
}

TEST(StopRule, DurationRunsEveryStepAndBadSettingsAreRefused) {
  test::TempDir dir;
  Scenario s = test::scenarioFromToml(dir, kCrossing, {"simulation.steps=50"});
  s.output.dir = dir.path() / "out";
  const RunSummary r = runScenario(s, quietRun());
  EXPECT_EQ(r.steps, 50);
  EXPECT_EQ(r.stopReason, "duration");
  auto refused = [&](const std::vector<std::string>& overrides, const std::string& expected) {
    try {
      test::scenarioFromToml(dir, kCrossing, overrides);
      ADD_FAILURE() << "accepted: " << overrides.front();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused({"simulation.stop_when=\"distance\""}, "simulation.stop_when");  // no stop_distance
  refused({"simulation.stop_distance=5.0"}, "simulation.stop_distance");   // without stop_when = "distance"
  refused({"simulation.stop_when=\"harbour\""}, "simulation.stop_when");
  try {
    test::scenarioFromToml(dir, "[simulation]\nsteps = 10\nstop_when = \"vessel_left_field\"\n");
    ADD_FAILURE() << "a stop rule that follows the vessel was accepted without a vessel";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no [vessel]"), std::string::npos) << e.what();
  }
}

// A scenario kept in its run folder as scenario.toml is the user's file: the run's record never
// overwrites it.
TEST(GemRun, AScenarioInItsOwnRunFolderIsNotOverwritten) {
  test::TempDir dir;
  const std::string text = std::string("# my notes\n") + kCrossing;
  const auto scenario = dir.write("scenario.toml", text);
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --quiet --steps 5 --out " + dir.path().string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  EXPECT_EQ(test::readFile(scenario), text);
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "summary.json"));
}

// ParaView frames of a CPU run carry each body's contact force: zero for a floe touching nothing,
// positive for one the vessel is pushing, and its value is |sum of its impulses| / dt, so the
// vessel's equals the time series' ice force magnitude when only the ice touches it.
TEST(GemRun, FramesCarryEachBodysContactForce) {
  test::TempDir dir;
  const auto scenario = dir.write("push.toml", test::kContactForceScene);
  const auto out = dir.path() / "out";
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --quiet --no-plots --out " + out.string(), dir.path() / "log"), 0)
      << test::readFile(dir.path() / "log");
  test::expectContactForcesInFrames(out);
}

// A summary value below the smallest normal double (a run's subnormal simulated time, once dt
// could be 1e-310 s; today dt is at least 1e-6 s, so the writer is called directly) is written as
// it is: its rounding once went through std::stod, which threw, and the run ended as an internal
// error with state.csv but no summary.json.
TEST(GemRun, SubnormalValuesReachTheSummary) {
  RunSummary summary;
  summary.simTime = 5e-310;
  const std::string json = summaryJson(summary);
  const auto at = json.find("\"sim_time_s\": ");
  ASSERT_NE(at, std::string::npos) << json;
  const double time = std::strtod(json.c_str() + at + 14, nullptr);
  EXPECT_GT(time, 0.0) << json;
  EXPECT_LT(time, 1e-300) << json;
}

// The closing report lists the files the run folder holds: no frames when the run wrote none.
TEST(GemRun, TheClosingReportListsTheFilesWritten) {
  test::TempDir dir;
  const auto scenario = dir.write("plain.toml",
                                  "[simulation]\ndt = 0.1\nsteps = 5\n[output]\nframe_every = 0\n"
                                  "[[floes]]\nvertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]\n");
  ASSERT_EQ(test::runGem("run " + scenario.string() + " --no-plots --out " + (dir.path() / "out").string(), dir.path() / "log"), 0);
  const std::string log = test::readFile(dir.path() / "log");
  const auto at = log.find("  outputs ");
  ASSERT_NE(at, std::string::npos) << log;
  const std::string line = log.substr(at, log.find('\n', at) - at);
  EXPECT_NE(line.find("summary.json"), std::string::npos) << line;
  EXPECT_NE(line.find("gem.log"), std::string::npos) << line;
  EXPECT_EQ(line.find("frames.pvd"), std::string::npos) << line;
  EXPECT_EQ(line.find("frames.ice"), std::string::npos) << line;
}
