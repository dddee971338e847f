// Bad input never crashes and never runs: each case exits with status 2, one clear message that
// names the file and line (or the key), and leaves no summary.json (the list, item 7).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <fstream>
#include <string>

#include "framework/api/input_size.hpp"
#include "framework/scenario/scenario.hpp"
#include "test_support.hpp"

using gem::test::TempDir;

namespace {

struct BadCase {
  const char* name;
  std::string toml;
  std::vector<std::string> expected;  // substrings of the message
  std::string file = "case.toml";     // the file the message must name
  std::vector<std::string> absent{};  // substrings it must not hold (a key it once blamed wrongly)
};
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.name; }

const std::string kSim = "[simulation]\ndt = 0.1\nsteps = 5\n";
const std::string kDomain = "[domain]\nx = [0.0, 100.0]\ny = [-50.0, 50.0]\n";

std::string floe(const std::string& vertices, const std::string& extra = "", const std::string& thickness = "1.0") {
  return "[[floes]]\nvertices = " + vertices + "\nthickness = " + thickness + "\n" + extra;
}

const std::string kSquare = "[[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]]";

std::vector<BadCase> badCases() {
  return {
      {"non_convex", kSim + floe("[[0.0, 0.0], [10.0, 0.0], [5.0, 2.0], [10.0, 10.0], [0.0, 10.0]]"), {"floes[0]", "not convex", ":4:"}},
      {"self_intersecting", kSim + floe("[[0.0, 0.0], [10.0, 10.0], [10.0, 0.0], [0.0, 10.0]]"), {"floes[0]", "not convex"}},
      {"two_vertices", kSim + floe("[[0.0, 0.0], [10.0, 0.0]]"), {"floes[0]", "3 to 19 vertices"}},
      {"too_many_vertices",
       kSim + floe([] {
         std::string v = "[";
         for (int k = 0; k < 20; ++k)
           v += (k ? ", [" : "[") + std::to_string(10 * std::cos(k * 0.314159)) + ", " + std::to_string(10 * std::sin(k * 0.314159)) + "]";
         return v + "]";
       }()),
       {"floes[0]", "3 to 19 vertices, got 20"}},
      {"nan_vertex", kSim + floe("[[nan, 0.0], [10.0, 0.0], [10.0, 10.0]]"), {"vertices", "finite"}},
      {"infinite_dt", "[simulation]\ndt = inf\n", {"simulation.dt", "finite", ":2:"}},
      {"zero_thickness", kSim + floe(kSquare, "", "0.0"), {"floes[0].thickness", "from 0.01 to 1000, got 0"}},
      {"floe_thinner_than_any_ice", kSim + floe(kSquare, "", "1e-300"), {"floes[0].thickness", "from 0.01 to 1000, got 1e-300"}},
      {"field_thinner_than_any_ice",
       kSim + kDomain + "[field]\nconcentration = 0.3\nthickness = 1e-9\n",
       {"field.thickness", "from 0.01 to 1000"}},
      {"group_thicker_than_an_iceberg",
       kSim + kDomain + "[field]\nconcentration = 0.3\ngroups = [{ coverage = 0.3, thickness = 5e3 }]\n",
       {"thickness", "from 0.01 to 1000"}},
      {"negative_dt", "[simulation]\ndt = -0.1\n", {"simulation.dt", "from 1e-06 to 3600, got -0.1"}},
      // A value a hair past a limit is shown with its digits, not rounded onto the limit.
      {"dt_a_hair_past_its_limit", "[simulation]\ndt = 3600.0000001\n", {"simulation.dt", "got 3600.0000001"}},
      {"floe_a_hair_too_fast",
       kSim + "[[floes]]\nvertices = " + kSquare + "\nvelocity = [100.0000001, 0.0]\n",
       {"floes[0].velocity", "got [100.0000001, 0]"}},
      {"zero_duration", "[simulation]\nduration = 0.0\n", {"simulation.duration", "positive"}},
      {"zero_mass", kSim + "[vessel]\nmass = 0.0\n", {"vessel.mass", "from 1 to 1e+12"}},
      {"overlap",
       kSim + floe(kSquare) + floe("[[5.0, 5.0], [15.0, 5.0], [15.0, 15.0], [5.0, 15.0]]"),
       {"overlap at the start", "floes[0]", "floes[1]"}},
      {"unknown_top_key", kSim + "[simulaton]\ndt = 0.1\n", {"unknown key \"simulaton\"", "simulation"}},
      {"unknown_section_key", "[simulation]\ndtt = 0.1\n", {"simulation.dtt", "valid keys here", "dt"}},
      {"unknown_event", kSim + "[events.dragg]\n", {"events.dragg", "unknown event", "drag"}},
      {"unknown_event_key", kSim + "[events.drag]\ncdd = 0.1\n", {"events.drag.cdd", "did you mean \"cd\"?"}},
      {"unknown_broadphase", "[simulation]\nbroadphase = \"octree\"\n", {"octree", "uniform_grid", "variable_radius"}},
      {"wrong_type", "[simulation]\ndt = \"fast\"\n", {"simulation.dt", "expected a number", ":2:"}},
      {"malformed_toml", "[simulation]\ndt = 0.1\nduration = = 3\n", {":3:"}},
      {"bad_dof", kSim + "[vessel]\ndof = 2\n", {"vessel.dof"}},
      {"unknown_cuda_driver", "[simulation]\ncuda_driver = \"warp\"\n", {"simulation.cuda_driver", "resident", "device", ":2:"}},
      {"missing_ice_file", kSim + "[field]\nkind = \"file\"\nfile = \"nowhere.ice\"\n", {"nowhere.ice"}, "nowhere.ice"},
      {"malformed_ice_file", kSim + "[field]\nkind = \"file\"\nfile = \"bad.ice\"\n", {"bad.ice:4:1", "malformed XML"}, "bad.ice"},
      {"field_without_domain", kSim + "[field]\nconcentration = 0.3\n", {"[domain]"}},
      {"bad_concentration", kSim + kDomain + "[field]\nconcentration = 0.95\n", {"field.concentration"}},
      {"plugin_missing_file", kSim + "[[plugins]]\npath = \"libx.so\"\n", {"plugins.path", "libx.so", "no such file", ":5:"}},
      // Hostile but fair (issue "Trust"): classes of input that crashed a parser or ran as nothing.
      {"empty_file", "", {"empty"}},
      {"only_comments", "# nothing but a comment\n", {"nothing in it"}},
      {"dotted_key_50000_parts",
       "[simulation]\n" +
           [] {
             std::string key = "a";
             for (int k = 0; k < 50000; ++k) key += ".a";
             return key + " = 1\n";
           }(),
       {"dotted key of more than 64 parts", ":2:"}},
      {"arrays_50000_deep",
       "[simulation]\nx = " + std::string(50000, '[') + std::string(50000, ']') + "\n",
       {"nested more than 64 deep", ":2:"}},
      {"tiny_dt", "[simulation]\ndt = 1e-300\n", {"simulation.dt", "from 1e-06 to 3600"}},
      // 5e-324 s with a step count that fits: 1/dt is inf, and NaN once filled timeseries.csv.
      {"subnormal_dt", "[simulation]\ndt = 5e-324\nsteps = 10\n", {"simulation.dt", "from 1e-06 to 3600"}},
      {"duration_over_dt_past_the_step_cap", "[simulation]\ndt = 1e-6\nduration = 1e4\n", {"simulation.duration", "more than the 2e9"}},
      // 1e-308 m once made walls too thin to be convex, refused naming no key.
      {"walls_too_thin", kSim + kDomain + "walls = true\nwall_thickness = 1e-308\n", {"domain.wall_thickness", "from 0.01"}},
      {"huge_duration", "[simulation]\nduration = 1e300\n", {"simulation.duration", "more than the 2e9"}},
      {"a_frame_format_twice", kSim + "[output]\nformats = [\"vtk\", \"ice\", \"vtk\"]\n", {"output.formats", "\"vtk\" is listed twice"}},
      {"non_convex_hull",
       kSim + "[vessel]\nvertices = [[-50.0, -10.0], [50.0, -10.0], [0.0, 0.0], [50.0, 10.0], [-50.0, 10.0]]\n"
              "frame_angle_deg = [80.0, 30.0, 30.0, 80.0, 80.0]\n",
       {"vessel.vertices", "not convex"}},
      {"field_beyond_memory",
       kSim + "[domain]\nx = [0.0, 1e7]\ny = [0.0, 1e7]\n[field]\nkind = \"hexagons\"\n",
       {"field: about", "floes", "GB"}},
      {"duration_below_one_step", "[simulation]\ndt = 0.1\nduration = 0.01\n", {"simulation.duration", "shorter than one step"}},
      // Values whose derived quantities overflow (the second hostile audit): refused, naming the key.
      {"huge_dt_makes_the_time_infinite", "[simulation]\ndt = 1e308\nsteps = 5\n", {"simulation.dt", "to 3600, got 1e+308", ":2:"}},
      {"huge_thickness_beyond_any_ice", kSim + floe(kSquare, "", "1e308"), {"floes[0].thickness", "from 0.01 to 1000, got 1e+308"}},
      {"domain_beyond_any_field", kSim + "[domain]\nx = [-1e308, 1e308]\ny = [-50.0, 50.0]\nwalls = true\n", {"domain.x", "within"}},
      {"walls_too_thick", kSim + kDomain + "walls = true\nwall_thickness = 1e308\n", {"domain.wall_thickness", "to 1e+07, got 1e+308"}},
      {"nul_in_output_dir", kSim + "[output]\ndir = \"a\\u0000b\"\n", {"output.dir", "NUL"}},
      {"empty_hull", kSim + "[vessel]\nvertices = []\nframe_angle_deg = []\n", {"vessel.vertices", "at least 3 vertices, got 0"}},
      // Values that passed gem check and made gem run fail at step 1 with a non-finite state (the
      // third hostile audit): each refused at load by its own key, line and range.
      {"vessel_heading_beyond_a_turn", kSim + "[vessel]\nheading_deg = 1e308\n", {"vessel.heading_deg", "from -360 to 360", ":5:"}},
      {"vessel_speed_beyond_any_ship", kSim + "[vessel]\nspeed = 1e308\n", {"vessel.speed", "from 0 to 100", ":5:"}},
      {"vessel_thrust_beyond_any_ship", kSim + "[vessel]\nbollard_thrust = 1e300\n", {"vessel.bollard_thrust", "from 0 to 1e+08"}},
      {"open_water_speed_near_zero", kSim + "[vessel]\nopen_water_speed = 1e-300\n", {"vessel.open_water_speed", "from 0.01"}},
      {"vessel_mass_beyond_any_ship", kSim + "[vessel]\nmass = 1e-300\n", {"vessel.mass", "from 1 to 1e+12"}},
      {"autopilot_period_near_zero",
       kSim + "[vessel]\ndof = 3\n[events.autopilot]\nperiod = 1e-300\n",
       {"events.autopilot.period", "from 0.01", ":7:"},
       "case.toml",
       {"g1"}},
      {"autopilot_gain_beyond_any",
       kSim + "[vessel]\ndof = 3\n[events.autopilot]\ng1 = 1e308\n",
       {"events.autopilot.g1", "from 0 to 1e+30"}},
      {"autopilot_heading_beyond_a_turn",
       kSim + "[vessel]\ndof = 3\n[events.autopilot]\nheading_deg = -1e308\n",
       {"events.autopilot.heading_deg", "from -360 to 360"}},
      {"wind_force_beyond_any_sky", kSim + "[events.wind]\nforce = 1e308\n", {"events.wind.force", "from -10000 to 10000"}},
      {"current_direction_beyond_a_turn", kSim + "[events.current]\ndirection_deg = 1e308\n", {"events.current.direction_deg"}},
      {"drag_coefficient_beyond_any_sea", kSim + "[events.drag]\ncd = 1e308\n", {"events.drag.cd", "from 0 to 10"}},
      // The two-body events' parameters: 1e308 once ran until a floe's state was no longer finite.
      {"elastic_factor_beyond_any_ice",
       kSim + "[events.elastic_contact]\nfactor = 1e308\n",
       {"events.elastic_contact.factor", "from 0 to 10"}},
      {"elastic_stress_beyond_any_ice",
       kSim + "[events.elastic_contact]\nsigma_max = 1e308\n",
       {"events.elastic_contact.sigma_max", "1e+09"}},
      {"friction_beyond_any_surface", kSim + "[events.impact]\nfriction = 1e308\n", {"events.impact.friction", "from 0 to 10"}},
      {"hull_pressure_beyond_any_ice", kSim + "[events.ship_impact]\npressure = 1e308\n", {"events.ship_impact.pressure", "1e+09"}},
      {"floe_velocity_beyond_any_floe",
       kSim + floe(kSquare, "velocity = [1e300, 0.0]\n"),
       {"floes[0].velocity", "within +-100 m/s", ":7:"}},
      {"floe_spin_beyond_any_floe", kSim + floe(kSquare, "angular_velocity = 1e300\n"), {"floes[0].angular_velocity", "from -100 to 100"}},
      {"ice_file_spin_beyond_any_floe",
       kSim + "[field]\nkind = \"file\"\nfile = \"spin.ice\"\n",
       {"spin.ice:3:1: object 0", "angular velocity must be within +-100 rad/s"},
       "spin.ice"},
      // A polygon of a .ice field is blamed on its <object> element's line and column.
      {"ice_file_polygon_not_convex",
       kSim + "[field]\nkind = \"file\"\nfile = \"bent.ice\"\n",
       {"bent.ice:4:3: object 1", "not convex"},
       "bent.ice"},
      // Floes past +-1e7 m: a square 1e300 m across was refused as "not convex", one 1e15 m out ran.
      {"ice_file_floe_beyond_any_sea",
       kSim + "[field]\nkind = \"file\"\nfile = \"far.ice\"\n",
       {"far.ice:3:1: object 0", "each vertex coordinate must be within +-1e+07 m"},
       "far.ice"},
      {"floe_beyond_any_sea",
       kSim + floe("[[1e15, 0.0], [1.00000001e15, 0.0], [1.00000001e15, 1e7], [1e15, 1e7]]"),
       {"floes[0]", "each vertex coordinate must be within +-1e+07 m"}},
      // The hull's own keys are named, not the polygon drawn from them (vessel.vertices was blamed).
      {"vessel_length_beyond_any_ship",
       kSim + "[vessel]\nlength = 1e308\n",
       {"vessel.length", "from 0.1 to 10000", ":5:"},
       "case.toml",
       {"vertices"}},
      {"vessel_beam_below_any_ship",
       kSim + "[vessel]\nbeam = 1e-308\n",
       {"vessel.beam", "from 0.1 to 10000", ":5:"},
       "case.toml",
       {"vertices"}},
      {"vessel_draft_beyond_any_ship", kSim + "[vessel]\ndraft = 1e308\n", {"vessel.draft", "at most 1000"}, "case.toml", {"vertices"}},
      {"vessel_position_beyond_any_field",
       kSim + "[vessel]\nposition = [1e308, 0.0]\n",
       {"vessel.position", "within +-1e+07 m"},
       "case.toml",
       {"vertices"}},
      {"hull_vertex_beyond_any_ship",
       kSim +
           "[vessel]\nvertices = [[-1e300, -10.0], [50.0, -10.0], [50.0, 10.0], [-50.0, 10.0]]\nframe_angle_deg = [0.0, 0.0, 0.0, 0.0]\n",
       {"vessel.vertices", "within +-10000 m"}},
      // Scenario keys that name a file or folder: "" once meant the default, or the scenario's folder.
      {"empty_output_dir", kSim + "[output]\ndir = \"\"\n", {"output.dir", "an empty path", ":5:"}},
      {"empty_field_file", kSim + "[field]\nkind = \"file\"\nfile = \"\"\n", {"field.file", "an empty path", ":6:"}},
      {"empty_plugin_path", kSim + "[[plugins]]\npath = \"\"\n", {"plugins.path", "an empty path", ":5:"}},
  };
}

}  // namespace

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ExitsWithStatus2AndAClearMessageAndWritesNoSummary) {
  const BadCase& c = GetParam();
  TempDir dir;
  dir.write(
      "bad.ice",
      "<iceFloeSim numFrames=\"1\">\n<frame index=\"0\">\n<object index=\"0\"><coordinates>0 0 1 0</coordinates\n</frame></iceFloeSim>\n");
  dir.write("spin.ice",
            "<iceFloeSim numFrames=\"1\">\n<frame index=\"0\">\n<object index=\"0\"><coordinates>0 0 10 0 10 10 0 10</coordinates>"
            "<velocity x=\"0\" y=\"0\" a=\"1e300\"/><thickness>1</thickness></object>\n</frame></iceFloeSim>\n");
  dir.write("bent.ice",
            "<iceFloeSim numFrames=\"1\">\n<frame index=\"0\">\n<object index=\"0\"><coordinates>0 0 10 0 10 10 0 10</coordinates>"
            "<thickness>1</thickness></object>\n  <object index=\"1\"><coordinates>20 0 30 0 25 2 30 10 20 10</coordinates>"
            "<thickness>1</thickness></object>\n</frame></iceFloeSim>\n");
  dir.write("far.ice",
            "<iceFloeSim numFrames=\"1\">\n<frame index=\"0\">\n<object index=\"0\"><coordinates>0 0 1e300 0 1e300 1e300 0 1e300"
            "</coordinates><thickness>1</thickness></object>\n</frame></iceFloeSim>\n");
  const auto scenario = dir.write("case.toml", c.toml);
  const auto out = dir.path() / "run";
  for (const char* command : {"run", "check"}) {
    const int status = gem::test::runGem(
        std::string(command) + " " + scenario.string() + " --quiet" + (std::string(command) == "run" ? " --out " + out.string() : ""),
        dir.path() / "log.txt");
    const std::string log = gem::test::readFile(dir.path() / "log.txt");
    EXPECT_EQ(status, 2) << command << ": " << log;
    EXPECT_EQ(std::count(log.begin(), log.end(), '\n'), 1) << "one message: " << log;
    EXPECT_NE(log.find(c.file), std::string::npos) << "names the file: " << log;
    for (const std::string& e : c.expected) EXPECT_NE(log.find(e), std::string::npos) << "missing \"" << e << "\" in: " << log;
    for (const std::string& e : c.absent) EXPECT_EQ(log.find(e), std::string::npos) << "blames \"" << e << "\": " << log;
    EXPECT_FALSE(std::filesystem::exists(out / "summary.json"));
  }
}

INSTANTIATE_TEST_SUITE_P(Cases, BadInput, ::testing::ValuesIn(badCases()),
                         [](const ::testing::TestParamInfo<BadCase>& info) { return std::string(info.param.name); });

// Things that are not scenario files, numbers on the command line that would be ignored or overflow,
// and a token too long to echo: exit 2, one short message naming the file or the option.
TEST(BadInputCli, NotAScenarioFileAndBadNumbersOnTheCommandLine) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  const auto good = dir.write("good.toml", kSim);
  std::filesystem::create_directories(dir.path() / "folder.toml");
  const struct {
    std::string arguments, expected;
  } cases[] = {
      {"run " + (dir.path() / "folder.toml").string(), "a folder, not a scenario file"},
      {"run /dev/zero", "not a regular file"},
      {"run " + good.string() + " --steps -5", "--steps -5"},
      {"run " + good.string() + " --steps 0", "--steps 0"},
      {"run " + good.string() + " --duration nan", "--duration nan"},
      // Each value is echoed as typed: CLI11 read '' as 0 and saturated a huge count.
      {"run " + good.string() + " --steps ''", "--steps '': expected a whole number"},
      {"run " + good.string() + " --steps 99999999999999999999", "--steps 99999999999999999999:"},
      {"run " + good.string() + " --steps 12x", "--steps 12x:"},
      {"run " + good.string() + " --duration ''", "--duration '': expected a positive number"},
      {"run " + good.string() + " --duration 5s", "--duration 5s:"},
      // An empty part of a --set key is the --set's fault, not the file's.
      {"run " + good.string() + " --set simulation..dt=1", "--set simulation..dt=...: the key must be"},
      {"run " + good.string() + " --duration 1e300", "a run takes 1 to 2e9 steps"},
      {"sweep " + (dir.path() / "folder.toml").string(), "a folder, not a sweep file"},
      {"sweep " + dir.write("empty_sweep.toml", "").string(), "empty"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(gem::test::runGem(c.arguments + " --quiet --out " + (dir.path() / "out").string(), log), 2) << c.arguments;
    const std::string text = gem::test::readFile(log);
    EXPECT_NE(text.find(c.expected), std::string::npos) << c.arguments << ": " << text;
    EXPECT_LE(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "summary.json")) << c.arguments;
  }
  // gem bench's step count is bounded too (10^13 steps ran for ever).
  EXPECT_EQ(gem::test::runGem("bench --cases 824 --steps 9999999999999", log), 2);
  EXPECT_NE(gem::test::readFile(log).find("--steps 9999999999999: from 1 to 10^7"), std::string::npos) << gem::test::readFile(log);
  // A file where the run folder (or a folder above it) should be: exit 2 naming it.
  const auto file = dir.write("a_file", "x");
  EXPECT_EQ(gem::test::runGem("run " + good.string() + " --quiet --out " + (file / "run").string(), log), 2);
  EXPECT_NE(gem::test::readFile(log).find(file.string() + " is a file, not a folder"), std::string::npos) << gem::test::readFile(log);
  // A 5 MB token in an unknown key is not echoed whole.
  const auto huge = dir.write("huge.toml", kSim + "[simulation.extra]\n" + std::string(5000000, 'k') + " = 1\n");
  EXPECT_EQ(gem::test::runGem("check " + huge.string(), log), 2);
  EXPECT_LT(std::filesystem::file_size(log), 2000u) << "the message echoes the whole token";
}

// Links that lead nowhere, and files whose size the system does not know, are said to be what
// they are: a loop of links was "no such scenario file", a dangling --out link "File exists", and a
// /proc file (size 0, text inside) "empty".
TEST(BadInputCli, LinksThatLeadNowhereAndFilesOfUnknownSizeAreNamedForWhatTheyAre) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  const auto good = dir.write("good.toml", kSim);
  std::filesystem::create_symlink("loop_b.toml", dir.path() / "loop_a.toml");
  std::filesystem::create_symlink("loop_a.toml", dir.path() / "loop_b.toml");
  std::filesystem::create_symlink("missing.toml", dir.path() / "dangling.toml");
  std::filesystem::create_symlink(dir.path() / "gone" / "run", dir.path() / "dangling_out");
  const struct {
    std::string arguments, expected;
  } cases[] = {
      {"check " + (dir.path() / "loop_a.toml").string(),
       "loop_a.toml: cannot be read as a scenario file: Too many levels of symbolic links"},
      {"check " + (dir.path() / "dangling.toml").string(), "dangling.toml: a symbolic link to missing.toml, which does not exist"},
      {"run " + good.string() + " --quiet --out " + (dir.path() / "dangling_out").string(),
       "dangling_out is a symbolic link to " + (dir.path() / "gone" / "run").string() + ", which does not exist"},
      {"check /proc/self/status", "/proc/self/status:1:"},  // read and parsed, not "empty"
  };
  for (const auto& c : cases) {
    EXPECT_EQ(gem::test::runGem(c.arguments, log), 2) << c.arguments;
    const std::string text = gem::test::readFile(log);
    EXPECT_NE(text.find(c.expected), std::string::npos) << c.arguments << ": " << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message: " << text;
  }
}

// A first word that is no command names itself and the commands (CLI11 said "A subcommand is
// required", as if none had been given).
TEST(BadInputCli, AnUnknownCommandIsNamedWithTheCommands) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  EXPECT_EQ(gem::test::runGem("nosuchcmd", log), 2);
  const std::string text = gem::test::readFile(log);
  EXPECT_NE(text.find("unknown command \"nosuchcmd\""), std::string::npos) << text;
  EXPECT_NE(text.find("run, check"), std::string::npos) << text;
}

// A loop of symbolic links where a run folder or one of its files is read (gem analyze, plot, view,
// movie) is bad input, exit 2, naming the path; it ended as an internal failure, exit 1, in the
// library's words ("filesystem error: status: Too many levels of symbolic links").
TEST(BadInputCli, ALoopOfSymbolicLinksInARunFolderIsBadInput) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  std::filesystem::create_symlink("loop", dir.path() / "loop");
  const std::filesystem::path run = dir.path() / "run";
  std::filesystem::create_directories(run);
  std::filesystem::create_symlink("timeseries.csv", run / "timeseries.csv");
  std::filesystem::create_symlink("impacts.csv", run / "impacts.csv");
  std::filesystem::create_symlink("frames.ice", run / "frames.ice");
  const std::string loop = (dir.path() / "loop").string();
  for (const std::string& arguments : {"analyze " + loop, "plot " + loop, "view " + loop, "analyze " + run.string(), "plot " + run.string(),
                                       "view " + run.string() + " --out " + (dir.path() / "v.html").string(),
                                       "movie " + run.string() + " --still 0 --out " + (dir.path() / "m.png").string()}) {
    EXPECT_EQ(gem::test::runGem(arguments, log), 2) << arguments << ": " << gem::test::readFile(log);
    const std::string text = gem::test::readFile(log);
    EXPECT_EQ(text.find("gem: failed"), std::string::npos) << arguments << ": " << text;
    EXPECT_TRUE(text.find("symbolic link") != std::string::npos || text.find("Too many levels") != std::string::npos)
        << arguments << ": " << text;
  }
}

// Every output place named on the command line (--out, --csv) is checked before any work: a file
// where a folder must be is exit 2, one line naming the option and the path, and nothing is run
// (no benchmark row, no calibration impact, no case folder).
TEST(BadInputCli, AnOutputPlaceThatCannotBeWrittenIsRefusedBeforeAnyWork) {
  TempDir dir;
  const auto file = dir.write("a_file", "x");
  const std::string blocked = (file / "below").string();
  const auto log = dir.path() / "log.txt";
  const auto sweepFile = dir.write("study.toml", "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n");
  dir.write("base.toml", kSim);
  const struct {
    std::string arguments, option;
  } cases[] = {
      {"bench --cases 100 --steps 10 --csv " + blocked + "/x.csv", "gem bench --csv"},
      {"bench --cases 100 --steps 10 --csv " + blocked + "/", "gem bench --csv"},
      {"calibrate --out " + blocked, "gem calibrate --out"},
      {"sweep " + sweepFile.string() + " --out " + blocked, "gem sweep --out"},
      {"movie " + dir.path().string() + " --out " + blocked + "/m.mp4", "gem movie --out"},
      {"view " + dir.path().string() + " --out " + blocked + "/v.html", "gem view --out"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(gem::test::runGem(c.arguments, log), 2) << c.arguments;
    const std::string text = gem::test::readFile(log);
    EXPECT_NE(text.find(c.option), std::string::npos) << c.arguments << ": " << text;
    EXPECT_NE(text.find(file.string() + " is a file, not a folder"), std::string::npos) << c.arguments << ": " << text;
    EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 1) << "one message, nothing run before it: " << text;
  }
  // A folder where the page should be.
  EXPECT_EQ(gem::test::runGem("view " + dir.path().string() + " --out " + dir.path().string(), log), 2);
  EXPECT_NE(gem::test::readFile(log).find("a folder, not a file"), std::string::npos) << gem::test::readFile(log);
}

// Numeric options out of their range are refused with a short message naming the option and the
// range (CLI11's open-ended checks printed the largest double as the bound), before any work.
TEST(BadInputCli, ANumericOptionOutOfRangeNamesItsRange) {
  TempDir dir;
  dir.write("base.toml", kSim);
  const auto sweepFile = dir.write("study.toml", "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n");
  const auto log = dir.path() / "log.txt";
  const std::string out = " --out " + (dir.path() / "out").string();
  for (const std::string& arguments :
       {"sweep " + sweepFile.string() + " --jobs -2" + out, "sweep " + sweepFile.string() + " --batch -1" + out,
        "sweep " + sweepFile.string() + " --case-index -1" + out, "view " + dir.path().string() + " --every 0"}) {
    EXPECT_EQ(gem::test::runGem(arguments, log), 2) << arguments;
    const std::string text = gem::test::readFile(log);
    EXPECT_NE(text.find("not in range"), std::string::npos) << arguments << ": " << text;
    EXPECT_LT(text.size(), 200u) << arguments << ": " << text;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "summary.csv")) << arguments;
  }
}

// A vessel of 1e308 kg is refused by its own key and range (it once got as far as the autopilot's
// gains worked out from it, inf, and named those); and a --set whose value holds a newline cannot
// slip a second key in unseen.
TEST(BadInputCli, ValuesBeyondTheirRangeAndSetValuesOfTwoLinesAreRefused) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  const auto heavy = dir.write("heavy.toml", kSim + "[vessel]\nmass = 1e308\n");
  EXPECT_EQ(gem::test::runGem("run " + heavy.string() + " --quiet --out " + (dir.path() / "out").string(), log), 2);
  std::string text = gem::test::readFile(log);
  EXPECT_NE(text.find("heavy.toml:5:8: vessel.mass: must be from 1 to 1e+12"), std::string::npos) << text;
  EXPECT_EQ(text.find("autopilot"), std::string::npos) << text;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "summary.json"));
  const auto good = dir.write("good.toml", kSim);
  EXPECT_EQ(gem::test::runGem("check " + good.string() + " --set \"$(printf 'simulation.dt=0.5\\nbogus_key=3')\"", log), 2);
  text = gem::test::readFile(log);
  EXPECT_NE(text.find("--set simulation.dt: the value must be one TOML value, with no other key after it"), std::string::npos) << text;
}

// A bad value given by --set is blamed on the --set, not on the scenario file that never held it:
// scenario keys, event parameters, unknown keys and bodies.
TEST(BadInputCli, ABadSetValueNamesTheSet) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  const auto good = dir.write("good.toml", kSim);
  for (const std::string set : {"simulation.dt=-1", "vessel.dof=2", "simulation.dtt=0.1", "events.drag.cd=-5", "events.drag.cdd=1",
                                "broadphase.brute_pair.skin=1.0", "floes=[{vertices=[[0.0,0.0],[1.0,0.0]],thickness=1.0}]"}) {
    EXPECT_EQ(gem::test::runGem("check " + good.string() + " --set '" + set + "'", log), 2) << set;
    const std::string text = gem::test::readFile(log);
    EXPECT_NE(text.find("--set " + set + ": "), std::string::npos) << text;
    EXPECT_EQ(text.find("good.toml"), std::string::npos) << "blames the file: " << text;
  }
  // A bad value in the file itself still names the file, line and column, with a --set beside it.
  const auto bad = dir.write("bad.toml", "[simulation]\ndt = -0.1\nsteps = 5\n");
  EXPECT_EQ(gem::test::runGem("check " + bad.string() + " --set simulation.seed=3", log), 2);
  EXPECT_NE(gem::test::readFile(log).find("bad.toml:2:"), std::string::npos) << gem::test::readFile(log);
}

TEST(BadInputCli, MissingScenarioFileAndUnknownOptionExit2) {
  TempDir dir;
  EXPECT_EQ(gem::test::runGem("run " + (dir.path() / "absent.toml").string(), dir.path() / "log.txt"), 2);
  EXPECT_NE(gem::test::readFile(dir.path() / "log.txt").find("absent.toml"), std::string::npos);
  EXPECT_EQ(gem::test::runGem("run --frobnicate x.toml", dir.path() / "log.txt"), 2);
}

// Every error of a scenario's tables comes in one message, each with its line and column, so the
// user fixes them in one round; an error that only follows from an earlier one is not repeated.
TEST(BadInput, EveryErrorOfTheTablesIsReportedAtOnce) {
  TempDir dir;
  const auto scenario = dir.write("many.toml",
                                  "[simulation]\n"
                                  "dt = -0.1\n"         // line 2
                                  "durations = 60.0\n"  // line 3: a typo
                                  "[vessel]\n"
                                  "mass = \"heavy\"\n"  // line 5
                                  "[output]\n"
                                  "frame_every = -3\n"  // line 7
                                  "formats = [\"vtk\"]\n"
                                  "vtk_encoding = \"zip\"\n");  // line 9
  for (const char* command : {"check", "run"}) {
    const std::string out = std::string(command) == "run" ? " --out " + (dir.path() / "run").string() : "";
    const int status = gem::test::runGem(std::string(command) + " " + scenario.string() + " --quiet" + out, dir.path() / "log.txt");
    const std::string log = gem::test::readFile(dir.path() / "log.txt");
    EXPECT_EQ(status, 2) << log;
    for (const char* e : {":2:", "simulation.dt", ":3:", "did you mean \"duration\"", ":5:", "vessel.mass", ":7:", "output.frame_every",
                          ":9:", "output.vtk_encoding", "5 errors in all"})
      EXPECT_NE(log.find(e), std::string::npos) << "missing \"" << e << "\" in: " << log;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "run" / "summary.json"));
  }
}

// The events' tables too: each event's errors, all of them, in one message.
TEST(BadInput, EveryEventTableErrorIsReportedAtOnce) {
  TempDir dir;
  const auto scenario = dir.write("events.toml", "[simulation]\nsteps = 5\n[events.drag]\ncdd = 0.1\n[events.impact]\nfrictio = 0.2\n");
  const int status = gem::test::runGem("check " + scenario.string() + " --quiet", dir.path() / "log.txt");
  const std::string log = gem::test::readFile(dir.path() / "log.txt");
  EXPECT_EQ(status, 2) << log;
  for (const char* e : {":4:", "events.drag.cdd", ":6:", "events.impact.frictio", "2 errors in all"})
    EXPECT_NE(log.find(e), std::string::npos) << "missing \"" << e << "\" in: " << log;
}

// "Did you mean" for names as for keys: an event, a broadphase, a choice.
TEST(BadInput, MisspelledNamesGetASuggestion) {
  TempDir dir;
  const auto scenario =
      dir.write("names.toml", "[simulation]\nsteps = 5\nbroadphase = \"uniform_gird\"\nbackend = \"cpuu\"\n[events.dragg]\n");
  const int status = gem::test::runGem("check " + scenario.string() + " --quiet", dir.path() / "log.txt");
  const std::string log = gem::test::readFile(dir.path() / "log.txt");
  EXPECT_EQ(status, 2) << log;
  for (const char* e : {"did you mean \"uniform_grid\"", "did you mean \"cpu\"", "did you mean \"drag\"", "3 errors in all"})
    EXPECT_NE(log.find(e), std::string::npos) << "missing \"" << e << "\" in: " << log;
}

// SIGTERM stops gem bench at once: only run, sweep and calibrate catch it to stop between two
// steps; a command that never looks at the flag keeps the signal's default (bench once ran on).
TEST(BadInputCli, SigtermStopsABenchAtOnce) {
  TempDir dir;
  const char* staged = std::getenv("GEM_BINARY_DIR");
  const std::string gem = std::string(staged ? staged : GEM_BINARY_DIR) + "/gem";
  const auto status = dir.path() / "status.txt";
  const std::string script = "cd " + dir.path().string() + " && GEM_SCENARIOS=" + std::string(GEM_SOURCE_DIR) + "/scenarios " + gem +
                             " bench --cases 824 --steps 10000000 > bench.log 2>&1 & p=$!; sleep 2; kill -TERM $p; "
                             "(sleep 30; kill -9 $p 2>/dev/null) & g=$!; wait $p; echo $? > " +
                             status.string() + "; kill $g 2>/dev/null";
  std::system(("sh -c '" + script + "'").c_str());
  EXPECT_EQ(gem::test::readFile(status), "143\n") << "128 + SIGTERM; 137 would be the guard's kill -9 after 30 s";
}

// A folder in the place of one of the run's files (gem.log is written last of all) is refused
// before any work: the run once wrote summary.json and state.csv and then failed on gem.log.
TEST(BadInputCli, AFolderWhereTheRunWritesAFileIsRefusedBeforeAnyWork) {
  TempDir dir;
  const auto good = dir.write("good.toml", kSim);
  for (const char* name : {"gem.log", "summary.json", "state.csv"}) {
    const auto out = dir.path() / (std::string("run_") + name);
    std::filesystem::create_directories(out / name / "sub");
    EXPECT_EQ(gem::test::runGem("run " + good.string() + " --quiet --no-plots --out " + out.string(), dir.path() / "log"), 2) << name;
    const std::string text = gem::test::readFile(dir.path() / "log");
    EXPECT_NE(text.find((out / name).string() + ": a folder where the run writes its file"), std::string::npos) << text;
    EXPECT_FALSE(std::filesystem::exists(out / "timeseries.csv")) << name;
    EXPECT_FALSE(std::filesystem::is_regular_file(out / "summary.json")) << name;
  }
}

// A pipe or a folder where a reader expects a file (the .ice field, impacts.csv read back by gem
// analyze) is refused at once, exit 2, naming the path: opening the pipe once blocked forever, and
// the folder ended gem as an internal error in the C++ library's words.
TEST(BadInputCli, APipeOrAFolderWhereAFileIsReadIsRefusedAtOnce) {
  TempDir dir;
  // Under `timeout`: a reader that opens the pipe would wait for a writer that never comes.
  auto gemWithin30s = [&](const std::string& arguments) {
    const char* staged = std::getenv("GEM_BINARY_DIR");
    const int status = std::system(("timeout 30 " + std::string(staged ? staged : GEM_BINARY_DIR) + "/gem " + arguments + " > " +
                                    (dir.path() / "log").string() + " 2>&1")
                                       .c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  };
  const std::filesystem::path pipe = dir.path() / "pack.ice";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  const auto scenario = dir.write("field.toml", std::string(kSim) + "[field]\nkind = \"file\"\nfile = \"pack.ice\"\n");
  EXPECT_EQ(gemWithin30s("check " + scenario.string()), 2);
  EXPECT_NE(gem::test::readFile(dir.path() / "log").find(pipe.string() + ": not a regular file"), std::string::npos)
      << gem::test::readFile(dir.path() / "log");
  for (const bool folder : {false, true}) {
    const std::filesystem::path run = dir.path() / (folder ? "run_folder" : "run_pipe");
    std::filesystem::create_directories(run);
    if (folder)
      std::filesystem::create_directories(run / "impacts.csv");
    else
      ASSERT_EQ(::mkfifo((run / "impacts.csv").c_str(), 0600), 0);
    EXPECT_EQ(gemWithin30s("analyze --quiet " + run.string()), 2) << folder;
    const std::string text = gem::test::readFile(dir.path() / "log");
    EXPECT_NE(text.find((run / "impacts.csv").string() + (folder ? ": a folder" : ": not a regular file")), std::string::npos) << text;
  }
}

// Control characters a message quotes from the input are written out (\x1b), not sent to the
// terminal: a value's escape sequences once retitled and cleared it.
TEST(BadInputCli, AMessageQuotesControlCharactersAsEscapes) {
  TempDir dir;
  const auto scenario = dir.write("esc.toml", "[simulation]\nsteps = 5\nbackend = \"\\u001b]0;pwned\\u0007\\u001b[2J\"\n");
  EXPECT_EQ(gem::test::runGem("check " + scenario.string(), dir.path() / "log"), 2);
  const std::string text = gem::test::readFile(dir.path() / "log");
  EXPECT_NE(text.find("esc.toml:3:"), std::string::npos) << text;
  EXPECT_NE(text.find("\\x1b]0;pwned\\x07\\x1b[2J"), std::string::npos) << text;
  EXPECT_EQ(text.find('\x1b'), std::string::npos) << text;
}

// An output path that is a pipe, a device or a folder is refused (exit 2), not replaced by the
// file written in its place (gem view --out /dev/full once replaced the device, run as root).
TEST(BadInputCli, AnOutputPathThatIsAPipeIsRefusedAndKept) {
  TempDir dir;
  const std::filesystem::path pipe = dir.path() / "table.csv";
  ASSERT_EQ(::mkfifo(pipe.c_str(), 0600), 0);
  EXPECT_EQ(gem::test::runGem("bench --backend cpu --cases 824 --steps 10 --csv " + pipe.string(), dir.path() / "log"), 2);
  const std::string text = gem::test::readFile(dir.path() / "log");
  EXPECT_NE(text.find(pipe.string() + ": a pipe, not a file GEM may write"), std::string::npos) << text;
  EXPECT_EQ(text.find("ms/step"), std::string::npos) << "refused before any case ran: " << text;
  EXPECT_TRUE(std::filesystem::is_fifo(pipe));
}

// gem plot and gem movie name what is wrong with the run folder or the picture's name: a file
// given as the run folder was "no such run folder", and --still --out x.jpg said "--still needs
// --out FILE.png" though --out was given.
TEST(BadInputCli, RunFolderCommandsSayWhatIsWrongWithTheirPaths) {
  TempDir dir;
  const auto file = dir.write("a.toml", kSim);
  EXPECT_EQ(gem::test::runGem("plot " + file.string(), dir.path() / "log"), 2);
  EXPECT_NE(gem::test::readFile(dir.path() / "log").find(file.string() + ": a file, not a run folder"), std::string::npos)
      << gem::test::readFile(dir.path() / "log");
  EXPECT_EQ(gem::test::runGem("movie " + (dir.path() / "nowhere").string(), dir.path() / "log"), 2);
  EXPECT_NE(gem::test::readFile(dir.path() / "log").find("nowhere: no such run folder"), std::string::npos)
      << gem::test::readFile(dir.path() / "log");
  EXPECT_EQ(gem::test::runGem("movie " + dir.path().string() + " --still 0 --out x.jpg", dir.path() / "log"), 2);
  EXPECT_NE(gem::test::readFile(dir.path() / "log").find("--out x.jpg: --still writes a PNG picture"), std::string::npos)
      << gem::test::readFile(dir.path() / "log");
}

// gem bench's largest field, 10^7 floes (about 30 GB), on a machine that could not hold it, is
// refused before it is generated (on a 24 GB machine it grew for minutes). Where it fits there is
// nothing to refuse: skipped, visibly.
TEST(BadInputCli, ABenchFieldBeyondTheMachinesMemoryIsRefused) {
  if (gem::fieldMemoryNeed(1e7) <= 0.8 * gem::machineMemory()) GTEST_SKIP() << "this machine could hold 10^7 floes";
  TempDir dir;
  EXPECT_EQ(gem::test::runGem("bench --backend cpu --cases 10000000 --steps 10", dir.path() / "log"), 2);
  EXPECT_NE(gem::test::readFile(dir.path() / "log").find("--cases 10000000: 10000000 floes need about"), std::string::npos)
      << gem::test::readFile(dir.path() / "log");
}

// A .ice field or a CSV read back whole that could not fit in memory is refused up front, naming
// the file and its size (a sparse file of 200 GB here): it once grew until std::bad_alloc (exit 1)
// or swapped for minutes.
TEST(BadInputCli, AFileTooLargeToReadIsRefusedNamingItsSize) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  const auto ice = dir.path() / "huge.ice";
  std::ofstream(ice).put('<');
  std::filesystem::resize_file(ice, std::uintmax_t(200) << 30);
  const auto scenario = dir.write("field.toml", kSim + "[field]\nkind = \"file\"\nfile = \"huge.ice\"\n");
  EXPECT_EQ(gem::test::runGem("check " + scenario.string(), log), 2);
  EXPECT_NE(gem::test::readFile(log).find("huge.ice: 215 GB, too large to read"), std::string::npos) << gem::test::readFile(log);
  const auto run = dir.path() / "run";
  std::filesystem::create_directories(run);
  std::ofstream(run / "impacts.csv").put('t');
  std::filesystem::resize_file(run / "impacts.csv", std::uintmax_t(200) << 30);
  EXPECT_EQ(gem::test::runGem("analyze --quiet " + run.string(), log), 2);
  EXPECT_NE(gem::test::readFile(log).find("impacts.csv: 215 GB, too large to read"), std::string::npos) << gem::test::readFile(log);
}

// An empty value of any option or argument that names a file or folder is refused, naming the
// option, before any work: `gem run --out ''` once ran into the scenario's own output folder.
TEST(BadInputCli, AnEmptyPathOptionIsRefusedNamingTheOption) {
  TempDir dir;
  const auto log = dir.path() / "log.txt";
  const auto good = dir.write("good.toml", kSim + "[output]\ndir = \"default_run\"\n");
  dir.write("base.toml", kSim);
  const auto sweepFile = dir.write("study.toml", "[sweep]\nbase = \"base.toml\"\n[[cases]]\nname = \"a\"\n");
  const std::string folder = dir.path().string();
  const struct {
    std::string arguments, option;
  } cases[] = {
      {"run " + good.string() + " --quiet --out ''", "--out"},
      {"run ''", "scenario"},
      {"run --resume ''", "--resume"},
      {"check ''", "scenario"},
      {"info --plugin ''", "--plugin"},
      {"bench --cases 100 --steps 10 --csv ''", "--csv"},
      {"calibrate ''", "scenario"},
      {"calibrate --out ''", "--out"},
      {"sweep ''", "sweep"},
      {"sweep " + sweepFile.string() + " --quiet --out ''", "--out"},
      {"analyze ''", "dir"},
      {"plot ''", "dir"},
      {"movie ''", "dir"},
      {"movie " + folder + " --out ''", "--out"},
      {"view ''", "dir"},
      {"view " + folder + " --out ''", "--out"},
  };
  for (const auto& c : cases) {
    EXPECT_EQ(gem::test::runGem(c.arguments, log), 2) << c.arguments;
    const std::string text = gem::test::readFile(log);
    EXPECT_EQ(text.rfind(c.option + ": an empty path", 0), 0u) << c.arguments << ": " << text;
    EXPECT_LT(text.size(), 200u) << c.arguments << ": " << text;
  }
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "default_run")) << "gem run --out '' ran into output.dir";
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "runs")) << "gem sweep --out '' ran into runs/NAME";
  // A name that stands for a scenario key, given empty, was ignored the same way.
  EXPECT_EQ(gem::test::runGem("check " + good.string() + " --backend ''", log), 2);
  EXPECT_EQ(gem::test::readFile(log).rfind("--backend: an empty value", 0), 0u) << gem::test::readFile(log);
}
