#include "framework/app/sweep.hpp"

#include "framework/app/mpi_work.hpp"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include <fmt/format.h>
#include <toml++/toml.h>

#include "framework/output/atomic_file.hpp"
#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/app/interrupt.hpp"
#include "framework/app/runner.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"
#include "framework/scenario/sweep_file.hpp"
#include "framework/analysis/sweep_summary.hpp"

namespace fs = std::filesystem;

namespace gem {

namespace {

std::vector<std::string> overrideStrings(const SweepCase& c) {
  std::vector<std::string> out;
  for (const SweepOverride& o : c.overrides) out.push_back(o.key + "=" + o.toml);
  return out;
}

// A case's scenario, writing into dir; its document made to stand on its own in dir: output.dir
// = "." (the folder of its scenario.toml) and a field file given by its absolute path.
Scenario loadCase(const SweepCase& c, const fs::path& dir) {
  Scenario s = loadScenario(c.base, overrideStrings(c));
  s.output.dir = dir;
  if (!s.root.contains("output")) s.root.insert("output", toml::table{});
  s.root.get("output")->as_table()->insert_or_assign("dir", ".");
  if (s.fieldKind == "file") {
    s.fieldFile = s.fieldFile.lexically_normal();
    s.root.get("field")->as_table()->insert_or_assign("file", s.fieldFile.string());
  }
  return s;
}

// How messages name a case: its index in case order and its name.
std::string caseLabel(const SweepDefinition& sweep, const SweepCase& c) {
  return fmt::format("case {} \"{}\"", &c - sweep.cases.data(), c.name);
}

// An override as a message names it: "KEY = VALUE" for one the sweep file gives (its line is the
// message's), "--set KEY=VALUE" for one given to gem sweep itself (no line); then what the
// scenario's loader said about it, without the "--set KEY=VALUE: " and the "KEY: " that the loader
// puts first for a value that has no line of its own.
std::string overrideMessage(const SweepOverride& o, std::string message) {
  const std::string assignment = "--set " + o.key + "=" + o.toml;
  if (message.rfind(assignment + ": ", 0) == 0) message.erase(0, assignment.size() + 2);
  if (message.rfind(o.key + ": ", 0) == 0) message.erase(0, o.key.size() + 2);
  return fmt::format("{}: {}", o.line > 0 ? o.key + " = " + o.toml : assignment, message);
}

// Loads a case as loadCase does; when its scenario is rejected, blames the sweep file's line for
// the override at fault (found by trying each alone), or the base scenario's own line.
Scenario validateCase(const SweepDefinition& sweep, const SweepCase& c, const fs::path& dir) {
  const std::string where = caseLabel(sweep, c);
  try {
    Scenario s = loadCase(c, dir);
    if (s.fieldKind == "file" && !fs::is_regular_file(s.fieldFile)) {
      int line = c.line, column = c.column;
      for (const SweepOverride& o : c.overrides)
        if (o.key == "field.file") line = o.line, column = o.column;
      throw InputError(sweep.fileName, line, column, fmt::format("{}: no such field file: {}", where, s.fieldFile.string()));
    }
    return s;
  } catch (const InputError& error) {
    if (std::string(error.what()).rfind(sweep.fileName, 0) == 0) throw;  // already ours
    loadScenario(c.base);  // a base that fails alone throws its own error (its file, line and column)
    for (const SweepOverride& o : c.overrides) {
      try {
        loadScenario(c.base, {o.key + "=" + o.toml});
      } catch (const InputError& alone) {
        throw InputError(sweep.fileName, o.line, o.column, fmt::format("{}: {}", where, overrideMessage(o, alone.what())));
      }
    }
    throw InputError(sweep.fileName, c.line, c.column, fmt::format("{}: {}", where, error.what()));
  }
}

// Checks a case that validateCase loaded as gem check checks a scenario (checkScenarioFirstStep:
// its world built, its events parsed, one CPU step). An error names the sweep file and the case,
// at the line of an override without which the case passes (a vessel.position that puts the hull
// on a floe), the varied ones tried first, else at the case's entry. Not validateCase's "each
// override alone": an override that needs another (field.concentration with its field.groups)
// fails alone for another reason.
void checkCaseFirstStep(const SweepDefinition& sweep, const SweepCase& c, const Scenario& s) {
  try {
    checkScenarioFirstStep(s);
  } catch (const InputError& error) {
    const std::string where = caseLabel(sweep, c);
    std::vector<size_t> order;
    for (bool varied : {true, false})
      for (size_t k = 0; k < c.overrides.size(); ++k)
        if (c.overrides[k].varied == varied) order.push_back(k);
    for (size_t k : order) {
      std::vector<std::string> others;
      for (size_t j = 0; j < c.overrides.size(); ++j)
        if (j != k) others.push_back(c.overrides[j].key + "=" + c.overrides[j].toml);
      try {
        checkScenarioFirstStep(loadScenario(c.base, others));
      } catch (const InputError&) {
        continue;  // fails without it too (or does not load without it): not this one's fault alone
      }
      const SweepOverride& o = c.overrides[k];
      throw InputError(sweep.fileName, o.line, o.column, fmt::format("{}: {}", where, overrideMessage(o, error.what())));
    }
    throw InputError(sweep.fileName, c.line, c.column, fmt::format("{}: {}", where, error.what()));
  }
}

// Checks the cases `which` (indices into sweep.cases, in case order) with checkCaseFirstStep, on up
// to `jobs` threads, each case stepping on one thread, and throws the error of the first case in
// case order that fails. On a terminal (progress), a line on stderr once there are many cases or
// it takes a while, cleared before anything else is printed.
void checkCases(const SweepDefinition& sweep, const std::vector<Scenario>& scenarios, const std::vector<size_t>& which, size_t jobs,
                bool progress) {
  std::mutex mutex;
  std::condition_variable changed;
  std::atomic<size_t> next{0};
  size_t done = 0;
  size_t failedAt = which.size();  // the first position in `which` that failed
  std::exception_ptr failure;
  auto worker = [&] {
    for (size_t k = next++; k < which.size(); k = next++) {
      {
        std::lock_guard lock(mutex);
        if (k > failedAt) return;  // a case before it failed: that one is reported
      }
      Scenario s = scenarios[which[k]];
      if (jobs > 1) s.threads = 1;
      std::exception_ptr error;
      try {
        checkCaseFirstStep(sweep, sweep.cases[which[k]], s);
      } catch (...) {
        error = std::current_exception();
      }
      std::lock_guard lock(mutex);
      ++done;
      if (error && k < failedAt) failedAt = k, failure = error;
      changed.notify_all();
    }
  };
  std::vector<std::thread> threads;
  for (size_t t = 1; t < std::min(jobs, which.size()); ++t) threads.emplace_back(worker);
  if (!progress) {
    worker();
  } else {
    threads.emplace_back(worker);
    const auto start = std::chrono::steady_clock::now();
    bool shown = false;
    std::unique_lock lock(mutex);
    while (done < which.size() && !failure) {
      if (which.size() >= 10 || std::chrono::steady_clock::now() - start > std::chrono::seconds(1)) {
        std::fprintf(stderr, "\r  checking cases %zu/%zu   ", done, which.size());
        std::fflush(stderr);
        shown = true;
      }
      changed.wait_for(lock, std::chrono::milliseconds(200));
    }
    if (shown) std::fprintf(stderr, "\r%*s\r", 40, "");
  }
  for (std::thread& t : threads) t.join();
  if (failure) std::rethrow_exception(failure);
}

// gem sweep's --set and --backend: overrides of every case, last (so they win), as in gem run.
void addCommandLineOverrides(SweepDefinition& sweep, const SweepOptions& options) {
  std::vector<std::string> extra = options.set;
  if (!options.backend.empty()) extra.push_back("simulation.backend=\"" + options.backend + "\"");
  for (const std::string& assignment : extra) {
    const size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
      throw InputError(fmt::format("--set {}: expected KEY=VALUE, e.g. simulation.dt=0.05", assignment));
    for (SweepCase& c : sweep.cases)
      c.overrides.push_back(SweepOverride{assignment.substr(0, eq), assignment.substr(eq + 1), assignment.substr(eq + 1)});
  }
}

fs::path sweepFolder(const SweepDefinition& sweep, const SweepOptions& options) {
  return options.outDir.empty() ? sweep.file.parent_path() / "runs" / sweep.name : fs::absolute(options.outDir).lexically_normal();
}

// The first two lines are read back by gem analyze (framework/analysis/sweep_cases.cpp): the case's
// name and its base scenario, which its folder name and scenario.toml do not hold.
std::string scenarioText(const SweepDefinition& sweep, const SweepCase& c, const Scenario& s) {
  std::ostringstream out;
  out << "# Case \"" << c.name << "\" of the sweep " << sweep.file.string() << " (gem sweep)\n# base: " << c.base.string() << "\n";
  for (const SweepOverride& o : c.overrides) out << "# set " << o.key << " = " << o.toml << "\n";
  out << "\n" << toml::toml_formatter{s.root, toml::toml_formatter::default_flags & ~toml::format_flags::indentation} << "\n";
  return out.str();
}

// A case ran to its end: its summary.json exists, reads, and does not say "completed": false (a
// run a signal stopped). Anything else runs again.
bool caseCompleted(const fs::path& dir) {
  if (!fs::exists(dir / "summary.json")) return false;
  try {
    const auto summary = readSummaryJson(dir / "summary.json");
    const auto completed = summary.find("completed");
    return completed == summary.end() || completed->second != "false";
  } catch (const InputError&) {
    return false;
  }
}

// A file's text; "" for anything but a regular file (a pipe would block the open).
std::string readText(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return "";
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  return s >= 3600 ? fmt::format("{}h{:02}m", s / 3600, (s / 60) % 60) : fmt::format("{}m{:02}s", s / 60, s % 60);
}

// The sweep's work, in units a worker takes at once: a case alone, or cases that run together in
// one device state (a backend with makeTogether; cases with the same batchKey). batch: the most
// cases per device state (0: automatic, 1: none together). Automatic: up to kMostTogether, and
// each group split over the node's devices (under MPI, over the ranks) so that every one has work.
constexpr size_t kMostTogether = 1024;

std::vector<std::vector<size_t>> workUnits(const std::vector<Scenario>& scenarios, const std::vector<size_t>& todo, int batch, int ranks) {
  std::vector<std::vector<size_t>> units;
  std::map<std::pair<std::string, std::string>, std::vector<size_t>> groups;  // (backend, key) -> cases, in order
  std::vector<std::pair<std::string, std::string>> groupOrder;
  for (size_t i : todo) {
    const BackendEntry* backend = nullptr;
    std::string key;
    if (batch != 1) {
      try {
        const Scenario& s = scenarios[i];
        backend = findBackend(resolveBackend(s.backend));
        if (backend && backend->makeTogether && backend->batchKey) key = backend->batchKey(s);
      } catch (const InputError&) {
        key.clear();  // a backend that is not there: the case runs alone, and its run says why it cannot
      }
    }
    if (key.empty()) {
      units.push_back({i});
      continue;
    }
    const auto id = std::make_pair(backend->name, key);
    if (!groups.count(id)) groupOrder.push_back(id);
    groups[id].push_back(i);
  }
  for (const auto& id : groupOrder) {
    const std::vector<size_t>& cases = groups[id];
    const size_t most = batch > 1 ? static_cast<size_t>(batch) : kMostTogether;
    size_t parts = (cases.size() + most - 1) / most;
    if (batch <= 0) {
      const BackendEntry* backend = findBackend(id.first);
      const size_t spread =
          ranks > 0 ? static_cast<size_t>(ranks) : static_cast<size_t>(backend->deviceCount ? std::max(1, backend->deviceCount()) : 1);
      parts = std::max(parts, std::min(cases.size(), spread));
    }
    // Consecutive cases, the parts as equal as can be.
    for (size_t p = 0, at = 0; p < parts; ++p) {
      const size_t size = cases.size() / parts + (p < cases.size() % parts ? 1 : 0);
      units.emplace_back(cases.begin() + static_cast<std::ptrdiff_t>(at), cases.begin() + static_cast<std::ptrdiff_t>(at + size));
      at += size;
    }
  }
  return units;
}

// What the workers share: the queue of cases to run and the tally.
struct SweepState {
  std::mutex mutex;
  std::condition_variable changed;
  std::atomic<size_t> next{0};
  size_t finished = 0, running = 0;
  std::vector<std::pair<std::string, std::string>> failures;  // case name, message
  std::map<size_t, double> together;                          // unit -> cases' worth done, for units of cases run together
};

}  // namespace

int runSweep(const SweepOptions& options) {
  MpiWork mpi;  // under mpirun: this rank's share of the world; finalised when the sweep returns
  SweepDefinition sweep = readSweepFile(options.sweepFile);
  addCommandLineOverrides(sweep, options);
  const fs::path outDir = sweepFolder(sweep, options);
  const size_t count = sweep.cases.size();
  if (options.caseIndex < -1 || options.caseIndex >= static_cast<long>(count))
    throw InputError(fmt::format("--case-index {}: {} has {} cases (0 to {})", options.caseIndex, sweep.fileName, count, count - 1));

  // Every case is loaded before any runs: a typo in the sweep fails now, not hours in.
  std::vector<fs::path> dirs;
  std::vector<std::string> texts;
  std::vector<Scenario> scenarios;  // as each case will run
  for (const SweepCase& c : sweep.cases) {
    dirs.push_back(outDir / "cases" / c.folder);
    scenarios.push_back(validateCase(sweep, c, dirs.back()));
    texts.push_back(scenarioText(sweep, c, scenarios.back()));
  }

  std::vector<size_t> selected;
  if (options.caseIndex >= 0)
    selected.push_back(static_cast<size_t>(options.caseIndex));
  else
    for (size_t i = 0; i < count; ++i) selected.push_back(i);
  if (options.caseIndex >= 0) std::printf("%s\n", sweep.cases[selected[0]].name.c_str());

  // What a case's folder holds where the sweep reads and writes its summary.json and case.toml
  // must be a file, or nothing: a folder, a pipe or a device there is refused before any case
  // runs, naming it (a fifo was removed and the case run again; a folder failed the case, exit 1,
  // after it ran).
  for (size_t i : selected) {
    holdsFile(dirs[i] / "summary.json", "case's summary.json");
    holdsFile(dirs[i] / "case.toml", "case's case.toml");
  }

  // Resume: complete cases whose scenario has not changed are skipped.
  std::vector<size_t> todo;
  size_t skipped = 0, stale = 0;
  for (size_t i : selected) {
    if (caseCompleted(dirs[i])) {
      if (readText(dirs[i] / "case.toml") == texts[i]) {
        ++skipped;
        continue;
      }
      ++stale;
    }
    todo.push_back(i);
  }
  // Under MPI a rank runs one unit at a time unless --jobs says otherwise (one rank per core).
  const unsigned cores = mpi.active() ? 1u : std::max(1u, std::thread::hardware_concurrency());
  // Every case to run is checked as gem check checks a scenario (its world built, its events
  // parsed, one CPU step): a floe on the vessel or a typo in an event's key fails now, before any
  // case runs. For the thesis's sweeps it takes a third of a second (docs/scenario.md 5).
  checkCases(sweep, scenarios, todo, options.jobs > 0 ? static_cast<size_t>(options.jobs) : cores,
             !options.quiet && mpi.rank() == 0 && isatty(fileno(stderr)));
  // Every rank must see the same list before any of them starts changing case folders.
  mpi.sumOverRanks(0);
  const std::vector<std::vector<size_t>> units = workUnits(scenarios, todo, options.batch, mpi.active() ? mpi.size() : 0);
  size_t together = 0;
  for (const auto& unit : units)
    if (unit.size() > 1) together += unit.size();
  const size_t jobs = std::min<size_t>(options.jobs > 0 ? static_cast<size_t>(options.jobs) : cores, std::max<size_t>(units.size(), 1));
  fs::create_directories(outDir / "cases");
  const bool terminal = !options.quiet && isatty(fileno(stderr));
  if (!options.quiet && mpi.rank() == 0) {
    std::printf("gem sweep %s: %zu case%s", sweep.name.c_str(), count, count == 1 ? "" : "s");
    if (options.caseIndex >= 0) std::printf(", running case %ld only", options.caseIndex);
    if (mpi.active())
      std::printf("; %zu to run on %d MPI ranks x %zu thread%s", todo.size(), mpi.size(), jobs, jobs == 1 ? "" : "s");
    else
      std::printf("; %zu to run on %zu thread%s", todo.size(), jobs, jobs == 1 ? "" : "s");
    if (together)
      std::printf(" (%zu of them in %zu device run%s of several cases)", together, units.size() - (todo.size() - together),
                  units.size() - (todo.size() - together) == 1 ? "" : "s");
    if (skipped) std::printf(", %zu already complete", skipped);
    if (stale) std::printf(", %zu complete but changed since (run again)", stale);
    std::printf("\n  folder %s\n", outDir.string().c_str());
    std::fflush(stdout);
  }

  SweepState state;
  const auto start = std::chrono::steady_clock::now();
  // Under mpirun the ranks share one counter (units go to whichever rank is free); alone, the
  // threads of this process share theirs.
  // After Ctrl-C or SIGTERM no new case starts; the running ones stop at their next step.
  auto claim = [&]() -> size_t {
    if (interruptSignal()) return units.size();
    return mpi.active() ? mpi.next(units.size()) : state.next++;
  };
  // A case's folder, ready for its run: the old summary goes first (a scenario.toml beside a
  // summary of another scenario would pass for complete if this run failed before writing its own).
  auto prepareCase = [&](size_t i) {
    Scenario s = scenarios[i];  // loaded once, before any case ran
    // Cases that run side by side share the cores: each steps on one thread unless it says otherwise.
    if (s.threads == 0 && (jobs > 1 || mpi.active())) s.threads = 1;
    fs::create_directories(dirs[i]);
    fs::remove(dirs[i] / "summary.json");
    // The case as this sweep wrote it, for the next resume (the run records its own scenario.toml).
    writeFileAtomically(dirs[i] / "case.toml", texts[i]);
    return s;
  };
  auto finished = [&](size_t i, const std::string& failure, double seconds, size_t with) {
    std::lock_guard lock(state.mutex);
    --state.running;
    ++state.finished;
    const SweepCase& c = sweep.cases[i];
    if (!failure.empty()) state.failures.emplace_back(c.name, failure);
    if (!options.quiet && !terminal) {
      const std::string who = mpi.active() ? fmt::format("rank {} ", mpi.rank()) : std::string();
      const std::string how = with > 1 ? fmt::format(" (with {} cases in one device state)", with) : std::string();
      if (failure.empty())
        std::printf("  %s[%zu/%zu] %s  %.1f s%s\n", who.c_str(), state.finished, todo.size(), c.name.c_str(), seconds, how.c_str());
      else
        std::printf("  %s[%zu/%zu] %s  FAILED: %s\n", who.c_str(), state.finished, todo.size(), c.name.c_str(), failure.c_str());
      std::fflush(stdout);
    }
    state.changed.notify_all();
  };
  auto message = [](auto&& body) -> std::string {
    try {
      body();
      return "";
    } catch (const std::exception& e) {
      return e.what();
    } catch (...) {
      return "unknown error";
    }
  };
  // Worker w of this node (its rank's local index x threads + its thread) runs on device w modulo
  // the node's devices, for every backend that has devices: one GPU per rank, or per thread.
  auto worker = [&](size_t thread) {
    const int node = mpi.localRank() * static_cast<int>(jobs) + static_cast<int>(thread);
    for (const std::string& name : backendNames())
      if (const BackendEntry* b = findBackend(name); b && b->useDeviceForWorker) b->useDeviceForWorker(node);
    for (size_t k = claim(); k < units.size(); k = claim()) {
      const std::vector<size_t>& unit = units[k];
      {
        std::lock_guard lock(state.mutex);
        state.running += unit.size();
      }
      const auto unitStart = std::chrono::steady_clock::now();
      if (unit.size() == 1) {
        const std::string failure = message([&] {
          RunOptions runOptions;
          runOptions.quiet = true;
          runOptions.checkpoints = false;
          runScenario(prepareCase(unit[0]), runOptions);
        });
        finished(unit[0], failure, std::chrono::duration<double>(std::chrono::steady_clock::now() - unitStart).count(), 1);
        continue;
      }
      // Cases run together in one device state (workUnits grouped them by the backend's batchKey).
      std::vector<Scenario> scenarios;
      std::vector<const Scenario*> pointers;
      std::vector<std::string> failures(unit.size());
      std::string shared = message([&] {
        for (size_t i : unit) scenarios.push_back(prepareCase(i));
        for (const Scenario& s : scenarios) pointers.push_back(&s);
        const BackendEntry* backend = findBackend(resolveBackend(scenarios.front().backend));
        // Their progress, for the status line: the cases' worth done so far (every percent).
        long shown = -1;
        auto progress = [&](long step, long steps) {
          const long percent = 100 * step / std::max(steps, 1L);
          if (percent == shown) return;
          shown = percent;
          std::lock_guard lock(state.mutex);
          state.together[k] = static_cast<double>(unit.size()) * static_cast<double>(step) / static_cast<double>(std::max(steps, 1L));
        };
        std::vector<std::unique_ptr<Stepper>> steppers;
        std::vector<size_t> members(unit.size());  // the unit's cases that step together (indices into unit)
        for (size_t j = 0; j < unit.size(); ++j) members[j] = j;
        try {
          steppers = backend->makeTogether(pointers);
        } catch (const BackendUnsupported& e) {
          // Cases the backend cannot hold together after all (too many ids for one state, say):
          // each runs alone, as with --batch 1.
          if (!options.quiet) std::fprintf(stderr, "gem sweep: %s; running those %zu cases one at a time\n", e.what(), unit.size());
          RunOptions runOptions;
          runOptions.quiet = true;
          runOptions.checkpoints = false;
          for (size_t j = 0; j < unit.size(); ++j) failures[j] = message([&] { runScenario(scenarios[j], runOptions); });
          return;
        } catch (const std::exception&) {
          // A case whose world cannot be built (a floe on the vessel, say) fails with its own
          // message, as it would alone, and the others still run together. Only a failure that is
          // no one case's fails them all.
          std::vector<const Scenario*> buildable;
          members.clear();
          for (size_t j = 0; j < unit.size(); ++j) {
            failures[j] = message([&] { buildWorld(scenarios[j]); });
            if (failures[j].empty()) members.push_back(j), buildable.push_back(pointers[j]);
          }
          if (members.size() == unit.size()) throw;
          if (members.empty()) return;
          pointers = std::move(buildable);
          steppers = backend->makeTogether(pointers);
        }
        const std::vector<std::string> outcomes = runScenariosTogether(pointers, std::move(steppers), progress);
        for (size_t m = 0; m < members.size(); ++m) failures[members[m]] = outcomes[m];
      });
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - unitStart).count();
      {
        std::lock_guard lock(state.mutex);
        state.together.erase(k);
      }
      for (size_t j = 0; j < unit.size(); ++j) finished(unit[j], shared.empty() ? failures[j] : shared, seconds, unit.size());
    }
  };
  std::vector<std::thread> threads;
  for (size_t t = 0; t < jobs && t < units.size(); ++t) threads.emplace_back(worker, t);
  if (terminal && !todo.empty() && !mpi.active()) {
    std::unique_lock lock(state.mutex);
    while (state.finished < todo.size() && !(interruptSignal() && state.running == 0)) {
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      // Cases running together count by how far their steps are.
      double done = static_cast<double>(state.finished);
      for (const auto& [unit, worth] : state.together) done += worth;
      const double eta = done > 0 ? elapsed / done * (static_cast<double>(todo.size()) - done) : NAN;
      std::fprintf(stderr, "\r  cases %zu/%zu done, %zu running%s, elapsed %s, ETA %s   ", state.finished, todo.size(), state.running,
                   state.failures.empty() ? "" : fmt::format(", {} failed", state.failures.size()).c_str(), formatDuration(elapsed).c_str(),
                   formatDuration(eta).c_str());
      std::fflush(stderr);
      state.changed.wait_for(lock, std::chrono::milliseconds(500));
    }
    std::fprintf(stderr, "\r  cases %zu/%zu done in %s%*s\n", state.finished, todo.size(),
                 formatDuration(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()).c_str(), 30, "");
  }
  for (std::thread& t : threads) t.join();

  // Under MPI every rank waits for all; rank 0 alone gathers the table.
  const long failures = mpi.sumOverRanks(static_cast<long>(state.failures.size()));
  for (const auto& [name, message] : state.failures) std::fprintf(stderr, "gem sweep: case %s failed: %s\n", name.c_str(), message.c_str());
  if (mpi.rank() != 0) return failures == 0 ? 0 : 1;
  const fs::path csv = outDir / "summary.csv";
  const int rows = writeSweepSummary(sweep, csv, dirs);
  if (!options.quiet) std::printf("  summary %s (%d of %zu cases complete)\n", csv.string().c_str(), rows, count);
  // Interrupted: the gathered table holds the cases that completed; `gem sweep` again resumes.
  if (const int signal = interruptSignal())
    throw Interrupted(signal,
                      fmt::format("sweep interrupted; {} of {} cases complete, the others run when the sweep is run again", rows, count));
  return failures == 0 ? 0 : 1;
}

int checkSweep(const SweepOptions& options) {
  SweepDefinition sweep = readSweepFile(options.sweepFile);
  addCommandLineOverrides(sweep, options);
  const fs::path outDir = sweepFolder(sweep, options);
  // Every case as gem sweep loads it before any runs...
  std::vector<Scenario> scenarios;
  for (const SweepCase& c : sweep.cases) scenarios.push_back(validateCase(sweep, c, outDir / "cases" / c.folder));
  // ... then as gem check checks a scenario.
  std::vector<size_t> all(sweep.cases.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  checkCases(sweep, scenarios, all, std::max(1u, std::thread::hardware_concurrency()), !options.quiet && isatty(fileno(stderr)));
  if (options.quiet) return 0;
  // The bases, relative to the sweep file's folder, each once, in case order.
  std::vector<std::string> bases;
  for (const SweepCase& c : sweep.cases) {
    const std::string base = c.base.lexically_relative(sweep.file.parent_path()).string();
    if (std::find(bases.begin(), bases.end(), base) == bases.end()) bases.push_back(base);
  }
  std::string baseText = "base " + bases[0];
  if (bases.size() > 1) {
    const size_t shownBases = std::min<size_t>(bases.size(), 3);
    baseText =
        fmt::format("{} bases: {}{}", bases.size(), fmt::join(bases.begin(), bases.begin() + static_cast<std::ptrdiff_t>(shownBases), ", "),
                    bases.size() > shownBases ? ", ..." : "");
  }
  std::printf("%s: ok (%zu case%s; %s)\n", options.sweepFile.c_str(), sweep.cases.size(), sweep.cases.size() == 1 ? "" : "s",
              baseText.c_str());
  return 0;
}

}  // namespace gem
