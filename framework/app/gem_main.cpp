// The gem command (docs/scenario.md "Command line"): run, check, info, bench, sweep, analyze, plot,
// movie.
// Exit status: 0 success; 2 bad input (with file, line and column or key); 1 any other failure.
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "framework/analysis/analyze.hpp"
#include "framework/analysis/movie.hpp"
#include "framework/analysis/run_plots.hpp"
#include "framework/analysis/view_page.hpp"
#include "bench/bench.hpp"
#include "framework/app/calibration.hpp"
#include "framework/api/errors.hpp"
#include "framework/app/interrupt.hpp"
#include "framework/app/plugin_loader.hpp"
#include "framework/api/registry.hpp"
#include "framework/app/run_log.hpp"
#include "framework/app/runner.hpp"
#include "framework/output/checkpoint.hpp"
#include "framework/output/output_path.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/app/mpi_work.hpp"
#include "framework/step/stepper.hpp"
#include "framework/app/sweep.hpp"
#include "framework/scenario/sweep_file.hpp"

namespace fs = std::filesystem;
using namespace gem;

namespace {

// A filesystem fault that only a path the user gave can cause (a loop of symbolic links, a file
// where a folder must be, a name too long): bad input, exit 2, naming the path; not an internal
// failure. Any other filesystem error (a full disk, a device error) stays a fault, exit 1.
std::optional<std::string> pathFaultOf(const std::filesystem::filesystem_error& e) {
  const std::error_code c = e.code();
  const char* what = c == std::errc::too_many_symbolic_link_levels ? "a loop of symbolic links"
                     : c == std::errc::not_a_directory             ? "a part of the path is a file, not a folder"
                     : c == std::errc::filename_too_long           ? "the path is too long"
                                                                   : nullptr;
  if (!what) return std::nullopt;
  const std::string path = e.path1().empty() ? std::string("a path") : e.path1().string();
  return path + ": " + what;
}

struct RunArguments {
  std::string scenario, out, backend, broadphase;
  int threads = -1;  // --threads: simulation.threads (-1: the scenario's)
  // --duration and --steps as typed: read here, so that an empty, partial or out-of-range value is
  // refused with the text the user gave (CLI11 would read '' as 0 and saturate a huge count).
  std::string durationText, stepsText;
  bool durationGiven = false, stepsGiven = false;  // set from the command line's counts
  std::vector<std::string> set;
  bool quiet = false;
  std::string commandLine;  // for gem.log
  bool noPlots = false;     // gem run --no-plots
  std::string resume;       // gem run --resume RUN_DIR
};

// The number a command-line value spells, the whole text and nothing else (no blank, no unit, no
// trailing characters); nullopt when it is empty, not a number or out of the type's range.
template <class T>
std::optional<T> wholeText(const std::string& text) {
  T value{};
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc() || stop != end) return std::nullopt;
  return value;
}

// A command-line value as a message repeats it: quoted when empty or spaced, cut when long.
std::string quotedArgument(const std::string& text) {
  const std::string shown = text.size() > 40 ? text.substr(0, 40) + "..." : text;
  return shown.empty() || shown.find_first_of(" \t") != std::string::npos ? "'" + shown + "'" : shown;
}

Scenario load(const RunArguments& a) {
  std::vector<std::string> overrides = a.set;
  if (!a.backend.empty()) overrides.push_back("simulation.backend=\"" + a.backend + "\"");
  if (!a.broadphase.empty()) overrides.push_back("simulation.broadphase=\"" + a.broadphase + "\"");
  if (a.threads >= 0) overrides.push_back("simulation.threads=" + std::to_string(a.threads));
  Scenario s = loadScenario(a.scenario, overrides);
  // --duration and --steps, when given, must make a run of 1 to 2e9 steps: never silently ignored.
  if (a.durationGiven) {
    const std::optional<double> duration = wholeText<double>(a.durationText);
    if (!duration || !(*duration > 0) || !std::isfinite(*duration))
      throw InputError(fmt::format("--duration {}: expected a positive number of seconds", quotedArgument(a.durationText)));
    const double count = *duration / static_cast<double>(s.dt);
    if (!(count >= 0.5 && count <= 2e9))
      throw InputError(
          fmt::format("--duration {}: {:.3g} steps of dt = {} s; a run takes 1 to 2e9 steps", quotedArgument(a.durationText), count, s.dt));
    s.duration = static_cast<Real>(*duration);
    s.steps = std::lround(count);
  }
  if (a.stepsGiven) {
    const std::optional<long long> steps = wholeText<long long>(a.stepsText);
    if (!steps || !(*steps >= 1 && *steps <= 2000000000))
      throw InputError(fmt::format("--steps {}: expected a whole number from 1 to 2e9", quotedArgument(a.stepsText)));
    s.steps = static_cast<long>(*steps);
    s.duration = static_cast<Real>(*steps) * s.dt;
  }
  if (!a.out.empty()) {
    s.output.dir = fs::absolute(a.out);
    // Checked here, so that its message names the option (the run folder's lock once said only
    // "cannot open the run folder's lock" for `--out /proc`), but without making the folder: a run
    // refused for its input leaves nothing behind.
    requireOutputFolderIfThere(s.output.dir, "gem run --out");
  }
  return s;
}

// The closing report of a run (also kept in its gem.log).
void reportRun(RunLog& log, const RunSummary& r) {
  log.say(fmt::format("  floes          {} at start, {} at end ({} broken, {:.4g} kg rubble)", r.floesInitial, r.floesFinal, r.floesBroken,
                      r.rubbleMass));
  // The record streams' totals, under the names their events give them (ship_impact: impacts).
  for (const RecordTotals& t : r.records) {
    if (t.countKey.empty()) continue;
    std::string line = fmt::format("  {:<14} {}", t.countKey, t.count);
    if (!t.statisticKey.empty() && t.statistic.count)
      line += fmt::format(", {} mean {:.4g}, max {:.4g}", t.statisticKey, t.statistic.mean, t.statistic.max);
    if (!t.countInIceKey.empty()) {
      line += fmt::format("; in ice {}", t.countInIce);
      if (t.statisticInIce.count) line += fmt::format(", mean {:.4g}", t.statisticInIce.mean);
    }
    log.say(line);
  }
  // In ice first: the studies' figures (the steps with the whole hull inside the domain's x
  // range); the whole run's, diluted by the open water before and after, second.
  if (r.shipSpeedInIce.count)
    log.say(fmt::format("  in ice         speed mean {:.3f} m/s (min {:.3f}, max {:.3f}); resistance {:.1f} kN; {} steps ({:.1f} s)",
                        r.shipSpeedInIce.mean, r.shipSpeedInIce.min, r.shipSpeedInIce.max, r.netThrustInIce.mean / 1e3,
                        r.shipSpeedInIce.count,
                        static_cast<double>(r.shipSpeedInIce.count) * r.simTime / std::max<double>(static_cast<double>(r.steps), 1)));
  else if (r.shipSpeed.count)
    log.say("  in ice         no step with the whole hull inside the domain's x range (no in-ice statistics)");
  if (r.shipSpeed.count)
    log.say(fmt::format("  whole run      speed mean {:.3f} m/s (min {:.3f}, max {:.3f}); mean net thrust {:.1f} kN", r.shipSpeed.mean,
                        r.shipSpeed.min, r.shipSpeed.max, r.netThrust.mean / 1e3));
  if (r.stopReason != "duration") log.say(fmt::format("  stopped        after {} steps: {}", r.steps, r.stopReason));
  log.say(fmt::format("  wall time      {:.3f} s for {:.1f} s simulated: {:.0f}x real time ({:.0f} steps/s)", r.wallTime, r.simTime,
                      r.simTime / std::max(r.wallTime, 1e-9), r.steps / std::max(r.wallTime, 1e-9)));
  // The files the run folder holds now (the frames only when the run wrote them, a plugin's own
  // files too), and gem.log, written just after this report.
  std::vector<std::string> files;
  std::error_code ec;
  for (const fs::directory_entry& e : fs::directory_iterator(r.outputDir, ec)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file(ec) && name[0] != '.' && name.find(".tmp-") == std::string::npos && name != "gem.log") files.push_back(name);
  }
  std::sort(files.begin(), files.end());
  files.push_back("gem.log");
  log.say(fmt::format("  outputs        {}/ ({})", r.outputDir, fmt::join(files, ", ")));
}

// gem plot, and the end of gem run: the run folder's plots, each file named as written.
int commandPlot(const fs::path& dir, bool quiet) {
  const RunPlots plots = writeRunPlots(dir);
  if (quiet) return 0;
  std::printf("gem plot %s: %zu files in %s\n", dir.c_str(), plots.files.size(), (dir / "plots").c_str());
  for (const fs::path& f : plots.files) std::printf("  %s\n", f.filename().c_str());
  for (const std::string& note : plots.notes) std::printf("  note: %s\n", note.c_str());
  return 0;
}

// gem run --resume RUN_DIR: the run folder's own scenario.toml, to go on from its checkpoint.
Scenario loadForResume(const RunArguments& a) {
  const fs::path dir = fs::absolute(a.resume).lexically_normal();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) throw InputError(fmt::format("--resume {}: not a folder", a.resume));
  if (!fs::is_regular_file(dir / "scenario.toml", ec))
    throw InputError(fmt::format("--resume {}: no scenario.toml there, so not the folder of a gem run", a.resume));
  // Threads change no result (docs/scenario.md): the one setting a resumed run may change.
  std::vector<std::string> overrides;
  if (a.threads >= 0) overrides.push_back("simulation.threads=" + std::to_string(a.threads));
  Scenario s = loadScenario((dir / "scenario.toml").string(), overrides);
  s.output.dir = dir;  // where the run is now, should the folder have moved
  return s;
}

int commandRun(const RunArguments& a) {
  const bool resume = !a.resume.empty();
  if (!resume && a.scenario.empty()) throw InputError("gem run: a scenario file is required (or --resume RUN_DIR)");
  if (resume && !a.scenario.empty())
    throw InputError(
        fmt::format("gem run --resume {}: takes no scenario file ({}): the run folder's scenario.toml is the run's", a.resume, a.scenario));
  const Scenario s = resume ? loadForResume(a) : load(a);
  RunOptions options;
  options.quiet = a.quiet;
  options.progress = isatty(fileno(stderr));
  RunLog log(a.commandLine, a.quiet);
  if (resume) log.continueFrom(s.output.dir);
  // The run announces itself once its input is all checked (runSteps calls this before its first step).
  options.started = [&](Stepper& sim) {
    if (resume)
      log.say(fmt::format("gem run --resume {}: from its checkpoint to step {}", a.resume, s.steps));
    else
      log.say(fmt::format("gem run {}: {} steps of {:.3g} s, backend {}, broadphase {}", a.scenario, s.steps, static_cast<double>(s.dt),
                          sim.backend(), s.broadphase));
    for (const LoadedPlugin& plugin : loadedPlugins())
      log.note(fmt::format("  plugin         {}{}", plugin.origin, plugin.fromEnvironment ? ", from GEM_PLUGIN_PATH" : ""));
  };
  try {
    const RunSummary r = resume ? resumeScenario(s, options) : runScenario(s, options);
    log.note(fmt::format("  device         {} ({} driver)", r.device, r.driver));
    reportRun(log, r);
    if (!a.noPlots) commandPlot(r.outputDir, a.quiet);
    log.write(s.output.dir, 0);
    return 0;
  } catch (const InputError& e) {
    log.note(fmt::format("gem: error: {}", e.what()));
    log.write(s.output.dir, 2);
    throw;
  } catch (const Interrupted& e) {
    log.note(fmt::format("gem: {}", e.what()));
    if (fs::exists(s.output.dir / kCheckpointFile)) {
      const std::string hint = fmt::format("gem: a checkpoint is kept: `gem run --resume {}` goes on from here", s.output.dir.string());
      std::fprintf(stderr, "%s\n", hint.c_str());
      log.note(hint);
    }
    log.write(s.output.dir, 128 + e.signal());
    throw;
  } catch (const std::filesystem::filesystem_error& e) {
    const std::optional<std::string> fault = pathFaultOf(e);
    log.note(fault ? fmt::format("gem: error: {}", *fault) : fmt::format("gem: failed: {}", e.what()));
    log.write(s.output.dir, fault ? 2 : 1);
    throw;
  } catch (const std::exception& e) {
    log.note(fmt::format("gem: failed: {}", e.what()));
    log.write(s.output.dir, 1);
    throw;
  }
}

// gem check SWEEP.toml: the sweep file, then every case as gem sweep loads it and as gem check
// checks a scenario. It takes the options gem sweep takes (--set, --backend), no others.
int commandCheckSweep(const RunArguments& a) {
  for (const auto& [given, option] : {std::pair{!a.broadphase.empty(), "--broadphase"}, std::pair{a.threads >= 0, "--threads"},
                                      std::pair{a.durationGiven, "--duration"}, std::pair{a.stepsGiven, "--steps"}})
    if (given)
      throw InputError(
          fmt::format("gem check {}: a sweep file takes --set and --backend, as gem sweep does, not {} (use --set)", a.scenario, option));
  SweepOptions options;
  options.sweepFile = a.scenario;
  options.set = a.set;
  options.backend = a.backend;
  options.quiet = a.quiet;
  return checkSweep(options);
}

int commandCheck(const RunArguments& a) {
  if (isSweepFile(a.scenario)) return commandCheckSweep(a);
  const Scenario s = load(a);
  const ScenarioCheck c = checkScenarioFirstStep(s);
  if (!a.quiet)
    std::printf("%s: ok (%d bodies: %d floes%s; %ld steps; broadphase %s; %zu events on)\n", a.scenario.c_str(), c.bodies, c.floes,
                s.vessel.present ? ", a vessel" : "", s.steps, s.broadphase.c_str(), c.events);
  return 0;
}

// An entry's origin: "built-in", or for a plugin's "PATH (NAME VERSION)" on a line of its own.
std::string originColumn(const std::string& origin) { return origin == "built-in" ? origin : "plugin"; }
void printPluginOrigin(const std::string& origin, size_t nameWidth) {
  if (origin != "built-in") std::printf("%s\n", fmt::format("  {:<{}} from {}", "", nameWidth, origin).c_str());
}

int commandInfo(const std::vector<std::string>& plugins) {
  loadEnvironmentPlugins();
  for (const std::string& p : plugins) loadPlugin(p);
  std::printf("GEM %s (GPU Event Mechanics)\n", GEM_VERSION);
  const BackendEntry* cuda = findBackend("cuda");
  std::printf("build: real type %s, backends: %s%s\n", sizeof(Real) == 8 ? "double" : "float",
              fmt::format("{}", fmt::join(backendNames(), ", ")).c_str(),
              cuda ? ", CUDA architectures " GEM_CUDA_ARCHITECTURES : " (no CUDA backend in this build)");
  std::printf("plugin ABI: version %d, compiler %s %s\n", GEM_PLUGIN_ABI_VERSION, GEM_COMPILER_ID, GEM_COMPILER_VERSION);
  std::printf("sweeps across MPI ranks: %s\n", mpiBuilt() ? "yes" : "no (built without MPI)");
  std::printf("devices: cpu");
  if (cuda) std::printf(", %s", cuda->available() ? cuda->deviceName().c_str() : "no CUDA device found");
  // The name column fits the longest name of the three lists (a plugin's may be long), 18 at least,
  // so that every list's columns line up.
  const std::vector<LoadedPlugin> loaded = loadedPlugins();
  size_t width = 18;
  for (const EventEntry* e : Registry::global().events()) width = std::max(width, e->name.size());
  for (const BroadphaseEntry* b : Registry::global().broadphases()) width = std::max(width, b->name.size());
  for (const LoadedPlugin& p : loaded) width = std::max(width, p.name.size());
  // In the order the drivers run them: by phase, then each event's declared order (docs/plugins.md "Order").
  std::printf("\n\nevents, in the order they run (phase, order, default, origin):\n");
  for (const EventEntry* e : Registry::global().events()) {
    std::printf("%s\n", fmt::format("  {:<{}} {:<9} {:<5} {:<4} {:<9} {}", e->name, width, eventPhaseName(e->phase), e->order,
                                    e->enabledByDefault ? "on" : "off", originColumn(e->origin), e->description)
                            .c_str());
    printPluginOrigin(e->origin, width);
  }
  std::printf("\nbroadphases (origin):\n");
  for (const BroadphaseEntry* b : Registry::global().broadphases()) {
    std::printf("%s\n", fmt::format("  {:<{}} {:<9} {}", b->name, width, originColumn(b->origin), b->description).c_str());
    printPluginOrigin(b->origin, width);
  }
  std::printf("\nplugins loaded: %s\n", loaded.empty() ? "none (GEM_PLUGIN_PATH, [[plugins]] or gem info --plugin PATH)" : "");
  for (const LoadedPlugin& p : loaded)
    std::printf("%s\n", fmt::format("  {:<{}} {:<9} {}", p.name, width, p.version, p.path.string()).c_str());
  return 0;
}

// Every option and argument that names a file or folder refuses an empty value: `--out ''` once
// meant the default run folder, silently.
const CLI::Validator kPath(
    [](const std::string& value) { return value.empty() ? std::string("an empty path: name a file or folder") : std::string(); }, "PATH");
// The same for a name that stands for a scenario key (--backend ''): empty, it was ignored.
const CLI::Validator kName(
    [](const std::string& value) {
      return value.empty() ? std::string("an empty value: give a name, or leave the option out") : std::string();
    },
    "NAME");

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"GEM: GPU Event Mechanics, ships in 2D pack ice"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("gem ") + GEM_VERSION + " (real type " + GEM_REAL_NAME + ", plugin ABI " +
                                        std::to_string(GEM_PLUGIN_ABI_VERSION) + ")");
  RunArguments args;
  args.commandLine = commandLineText(argc, argv);
  auto addRunOptions = [&](CLI::App* c, bool scenarioRequired) {
    auto* scenario = c->add_option("scenario", args.scenario, "scenario file (TOML)")->check(kPath);
    if (scenarioRequired) scenario->required();
    c->add_option("--backend", args.backend, "auto, cpu or cuda")->check(kName);
    c->add_option("--broadphase", args.broadphase, "broadphase strategy by name (see gem info)")->check(kName);
    c->add_option("--threads", args.threads, "CPU backend: threads stepping the field (simulation.threads; 0 = every core)")
        ->check(CLI::Range(0, 1024));
    auto* duration =
        c->add_option("--duration", args.durationText, "simulated time, s")->each([&](const std::string&) { args.durationGiven = true; });
    c->add_option("--steps", args.stepsText, "number of steps")->excludes(duration)->each([&](const std::string&) {
      args.stepsGiven = true;
    });
    c->add_option("--set", args.set, "override a scenario key: --set simulation.dt=0.05")->take_all();
  };
  CLI::App* run = app.add_subcommand("run", "run a scenario and write its outputs");
  addRunOptions(run, false);  // gem run --resume RUN_DIR takes none
  run->add_option("--out", args.out, "run folder (default: output.dir of the scenario, else runs/NAME)")->check(kPath);
  run->add_flag("--quiet", args.quiet, "no progress line and no summary");
  run->add_flag("--no-plots", args.noPlots, "do not write RUN/plots/ at the end (gem plot RUN writes them later)");
  // What a resumed run could change would make it another run: only --threads, --quiet and
  // --no-plots go with --resume.
  auto* resumeOption = run->add_option("--resume", args.resume,
                                       "go on with the stopped run in this folder from its checkpoint (output.checkpoint_every, or the one "
                                       "Ctrl-C and SIGTERM write), to the very files the whole run writes")
                           ->check(kPath);
  for (const char* other : {"--backend", "--broadphase", "--duration", "--steps", "--set", "--out"})
    resumeOption->excludes(run->get_option(other));
  CLI::App* check =
      app.add_subcommand("check", "load and validate a scenario, or every case of a sweep file, and its first step, without running it");
  addRunOptions(check, true);
  check->get_option("scenario")->description("scenario file, or sweep file (a [sweep] table; with --set and --backend only)");
  check->add_flag("--quiet", args.quiet, "print nothing when the scenario or sweep is valid");
  std::vector<std::string> infoPlugins;
  CLI::App* info = app.add_subcommand("info", "version, build, devices, registered events and broadphases");
  info->add_option("--plugin", infoPlugins, "load this plugin first (repeatable); GEM_PLUGIN_PATH's are loaded too")->check(kPath);
  BenchOptions bench;
  CLI::App* benchCommand =
      app.add_subcommand("bench", "the thesis's Chapter 5 timings as tables, printed and as CSV, each row with its device (--table)");
  benchCommand->add_option("--table", bench.table,
                           "step: time per step of --cases on --backend (default);\n"
                           "fields: 456 and 824 floes, cpu and cuda, every built-in broadphase;\n"
                           "blocks: cuda_block_size 32..1024 on 3584 and 7168 floes (cuda);\n"
                           "copyback: copy_back_every 1..128 on 824 and 10^5 floes (cuda);\n"
                           "scaling: 10^4, 10^5, 10^6 floes, every broadphase on cuda, variable_radius on the cpu;\n"
                           "intersection, triangulation: the geometry tables (thesis 5.2, 5.3);\n"
                           "resident: 456 and 824 floes on each CUDA driver and the CPU, then ensembles of 10, 100, 1000, "
                           "10000 456-floe worlds on the resident driver (cuda; --sizes: world counts);\n"
                           "cpu: 456, 824, 10^4, 10^5 floes on 1, 2, 4, 8 and every core's threads;\n"
                           "all: fields, blocks, copyback, scaling, intersection, triangulation (without a CUDA device "
                           "the CUDA rows are skipped, saying so; each table its own cases and broadphases)");
  benchCommand
      ->add_option("--csv", bench.csv,
                   "also write CSV: a FILE for one table; for --table all (or a PATH that is a directory or ends "
                   "in /) a directory, created, with one TABLE.csv per table (fields.csv, blocks.csv, ...)")
      ->check(kPath);
  benchCommand->add_option("--steps", bench.steps, "steps timed per case (default 2000; fewer for large fields)");
  benchCommand->add_option("--cases", bench.cases,
                           "456, 824 (thesis fields) or floe counts N (random, 40 %); default: the table's own "
                           "(step: 456 824 10000)");
  benchCommand->add_option("--backend", bench.backends, "backends to time: cpu, cuda (default: the table's own; step: cpu)");
  benchCommand->add_option("--broadphase", bench.broadphases, "broadphases to time (default: the table's own; step: variable_radius)");
  benchCommand->add_option("--blocks", bench.blockSizes, "blocks: block sizes (default 32 64 128 256 512 1024)");
  benchCommand->add_option("--threads", bench.threads, "threads of the CPU rows (simulation.threads; default 1, one core)");
  benchCommand->add_option("--copy-back", bench.copyBackEvery, "copyback: intervals k (default 1 2 4 8 16 32 64 128)");
  benchCommand->add_option("--sizes", bench.sizes,
                           "intersection/triangulation: N per row (default the thesis's sizes); resident: world counts");
  benchCommand->add_option("--reps", bench.reps, "intersection/triangulation: timed repetitions, median (default 50)");

  std::string calibrationFile = std::string(GEM_SOURCE_DIR) + "/scenarios/thesis/calibration.toml", calibrationOut = "runs/calibration";
  CLI::App* calibrateCommand = app.add_subcommand("calibrate", "the 32 calibration impacts of thesis 6.2.2.1: logged vs direct force");
  calibrateCommand->add_option("scenario", calibrationFile, "base scenario (default scenarios/thesis/calibration.toml)")->check(kPath);
  calibrateCommand->add_option("--out", calibrationOut, "folder for calibration.csv")->check(kPath);

  AnalyzeOptions analyze;
  CLI::App* analyzeCommand = app.add_subcommand("analyze", "impact-load statistics and plots of a run or sweep folder");
  analyzeCommand->add_option("dir", analyze.dir, "run folder or sweep folder")->required()->check(kPath);
  // A label holds commas ("concentration=0.4,count=668"): groups are separated by ';' or given by
  // repeating --groups.
  analyzeCommand
      ->add_option("--groups", analyze.groups,
                   "groups to analyse, each by its label (concentration=0.4) or a case's name (121_46); several: repeat "
                   "--groups or separate with ';'")
      ->check(kName);  // `--groups ''` once meant every group; split on ';' below
  analyzeCommand->add_flag("--quiet", analyze.quiet, "print nothing but errors");

  std::string plotDir;
  bool plotQuiet = false;
  CLI::App* plotCommand = app.add_subcommand("plot", "PNG and SVG plots of a run folder: time series and impact loads, in RUN/plots/");
  plotCommand->add_option("dir", plotDir, "run folder")->required()->check(kPath);
  plotCommand->add_flag("--quiet", plotQuiet, "print nothing but errors");

  MovieOptions movie;
  std::string movieOut;
  CLI::App* movieCommand = app.add_subcommand("movie", "an MP4 of a run's frames (frames.ice) through ffmpeg, or one frame as a PNG");
  movieCommand->add_option("dir", movie.runDir, "run folder")->required()->check(kPath);
  movieCommand->add_option("--out", movieOut, "movie file (default RUN/movie.mp4); with --still, the PNG")->check(kPath);
  movieCommand->add_option("--fps", movie.fps, "frames per second (default 10: one movie frame per saved frame)");
  movieCommand->add_option("--color", movie.color, "what colours the floes: speed (default), thickness or id");
  movieCommand->add_option("--size", movie.size, "WxH in pixels, each even (default 1280x720)");
  movieCommand->add_option("--still", movie.still, "write frame K (0-based) as a PNG to --out instead of the movie");
  ViewOptions view;
  CLI::App* viewCommand = app.add_subcommand("view", "one self-contained HTML page that plays a run's frames in a browser");
  viewCommand->add_option("dir", view.dir, "run folder (with frames.ice)")->required()->check(kPath);
  viewCommand->add_option("--out", view.out, "the page (default DIR/view.html)")->check(kPath);
  viewCommand->add_option("--every", view.every, "keep every N-th frame and the last (default: all, thinned above 300 MB)")
      ->check(CLI::Range(1, 1000000000));
  viewCommand->add_flag("--quiet", view.quiet, "print nothing but errors");

  SweepOptions sweep;
  CLI::App* sweepCommand = app.add_subcommand("sweep", "run a parameter study and gather one summary.csv");
  sweepCommand->add_option("sweep", sweep.sweepFile, "sweep file (TOML)")->required()->check(kPath);
  sweepCommand->add_option("--out", sweep.outDir, "sweep folder (default runs/NAME)")->check(kPath);
  // Bounded ranges: CLI11's PositiveNumber and NonNegativeNumber print the largest double in their message.
  sweepCommand->add_option("--jobs", sweep.jobs, "cases run at once (default 0: all cores)")->check(CLI::Range(0, 65536));
  sweepCommand->add_option("--case-index", sweep.caseIndex, "run only case I (0-based), e.g. in a job array")
      ->check(CLI::Range(0L, 100000L));
  sweepCommand
      ->add_option("--batch", sweep.batch,
                   "on a GPU, the most cases run together in one device state (default 0: automatic; 1: one case at a time)")
      ->check(CLI::Range(0, 1024));  // a device state holds at most 1024 cases (sweep.cpp, kMostTogether)
  sweepCommand->add_flag("--quiet", sweep.quiet, "no progress");
  sweepCommand->add_option("--set", sweep.set, "override a scenario key in every case: --set simulation.dt=0.05")->take_all();
  sweepCommand->add_option("--backend", sweep.backend, "auto, cpu or cuda, for every case")->check(kName);

  // A first word that names no command: say so, with the commands (CLI11 said only "A subcommand
  // is required").
  if (argc > 1 && argv[1][0] != '-') {
    std::vector<std::string> names;
    bool known = false;
    for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
      names.push_back(command->get_name());
      known = known || command->get_name() == argv[1];
    }
    if (!known) {
      std::fprintf(stderr, "gem: error: unknown command \"%s\" (the commands: %s; gem --help says what each does)\n",
                   InputError::shorten(argv[1]).c_str(), fmt::format("{}", fmt::join(names, ", ")).c_str());
      return 2;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    // GEM_PLUGIN_PATH's plugins, for every command: a scenario, gem bench --broadphase or gem info
    // may name what they add.
    loadEnvironmentPlugins();
    // Ctrl-C and SIGTERM stop a run between two steps, its files kept whole, and a sweep or a
    // calibration between cases; the commands that never look at the flag (check, bench, the
    // readers) keep the signals' default and stop at once.
    if (*run || *sweepCommand || *calibrateCommand) catchInterrupts();
    if (*run) return commandRun(args);
    if (*check) return commandCheck(args);
    // Output places named on the command line, checked before any work (framework/output/output_path.hpp).
    if (*sweepCommand && !sweep.outDir.empty()) requireOutputFolder(sweep.outDir, "gem sweep --out");
    if (*calibrateCommand) requireOutputFolder(calibrationOut, "gem calibrate --out");
    if (*movieCommand && !movieOut.empty()) requireOutputFile(movieOut, "gem movie --out");
    if (*viewCommand && !view.out.empty()) requireOutputFile(view.out, "gem view --out");
    if (*benchCommand) return runBench(bench);
    if (*sweepCommand) return runSweep(sweep);
    if (*analyzeCommand) {
      // Split here, not by CLI11, which dropped the empty names of 'a;;b' and took 'a;;b' for a;b.
      std::vector<std::string> groups;
      for (const std::string& given : analyze.groups)
        for (size_t at = 0;;) {
          const size_t end = std::min(given.find(';', at), given.size());
          if (end == at)
            throw InputError(
                fmt::format("--groups {}: an empty group name; name each group, separated by ';'", InputError::shorten(given)));
          groups.push_back(given.substr(at, end - at));
          if (end == given.size()) break;
          at = end + 1;
        }
      analyze.groups = groups;
      return runAnalyze(analyze);
    }
    if (*plotCommand) return commandPlot(plotDir, plotQuiet);
    if (*movieCommand) {
      movie.out = movieOut;
      const MovieResult m = writeMovie(movie);
      std::printf("gem movie %s: %s (%zu frame%s, %d x %d)\n", movie.runDir.c_str(), m.file.c_str(), m.frames, m.frames == 1 ? "" : "s",
                  m.width, m.height);
      return 0;
    }
    if (*viewCommand) return runView(view);
    if (*calibrateCommand) return runCalibration(calibrationFile, calibrationOut, false) <= 0.02 ? 0 : 1;
    return commandInfo(infoPlugins);
  } catch (const InputError& e) {
    std::fprintf(stderr, "gem: error: %s\n", e.what());
    return 2;
  } catch (const std::filesystem::filesystem_error& e) {
    if (const std::optional<std::string> fault = pathFaultOf(e)) {
      std::fprintf(stderr, "gem: error: %s\n", fault->c_str());
      return 2;
    }
    std::fprintf(stderr, "gem: failed: %s\n", e.what());
    return 1;
  } catch (const Interrupted& e) {
    if (!args.quiet) std::fprintf(stderr, "\n");  // past the progress line
    std::fprintf(stderr, "gem: %s\n", e.what());
    return 128 + e.signal();
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "gem: failed: out of memory (a field, a sweep or a file larger than this machine holds)\n");
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gem: failed: %s\n", e.what());
    return 1;
  }
}
