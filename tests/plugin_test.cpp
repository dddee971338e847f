// Plugins (issue 4, docs/plugins.md): the descriptor check, every load error with exit status 2
// and a message naming the file and the cause (broken plugins built by tests/CMakeLists.txt), name
// clashes and override, and the SDK end to end: install GEM to a prefix, build each example under
// plugins/ out of tree against it, run its scenario with the installed gem, see it in gem info.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <string>

#include "framework/app/plugin_loader.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using gem::test::readFile;
using gem::test::TempDir;

namespace {

std::string plugin(const std::string& name) { return std::string(GEM_TEST_PLUGIN_DIR) + "/lib" + name + ".so"; }

// Runs a shell command; returns its exit status, its output in `log`.
int run(const std::string& command, const fs::path& log) {
  const int status = std::system((command + " > " + log.string() + " 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

const std::string kFloe =
    "[simulation]\ndt = 0.1\nsteps = 20\nbroadphase = \"all_pairs\"\n"
    "[[floes]]\nvertices = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\nthickness = 0.5\nvelocity = [1.0, 0.0]\n";

GemPluginDescriptor matching() {
  return {GEM_PLUGIN_ABI_VERSION, sizeof(gem::Real), "", GEM_COMPILER_ID, GEM_COMPILER_VERSION, GEM_VERSION, "t", "1"};
}

}  // namespace

TEST(PluginDescriptor, AcceptsItsOwnBuildAndSaysWhatDiffers) {
  EXPECT_TRUE(gem::descriptorMismatches(matching()).empty());
  GemPluginDescriptor d = matching();
  d.abiVersion = GEM_PLUGIN_ABI_VERSION + 1;
  d.realSize = 3;  // not read: under another ABI only the version is trusted
  auto m = gem::descriptorMismatches(d);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_TRUE(contains(m[0], "plugin ABI version")) << m[0];
  d = matching();
  d.realSize = sizeof(gem::Real) == 8 ? 4 : 8;
  d.compilerVersion = "1.0.0";
  m = gem::descriptorMismatches(d);
  ASSERT_EQ(m.size(), 2u);
  EXPECT_TRUE(contains(m[0], "real type")) << m[0];
  EXPECT_TRUE(contains(m[1], "compiler")) << m[1];
}

// Each broken library: gem exits 2 with one message naming the file and the cause, and nothing of
// the library runs after its descriptor (the mismatched ones abort in gem_plugin_register).
TEST(PluginErrors, EachExitsWithStatus2NamingTheFileAndTheCause) {
  TempDir dir;
  const fs::path log = dir.path() / "log.txt";
  const struct {
    std::string file, cause;
  } cases[] = {
      {plugin("absent"), "no such file"},
      {plugin("not_a_plugin"), "not a GEM plugin"},
      {plugin("missing_register"), "missing symbol gem_plugin_register"},
      {plugin("abi_mismatch"), "plugin ABI version 999 (this GEM: " + std::to_string(GEM_PLUGIN_ABI_VERSION) + ")"},
      {plugin("real_mismatch"), "real type"},
      {plugin("compiler_mismatch"), "compiler TurboC 3.0.0"},
      {dir.write("text.so", "not a library\n").string(), "cannot be loaded"},
      {plugin("throws_int"), "not a std::exception"},
      {plugin("throws_at_load"), "a static initializer threw while the library loaded: throws_at_load: a static initializer throwing"},
      {plugin("unresolved_symbol"), "undefined symbol: gem_test_symbol_that_no_library_defines"},
      // What GEM writes itself, or a built-in writes, is not a plugin's to take.
      {plugin("takes_impacts_csv"), "impacts.csv is written by the record output of stream \"impacts\" from built-in"},
      {plugin("takes_steps_key"), "\"steps\" is a key GEM writes in summary.json itself"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(gem::test::runGem("info --plugin " + c.file, log), 2) << c.file;
    const std::string text = readFile(log);
    EXPECT_TRUE(contains(text, c.file)) << text;
    EXPECT_TRUE(contains(text, c.cause)) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
    EXPECT_FALSE(contains(text, "Bad file descriptor")) << "a stale errno, not the cause: " << text;
  }
}

// A plugin whose parse function throws a std::runtime_error (where TableReader::fail was meant):
// refused as bad input naming the scenario, the event's table and the plugin, with its event off
// as on (every event's table is read); it once ended gem as an internal error naming nothing.
TEST(PluginErrors, AParseFunctionThatThrowsIsNamedWithItsEventAndPlugin) {
  TempDir dir;
  const fs::path log = dir.path() / "log.txt";
  for (const char* enabled : {"false", "true"}) {
    SCOPED_TRACE(enabled);
    const fs::path scenario = dir.write("case.toml", kFloe + "[[plugins]]\npath = \"" + plugin("throws_in_parse") +
                                                         "\"\n[events.throws_in_parse]\nenabled = " + enabled + "\n");
    EXPECT_EQ(gem::test::runGem("check " + scenario.string(), log), 2);
    const std::string text = readFile(log);
    EXPECT_TRUE(contains(text, "case.toml:11:1: events.throws_in_parse: the plugin's parse function threw")) << text;
    EXPECT_TRUE(contains(text, "parsing fails on purpose")) << text;
    EXPECT_TRUE(contains(text, plugin("throws_in_parse"))) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
  }
}

// An event that opens a built-in's record stream with another record type: exit 2 naming both
// events, the plugin and the scenario's line, whether the event is on or off.
TEST(PluginErrors, AStreamOpenedWithAnotherTypeNamesBothEventsAndThePlugin) {
  TempDir dir;
  const fs::path log = dir.path() / "log.txt";
  for (const char* enabled : {"false", "true"}) {
    SCOPED_TRACE(enabled);
    const fs::path scenario = dir.write("case.toml", kFloe + "[[plugins]]\npath = \"" + plugin("reuses_impacts_stream") +
                                                         "\"\n[events.reuses_impacts_stream]\nenabled = " + enabled + "\n");
    EXPECT_EQ(gem::test::runGem("check " + scenario.string(), log), 2);
    const std::string text = readFile(log);
    EXPECT_TRUE(contains(text, "events.reuses_impacts_stream (plugin " + plugin("reuses_impacts_stream"))) << text;
    EXPECT_TRUE(contains(text, "events.ship_impact (built-in)")) << text;
    EXPECT_TRUE(contains(text, "case.toml:11:1")) << text;
    EXPECT_TRUE(contains(text, "the record stream \"impacts\"")) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
  }
}

// A plugin built for the other real type that calls GEM functions taking a Real: refused for its
// real type, from its note, before the dynamic linker could fail on those symbols.
TEST(PluginErrors, AnotherRealTypeIsRefusedBeforeItsSymbolsAreBound) {
  TempDir dir;
  const fs::path log = dir.path() / "log.txt";
  const std::string file = plugin("other_real_type");
  EXPECT_EQ(gem::test::runGem("info --plugin " + file, log), 2);
  const std::string text = readFile(log);
  EXPECT_TRUE(contains(text, file + ": refused, it was built for another GEM: real type " + (sizeof(gem::Real) == 8 ? "float" : "double")))
      << text;
  EXPECT_FALSE(contains(text, "undefined symbol")) << text;
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
}

TEST(PluginErrors, ScenarioEntryGetsTheScenariosFileLineAndColumn) {
  TempDir dir;
  fs::copy_file(plugin("abi_mismatch"), dir.path() / "libabi.so");
  const fs::path scenario = dir.write("case.toml", kFloe + "[[plugins]]\npath = \"libabi.so\"\n");
  EXPECT_EQ(gem::test::runGem("check " + scenario.string(), dir.path() / "log"), 2);
  const std::string text = readFile(dir.path() / "log");
  EXPECT_TRUE(contains(text, "case.toml:10:")) << text;
  EXPECT_TRUE(contains(text, "libabi.so")) << text;
  EXPECT_TRUE(contains(text, "plugin ABI version 999")) << text;
}

TEST(PluginErrors, BrokenPluginOnGemPluginPathExits2) {
  TempDir dir;
  fs::create_directories(dir.path() / "p");
  fs::copy_file(plugin("not_a_plugin"), dir.path() / "p" / "libnot_a_plugin.so");
  const fs::path log = dir.path() / "log";
  EXPECT_EQ(run("GEM_PLUGIN_PATH=" + (dir.path() / "p").string() + " " GEM_BINARY_DIR "/gem info", log), 2);
  EXPECT_TRUE(contains(readFile(log), "GEM_PLUGIN_PATH")) << readFile(log);
  EXPECT_TRUE(contains(readFile(log), "libnot_a_plugin.so: not a GEM plugin")) << readFile(log);
  EXPECT_EQ(run("GEM_PLUGIN_PATH=" + (dir.path() / "nowhere").string() + " " GEM_BINARY_DIR "/gem info", log), 2);
  EXPECT_TRUE(contains(readFile(log), "no such folder")) << readFile(log);
}

// A run whose plugin came from GEM_PLUGIN_PATH records it in its scenario.toml ([[plugins]], by
// absolute path) and in gem.log: `gem run RUN_DIR/scenario.toml` repeats the run without the
// variable (it once stopped at "events.floe_friction: unknown event"), and with it set again (the
// same library is not loaded twice).
TEST(PluginPath, ARunRecordsThePluginsOfGemPluginPath) {
  TempDir dir;
  fs::create_directories(dir.path() / "p");
  fs::copy_file(plugin("floe_friction"), dir.path() / "p" / "libfloe_friction.so");
  const fs::path scenario = dir.write("case.toml", kFloe +
                                                       "[[floes]]\nvertices = [[10.5, 0.0], [20.0, 0.0], [20.0, 10.0], [10.5, 10.0]]\n"
                                                       "thickness = 0.5\n[events.floe_friction]\nenabled = true\n");
  const fs::path log = dir.path() / "log";
  const std::string withPath = "GEM_PLUGIN_PATH=" + (dir.path() / "p").string() + " ";
  ASSERT_EQ(
      run(withPath + GEM_BINARY_DIR "/gem run " + scenario.string() + " --quiet --no-plots --out " + (dir.path() / "first").string(), log),
      0)
      << readFile(log);
  const std::string recorded = readFile(dir.path() / "first" / "scenario.toml");
  EXPECT_TRUE(contains(recorded, "[[plugins]]")) << recorded;
  EXPECT_TRUE(contains(recorded, (dir.path() / "p" / "libfloe_friction.so").string())) << recorded;
  EXPECT_TRUE(contains(readFile(dir.path() / "first" / "gem.log"), "libfloe_friction.so (floe_friction 0.1.0), from GEM_PLUGIN_PATH"));
  for (const std::string& env : {std::string(), withPath}) {
    SCOPED_TRACE(env);
    ASSERT_EQ(run(env + GEM_BINARY_DIR "/gem run " + (dir.path() / "first" / "scenario.toml").string() + " --quiet --no-plots --out " +
                      (dir.path() / "again").string(),
                  log),
              0)
        << readFile(log);
    EXPECT_EQ(readFile(dir.path() / "first" / "timeseries.csv"), readFile(dir.path() / "again" / "timeseries.csv"));
  }
}

// A plugin's "drag" clashes with the built-in (exit 2, both origins named) unless its entry says
// override = true; then the plugin's drag (C_d = 5) is the one that runs.
TEST(PluginRegistry, NameClashIsAnErrorUnlessTheScenarioOverrides) {
  TempDir dir;
  const std::string path = plugin("drag_clash");
  const fs::path clash = dir.write("clash.toml", kFloe + "[[plugins]]\npath = \"" + path + "\"\n");
  EXPECT_EQ(gem::test::runGem("check " + clash.string(), dir.path() / "log"), 2);
  const std::string text = readFile(dir.path() / "log");
  EXPECT_TRUE(contains(text, "clash.toml:10:")) << text;
  EXPECT_TRUE(contains(text, "event \"drag\"")) << text;
  EXPECT_TRUE(contains(text, path + " (drag_clash 0.0.1)")) << text;
  EXPECT_TRUE(contains(text, "built-in")) << text;
  EXPECT_TRUE(contains(text, "override = true")) << text;

  // The same library twice (once by a path with "..", once plain) is one load, then no clash.
  const fs::path over = dir.write("override.toml", kFloe + "[[plugins]]\npath = \"" + path + "\"\noverride = true\n" +
                                                       "[[plugins]]\npath = \"" + GEM_TEST_PLUGIN_DIR + "/../plugins/libdrag_clash.so\"\n");
  ASSERT_EQ(gem::test::runGem("run " + over.string() + " --quiet --out " + (dir.path() / "over").string(), dir.path() / "log"), 0)
      << readFile(dir.path() / "log");
  const fs::path plain = dir.write("plain.toml", kFloe);
  ASSERT_EQ(gem::test::runGem("run " + plain.string() + " --quiet --out " + (dir.path() / "plain").string(), dir.path() / "log"), 0);
  // state.csv: id,kind,x,y,angle,vx,...: the plugin's drag slows the floe far more.
  auto vx = [](const fs::path& state) { return gem::readCsvTable(state).numbers("vx").at(0); };
  const double vxOverride = vx(dir.path() / "over" / "state.csv"), vxPlain = vx(dir.path() / "plain" / "state.csv");
  EXPECT_GT(vxPlain, 0.8);
  EXPECT_LT(vxOverride, 0.5 * vxPlain);
}

// A plugin written against GEM 0.1's include paths (tests/plugins/old_layout.cpp) still builds,
// through the deprecated forwarding headers, loads and runs: its event pushes the floe towards +y.
TEST(PluginSdk, APluginOfTheOldLayoutStillBuildsAndRuns) {
  TempDir dir;
  const fs::path scenario = dir.write("old.toml", kFloe + "[[plugins]]\npath = \"" + plugin("old_layout") +
                                                      "\"\n[events.sideways_push]\naccel = 1.0\n[events.drag]\nenabled = false\n");
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() + " --quiet --out " + (dir.path() / "out").string(), dir.path() / "log"), 0)
      << readFile(dir.path() / "log");
  // state.csv: id,kind,x,y,angle,vx,vy,...: 20 steps of 0.1 s at 1 m/s^2 give vy = 2 m/s.
  EXPECT_NEAR(gem::readCsvTable(dir.path() / "out" / "state.csv").numbers("vy").at(0), 2.0, 1e-9);
}

// Declared event order (docs/plugins.md "Order"): gem info lists the pair events in the order they
// run, the friction plugin (kOrder = impulses + 50) between impact and ship_impact; and it reads the
// impact's normal impulse from the contact's slot: a floe sliding along another drags it along.
TEST(PluginOrder, AFrictionEventRunsAfterImpactAndReadsItsNormalImpulse) {
  TempDir dir;
  const fs::path log = dir.path() / "info.txt";
  ASSERT_EQ(gem::test::runGem("info --plugin " + plugin("floe_friction"), log), 0) << readFile(log);
  const std::string info = readFile(log);
  const size_t elastic = info.find("  elastic_contact "), impact = info.find("  impact "), friction = info.find("  floe_friction "),
               ship = info.find("  ship_impact ");
  ASSERT_NE(friction, std::string::npos) << info;
  EXPECT_LT(elastic, impact) << info;
  EXPECT_LT(impact, friction) << info;
  EXPECT_LT(friction, ship) << info;
  EXPECT_TRUE(contains(info, "  floe_friction      two-body  250")) << info;

  // Floe 0 slides up (+y) while it closes on floe 1 (+x): the impact stops the closing; friction
  // then passes part of the sliding to floe 1.
  const std::string scene =
      "[simulation]\ndt = 0.01\nsteps = 100\nbroadphase = \"all_pairs\"\n[events.drag]\nenabled = false\n"
      "[[floes]]\nvertices = [[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]\nthickness = 0.5\nvelocity = [2.0, 1.0]\n"
      "[[floes]]\nvertices = [[10.2, -5.0], [20.2, -5.0], [20.2, 5.0], [10.2, 5.0]]\nthickness = 0.5\n"
      "[[plugins]]\npath = \"" +
      plugin("floe_friction") + "\"\n";
  auto vyOfFloe1 = [&](const std::string& name, const std::string& extra) {
    const fs::path scenario = dir.write(name + ".toml", scene + extra);
    EXPECT_EQ(gem::test::runGem("run " + scenario.string() + " --quiet --out " + (dir.path() / name).string(), dir.path() / "log"), 0)
        << readFile(dir.path() / "log");
    // state.csv: id,kind,x,y,angle,vx,vy,...: the row of id 1.
    const gem::CsvTable state = gem::readCsvTable(dir.path() / name / "state.csv");
    const std::vector<double> ids = state.numbers("id"), vy = state.numbers("vy");
    for (size_t r = 0; r < ids.size(); ++r)
      if (ids[r] == 1) return vy[r];
    ADD_FAILURE() << "no floe 1 in " << name;
    return 0.0;
  };
  const double without = vyOfFloe1("without", ""), with = vyOfFloe1("with", "[events.floe_friction]\nmu = 0.5\n");
  EXPECT_LT(std::abs(without), 0.01);  // the impact alone pushes floe 1 (almost) along x only
  EXPECT_GT(with, without + 0.05);
}

// A plugin's own record stream and output file (tests/plugins/contact_areas.cpp): written to the
// run folder, one row per floe-floe contact, counted in summary.json under the plugin's keys.
TEST(PluginRecords, APluginsRecordStreamIsWrittenToItsOwnFile) {
  TempDir dir;
  const fs::path scenario = dir.write("areas.toml",
                                      "[simulation]\ndt = 0.1\nsteps = 30\nbroadphase = \"all_pairs\"\n"
                                      "[[floes]]\nvertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]\nvelocity = [1.0, 0.0]\n"
                                      "[[floes]]\nvertices = [[4.5, 0.0], [8.5, 0.0], [8.5, 4.0], [4.5, 4.0]]\n"
                                      "[[floes]]\nvertices = [[9.0, 0.0], [13.0, 0.0], [13.0, 4.0], [9.0, 4.0]]\nvelocity = [-1.0, 0.0]\n"
                                      "[[plugins]]\npath = \"" +
                                          plugin("contact_areas") + "\"\n[events.contact_area_log]\nmin_area = 0.0\n");
  ASSERT_EQ(gem::test::runGem("run " + scenario.string() + " --quiet --out " + (dir.path() / "out").string(), dir.path() / "log"), 0)
      << readFile(dir.path() / "log");
  const std::string csv = readFile(dir.path() / "out" / "contact_areas.csv");
  ASSERT_EQ(csv.rfind("t,id_a,id_b,area_m2\n", 0), 0u) << csv;
  const long rows = std::count(csv.begin(), csv.end(), '\n') - 1;
  EXPECT_GT(rows, 0) << "the floes meet: rows are logged";
  // The plugin's writer appends to the row it is handed: each row is its own, four columns.
  std::istringstream lines(csv);
  std::string line;
  while (std::getline(lines, line)) ASSERT_EQ(std::count(line.begin(), line.end(), ','), 3) << line;
  const std::string summary = readFile(dir.path() / "out" / "summary.json");
  EXPECT_TRUE(contains(summary, "\"contact_rows\": " + std::to_string(rows) + ",")) << summary;
  EXPECT_TRUE(contains(summary, "\"contact_area_m2\": {\"min\"")) << summary;
  EXPECT_TRUE(contains(summary, "\"impacts\": 0,")) << summary;  // ship_impact's stream, no vessel here
}

// gem info's columns fit the longest name: a plugin's event of 25 characters
// (tests/plugins/spin_up.cpp) once pushed its own row's columns out of line with the others.
TEST(PluginInfo, TheColumnsFitTheLongestName) {
  TempDir dir;
  const fs::path log = dir.path() / "log.txt";
  ASSERT_EQ(gem::test::runGem("info --plugin " + plugin("spin_up"), log), 0) << readFile(log);
  std::istringstream lines(readFile(log));
  std::string line;
  std::map<std::string, size_t> column;  // where the phase (or origin, or version) column starts, by row
  size_t fromColumn = 0;
  while (std::getline(lines, line)) {
    if (line.rfind("  ", 0) != 0) continue;
    const size_t nameEnd = line.find(' ', 2);
    const std::string name = line.substr(2, nameEnd - 2);
    if (name.empty()) {
      fromColumn = line.find("from ");  // the plugin's origin, under the name column's end
      continue;
    }
    column[name] = line.find_first_not_of(' ', nameEnd);
  }
  ASSERT_TRUE(column.count("spin_past_any_finite_rate")) << readFile(log);
  for (const char* other : {"drag", "motion", "all_pairs", "triangulation_mesh", "spin_up"}) {
    ASSERT_TRUE(column.count(other)) << other << ": " << readFile(log);
    EXPECT_EQ(column[other], column["spin_past_any_finite_rate"]) << other << ": " << readFile(log);
  }
  EXPECT_EQ(fromColumn, column["drag"]) << readFile(log);
}

// A plugin event's parameter without a default: asked for when the event is on, not when a scenario
// that loads the plugin leaves the event off (every loaded event is parsed: EventConfig::enabled).
TEST(PluginRecords, ARequiredParameterIsAskedForOnlyWhenTheEventIsOn) {
  TempDir dir;
  const std::string floes =
      "[simulation]\ndt = 0.1\nsteps = 5\n"
      "[[floes]]\nvertices = [[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]]\n"
      "[[plugins]]\npath = \"" +
      plugin("contact_areas") + "\"\n";
  const fs::path off = dir.write("off.toml", floes), on = dir.write("on.toml", floes + "[events.contact_area_log]\n");
  EXPECT_EQ(gem::test::runGem("run " + off.string() + " --quiet --out " + (dir.path() / "off").string(), dir.path() / "off.log"), 0)
      << readFile(dir.path() / "off.log");
  EXPECT_EQ(gem::test::runGem("run " + on.string() + " --quiet --out " + (dir.path() / "on").string(), dir.path() / "on.log"), 2);
  const std::string message = readFile(dir.path() / "on.log");
  EXPECT_TRUE(contains(message, "on.toml")) << message;
  EXPECT_TRUE(contains(message, "events.contact_area_log.min_area")) << message;
  EXPECT_TRUE(contains(message, "required")) << message;
}

// A broadphase from a plugin that proposes its pairs in any order, reversed, repeated, or a body
// with itself (tests/plugins/scrambled_pairs.cpp): GEM puts them in the contract's order, so the
// run is all_pairs's bit for bit.
TEST(PluginBroadphase, PairsInAnyOrderGiveTheBuiltInsTrajectoriesBitForBit) {
  TempDir dir;
  const fs::path scenario = dir.write("pack.toml",
                                      "[simulation]\ndt = 0.1\nsteps = 150\n"
                                      "[domain]\nx = [0.0, 120.0]\ny = [-30.0, 30.0]\n[field]\nconcentration = 0.5\n"
                                      "[vessel]\nposition = [-45.0, 0.0]\nopen_water_speed = 5.0\n[output]\nframe_every = 0\n"
                                      "[[plugins]]\npath = \"" +
                                          plugin("scrambled_pairs") + "\"\n");
  auto run = [&](const std::string& name, const std::string& broadphase) {
    const fs::path out = dir.path() / name;
    EXPECT_EQ(gem::test::runGem("run " + scenario.string() + " --quiet --no-plots --broadphase " + broadphase + " --out " + out.string(),
                                dir.path() / (name + ".log")),
              0)
        << readFile(dir.path() / (name + ".log"));
    return readFile(out / "state.csv") + readFile(out / "timeseries.csv") + readFile(out / "impacts.csv");
  };
  const std::string reference = run("all_pairs", "all_pairs"), scrambled = run("scrambled", "scrambled_pairs");
  ASSERT_GT(reference.size(), 1000u);
  EXPECT_EQ(reference, scrambled);
}

// The SDK from the build, as a user does it: install, build each example out of tree, run it. One
// test per example, so that each stays under a minute in the sanitizer pass (each builds its own).

namespace {

// GEM installed to DIR/prefix by `cmake --install` of the build; `gem` is the installed binary.
struct InstalledGem {
  fs::path prefix, gem, log;
  std::string cmake;
  explicit InstalledGem(const TempDir& dir)
      : prefix(dir.path() / "prefix"),
        gem(prefix / "bin" / "gem"),
        log(dir.path() / "log.txt"),
        cmake(std::string("\"") + GEM_CMAKE_COMMAND + "\"") {}
  // Returns the install's exit status (its output in log).
  int install() const { return run(cmake + " --install " GEM_BINARY_DIR " --prefix " + prefix.string(), log); }
  // Configures and builds the example plugins/NAME out of tree against the install, in DIR/NAME.
  int buildExample(const std::string& name, const fs::path& build) const {
    const std::string makeProgram = GEM_MAKE_PROGRAM;
    const std::string configure =
        cmake + " -G \"" GEM_CMAKE_GENERATOR "\"" + (makeProgram.empty() ? "" : " -DCMAKE_MAKE_PROGRAM=\"" + makeProgram + "\"") +
        " -DCMAKE_CXX_COMPILER=\"" GEM_CXX_COMPILER "\" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=" + prefix.string();
    const int status = run(configure + " -S " GEM_SOURCE_DIR "/plugins/" + name + " -B " + build.string(), log);
    return status != 0 ? status : run(cmake + " --build " + build.string(), log);
  }
};

}  // namespace

// The install holds the CMake package and the plugin API, and the installed gem runs gem bench
// from its own share/gem/scenarios, not the source tree.
TEST(PluginSdk, TheInstalledGemHasItsPackageHeadersAndScenarios) {
  TempDir dir;
  const InstalledGem installed(dir);
  ASSERT_EQ(installed.install(), 0) << readFile(installed.log);
  ASSERT_EQ(run(installed.gem.string() + " bench --backend cpu --cases 456 --steps 3", installed.log), 0) << readFile(installed.log);
  EXPECT_NE(readFile(installed.log).find("scenes from " + fs::weakly_canonical(installed.prefix / "share" / "gem" / "scenarios").string()),
            std::string::npos)
      << readFile(installed.log);
  EXPECT_TRUE(fs::exists(installed.prefix / "lib" / "cmake" / "gem" / "gemConfig.cmake"));
  EXPECT_TRUE(fs::exists(installed.prefix / "include" / "gem" / "framework" / "plugin_api.hpp"));
}

class PluginSdkExample : public ::testing::TestWithParam<std::string> {};

// Each example under plugins/ builds out of tree against the install, gem info lists it (by
// --plugin and by GEM_PLUGIN_PATH) with its path and version, its scenario runs, and it does what
// it is for.
TEST_P(PluginSdkExample, BuildsOutOfTreeRunsAndShowsInGemInfo) {
  const std::string name = GetParam();
  TempDir dir;
  const InstalledGem installed(dir);
  const fs::path& log = installed.log;
  const std::string gem = installed.gem.string();
  ASSERT_EQ(installed.install(), 0) << readFile(log);
  const fs::path build = dir.path() / name;
  ASSERT_EQ(installed.buildExample(name, build), 0) << readFile(log);
  const fs::path library = build / ("lib" + name + ".so");
  ASSERT_TRUE(fs::exists(library));

  ASSERT_EQ(run(gem + " info --plugin " + library.string(), log), 0) << readFile(log);
  EXPECT_TRUE(contains(readFile(log), "from " + fs::canonical(library).string() + " (" + name + " 1.0.0)")) << readFile(log);
  ASSERT_EQ(run("GEM_PLUGIN_PATH=" + build.string() + " " + gem + " info", log), 0) << readFile(log);
  EXPECT_TRUE(contains(readFile(log), fs::canonical(library).string())) << readFile(log);

  const fs::path out = dir.path() / "run";
  ASSERT_EQ(run(gem + " run " + (build / "scenario.toml").string() + " --quiet --out " + out.string(), log), 0) << readFile(log);
  ASSERT_TRUE(fs::exists(out / "summary.json"));

  if (name == "shear_current") {
    // U = 0.2 + 0.01 y, floes at y = -40, 0, 40 (state.csv rows in id order): the first drifts
    // back (U < 0), the last fastest.
    std::vector<double> vx = gem::readCsvTable(out / "state.csv").numbers("vx");
    ASSERT_EQ(vx.size(), 3u);
    EXPECT_LT(vx[0], 0);
    EXPECT_GT(vx[1], 0);
    EXPECT_GT(vx[2], 2 * vx[1]);
  } else if (name == "rafting_onset") {
    // The thin pair's onset is logged (floes 0 and 1), the thick pair's is not.
    const std::string text = readFile(out / "rafting.csv");
    EXPECT_TRUE(contains(text, "t,floe_a,floe_b,x,y,vc,thickness\n")) << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 2) << text;
    EXPECT_TRUE(contains(text, ",0,1,")) << text;
  } else if (name == "sweep_and_prune") {
    // The same contacts as all_pairs, so the same final state bit for bit.
    const fs::path allPairs = dir.path() / "run_all_pairs";
    ASSERT_EQ(run(gem + " run " + (build / "scenario.toml").string() + " --broadphase all_pairs --quiet --out " + allPairs.string(), log),
              0)
        << readFile(log);
    const std::string sap = readFile(out / "state.csv");
    EXPECT_GT(std::count(sap.begin(), sap.end(), '\n'), 20);
    EXPECT_EQ(sap, readFile(allPairs / "state.csv"));
    EXPECT_TRUE(contains(readFile(out / "summary.json"), "sweep_and_prune"));
  } else {
    FAIL() << "no check written for the example " << name;
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, PluginSdkExample, ::testing::Values("shear_current", "rafting_onset", "sweep_and_prune"),
                         [](const auto& info) { return info.param; });

// Nothing lost when a run fails: an event that fails mid-run (exit 1) leaves the whole rows
// written so far under their final names, and no summary.json (a run that failed is not complete).
TEST(PluginRun, ARunThatFailsMidwayKeepsItsRowsAndWritesNoSummary) {
  gem::test::TempDir dir;
  const auto scenario = dir.write("fail.toml",
                                  "[simulation]\nsteps = 50\n[vessel]\nposition = [0.0, 0.0]\n"
                                  "[events.fail_midway]\nat_step = 5\n[[plugins]]\npath = \"" +
                                      plugin("fail_midway") + "\"\n");
  const auto out = dir.path() / "run";
  const int status = gem::test::runGem("run " + scenario.string() + " --quiet --out " + out.string(), dir.path() / "log.txt");
  const std::string log = gem::test::readFile(dir.path() / "log.txt");
  EXPECT_EQ(status, 1) << log;
  EXPECT_NE(log.find("failing on purpose at step 5"), std::string::npos) << log;
  EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  const std::string series = gem::test::readFile(out / "timeseries.csv");
  EXPECT_EQ(std::count(series.begin(), series.end(), '\n'), 1 + 5) << series;  // header + steps 0..4
  EXPECT_TRUE(std::filesystem::exists(out / "impacts.csv"));
  for (const auto& entry : std::filesystem::recursive_directory_iterator(out))
    EXPECT_EQ(entry.path().string().find(".tmp"), std::string::npos) << entry.path();
}
