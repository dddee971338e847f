#include "bench/bench.hpp"

#include <algorithm>
#include <system_error>
#include <cstdlib>
#include <chrono>
#include <ctime>
#include <exception>
#include <latch>
#include <numeric>
#include <thread>
#include <tuple>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"
#include "framework/output/csv.hpp"
#include "framework/output/output_path.hpp"
#include "framework/api/errors.hpp"
#include "framework/api/input_size.hpp"
#include "framework/field/field_generator.hpp"
#include "bench/geometry_bench.hpp"
#include "framework/api/registry.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"

namespace fs = std::filesystem;

namespace gem {

std::string cpuName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
  return "unknown CPU";
}

const std::vector<std::string>& benchTables() {
  static const std::vector<std::string> tables{"step",         "fields",        "blocks",   "copyback", "scaling",
                                               "intersection", "triangulation", "resident", "cpu",      "all"};
  return tables;
}

namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

}  // namespace

// Where the bench's scenes are read from: $GEM_SCENARIOS; else beside an installed or copied gem
// (PREFIX/share/gem/scenarios, or a scenarios/ folder next to the binary); else the source tree it
// was built from. A gem that finds none says where it looked.
fs::path benchScenariosDir() {
  std::vector<fs::path> candidates;
  if (const char* env = std::getenv("GEM_SCENARIOS")) candidates.emplace_back(env);
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    candidates.push_back(exe.parent_path() / ".." / "share" / "gem" / "scenarios");
    candidates.push_back(exe.parent_path() / "scenarios");
  }
  candidates.emplace_back(fs::path(GEM_SOURCE_DIR) / "scenarios");
  std::string tried;
  for (const fs::path& c : candidates) {
    if (fs::is_regular_file(c / "thesis" / "random_35.toml", ec)) return fs::weakly_canonical(c, ec);
    tried += (tried.empty() ? "" : ", ") + c.string();
  }
  throw InputError("gem bench: its scenes (scenarios/thesis/*.toml) are not found; looked in " + tried + " (set GEM_SCENARIOS)");
}

namespace {

Scenario thesisField(const char* file) {
  const fs::path path = benchScenariosDir() / "thesis" / file;
  Scenario s = loadScenario(path);
  s.output.frameEvery = 0;
  return s;
}

// N random floes at 40 % in a square-ish channel, the vessel entering it. The domain's area holds
// N floes of the thesis's size statistics (E[s^2] = 6.9^2 + 3.9^2 m^2).
Scenario largeField(int floes) {
  Scenario s = thesisField("random_35.toml");
  const Real area = floes * Real(6.9 * 6.9 + 3.9 * 3.9) / Real(0.4);
  const Real width = std::max<Real>(200, std::round(std::sqrt(area) / 100) * 100);
  s.domain = Domain{0, std::ceil(area / width), -width / 2, width / 2};
  s.randomField.domain = s.domain;
  s.randomField.count = floes;
  s.randomField.concentration = Real(0.4);
  return s;
}

// A case: "456" (hexagons), "824" (random, 50 %) or a floe count N (random, 40 %).
struct CaseKey {
  std::string key, name;
  long floes;  // the random field's count; 0 for the thesis fields
};

CaseKey parseCase(const std::string& key) {
  if (key == "456") return {key, "456 hexagons (46 %)", 0};
  if (key == "824") return {key, "824 random (50 %)", 0};
  size_t used = 0;
  long n = 0;
  try {
    n = std::stol(key, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != key.size() || n < 10 || n > 10000000)
    throw InputError(
        fmt::format("gem bench --cases {}: valid cases are 456, 824 (the thesis fields) or a floe count "
                    "from 10 to 10^7 (random convex floes at 40 %), e.g. 10000 100000 1000000",
                    key));
  // A field this machine could not hold is refused before it is generated (10^7 floes want about
  // 30 GB: on a 24 GB machine it grew for minutes).
  if (fieldMemoryNeed(static_cast<double>(n)) > 0.8 * machineMemory())
    throw InputError(fmt::format("gem bench --cases {}: {} floes need about {:.3g} GB; this machine has {:.3g} GB: give fewer floes", key,
                                 n, fieldMemoryNeed(static_cast<double>(n)) / 1e9, machineMemory() / 1e9));
  int power = 0;
  for (long m = n; m % 10 == 0 && m > 1; m /= 10) ++power;
  const bool powerOfTen = n == static_cast<long>(std::llround(std::pow(10.0, power)));
  return {key, powerOfTen && power >= 4 ? fmt::format("10^{} random (40 %)", power) : fmt::format("{} random (40 %)", n), n};
}

// Scenarios of the cases, a large field generated once per run (10^6 floes take seconds) and
// handed to every row as explicit floes: buildWorld adds them in the generator's order.
class CaseScenarios {
 public:
  Scenario get(const CaseKey& c) {
    if (c.key == "456") return thesisField("hexagons_46.toml");
    if (c.key == "824") return thesisField("random_50.toml");
    Scenario s = largeField(static_cast<int>(c.floes));
    auto it = m_fields.find(c.floes);
    if (it == m_fields.end()) {
      const auto start = Clock::now();
      if (c.floes >= 50000) std::fprintf(stderr, "gem bench: generating %s...\n", c.name.c_str());
      it = m_fields.emplace(c.floes, generateRandomConvexField(s.randomField)).first;
      if (c.floes >= 50000) std::fprintf(stderr, "gem bench: generated %s in %.1f s\n", c.name.c_str(), secondsSince(start));
    }
    s.fieldKind = "none";
    s.floes = it->second;
    return s;
  }

 private:
  std::map<long, std::vector<BodySpec>> m_fields;
};

// Seconds per step: the median of 5 chunks after a warm-up. Large fields get fewer steps, so that
// one case stays within a minute on a slow backend. A device backend runs steps in batches of
// copy_back_every, cut at each re-sort (every 200 steps): it is timed over whole periods of that
// pattern from a period's start, so every chunk holds the same batches (and the copies).
double timePerStep(Stepper& sim, const Scenario& s, long requested, int bodies) {
  const long steps = std::clamp<long>(requested * 1000 / std::max(bodies, 1), std::min<long>(10, requested), requested);
  long chunk = std::max<long>(1, steps / 5), warm = std::min<long>(100, steps);
  if (sim.backend() != "cpu") {
    const long period = s.mortonSort ? 200 : std::max(1, s.copyBackEvery);
    auto roundUp = [&](long n) { return (std::max<long>(n, 1) + period - 1) / period * period; };
    chunk = roundUp(chunk), warm = roundUp(warm);
  }
  for (long k = 0; k < warm; ++k) sim.step();
  sim.restartPhaseClock();
  std::vector<double> perStep;
  for (int r = 0; r < 5; ++r) {
    const auto start = Clock::now();
    for (long k = 0; k < chunk; ++k) sim.step();  // step() returns once the step is done (device synced)
    perStep.push_back(secondsSince(start) / chunk);
  }
  std::sort(perStep.begin(), perStep.end());
  return perStep[perStep.size() / 2];
}

struct Row {
  std::string caseName, backend, broadphase, param;
  int bodies = 0, floes = 0;
  double seconds = 0;  // per step
  double dt = 0.1;
  std::string device;
};

// One printed table and its CSV (rewritten after every row, so a run cut short keeps its rows).
class Table {
 public:
  Table(std::string name, std::string paramColumn, std::string csvPath)
      : m_name(std::move(name)), m_param(std::move(paramColumn)), m_csvPath(std::move(csvPath)) {
    m_csv = "case,backend,broadphase," + (m_param.empty() ? "" : m_param + ",") +
            "bodies,floes,ms_per_step,steps_per_s,floe_steps_per_s,real_time_factor,device\n";
    // The header at once: a CSV path that cannot be written (a pipe, a folder, no such folder) is
    // refused before any case runs, not after the first one.
    if (!m_csvPath.empty()) writeFileAtomically(m_csvPath, m_csv);
  }
  void printHeader() const {
    std::printf("%-20s %-7s %-18s ", "case", "backend", "broadphase");
    if (!m_param.empty()) std::printf("%15s ", m_param.c_str());
    std::printf("%8s %10s %10s %14s %12s  %s\n", "bodies", "ms/step", "steps/s", "floe-steps/s", "x real time", "device");
  }
  void add(const Row& r) {
    const double t = r.seconds, realTime = r.dt / t;
    std::printf("%-20s %-7s %-18s ", r.caseName.c_str(), r.backend.c_str(), r.broadphase.c_str());
    if (!m_param.empty()) std::printf("%15s ", r.param.c_str());
    std::printf("%8d %10.4f %10.0f %14.3g %12.0f  %s\n", r.bodies, t * 1e3, 1 / t, r.floes / t, realTime, r.device.c_str());
    std::fflush(stdout);
    m_csv += fmt::format("{},{},{},{}{},{},{:.6f},{:.1f},{:.6g},{:.1f},{}\n", csvQuoted(r.caseName), csvField(r.backend),
                         csvField(r.broadphase), m_param.empty() ? "" : csvField(r.param) + ",", r.bodies, r.floes, t * 1e3, 1 / t,
                         r.floes / t, realTime, csvQuoted(r.device));
    if (!m_csvPath.empty()) writeFileAtomically(m_csvPath, m_csv);
    m_rows.push_back(r);
  }
  const std::vector<Row>& rows() const { return m_rows; }
  // An empty table still leaves its header in the CSV.
  void finish() const {
    if (!m_csvPath.empty() && m_rows.empty()) writeFileAtomically(m_csvPath, m_csv);
    if (!m_csvPath.empty()) std::printf("CSV: %s\n", m_csvPath.c_str());
  }

 private:
  std::string m_name, m_param, m_csvPath, m_csv;
  std::vector<Row> m_rows;
};

// Times one row: the case's scenario on a backend and broadphase, with a CUDA setting changed.
// The CPU rows' threads (gem bench --threads; 1 unless asked: the thesis's tables compare one core).
int g_cpuThreads = 1;
std::string cpuDeviceName() {
  return cpuName() + (g_cpuThreads == 1 ? std::string(" (one core)") : fmt::format(" ({} threads)", g_cpuThreads));
}

// The case's scenario as a row times it: on `backend` with `broadphase` and `threads`, long enough
// that no batch is cut at the scenario's end inside the timing.
Scenario rowScenario(CaseScenarios& scenarios, const CaseKey& c, const std::string& backend, const std::string& broadphase, long steps,
                     int threads) {
  Scenario s = scenarios.get(c);
  s.backend = backend;
  s.threads = threads;
  s.broadphase = broadphase;
  s.steps = std::max<long>(s.steps, 2 * steps + 1000);
  return s;
}

Row timeRow(CaseScenarios& scenarios, const CaseKey& c, const std::string& backend, const std::string& broadphase, long steps,
            const std::string& param = "", std::optional<int> blockSize = {}, std::optional<int> copyBackEvery = {}) {
  Scenario s = rowScenario(scenarios, c, backend, broadphase, steps, g_cpuThreads);
  if (blockSize) s.cudaBlockSize = *blockSize;
  if (copyBackEvery) s.copyBackEvery = *copyBackEvery;
  const bool large = c.floes >= 50000;
  const auto start = Clock::now();
  if (large)
    std::fprintf(stderr, "gem bench: %s, %s, %s%s%s...\n", c.name.c_str(), backend.c_str(), broadphase.c_str(), param.empty() ? "" : ", ",
                 param.c_str());
  std::unique_ptr<Stepper> sim = makeStepper(s);
  Row r;
  r.caseName = c.name, r.backend = backend, r.broadphase = broadphase, r.param = param;
  r.bodies = sim->hostWorld().size();
  r.floes = sim->hostWorld().count(BodyKind::Floe);
  r.dt = s.dt;
  r.seconds = timePerStep(*sim, s, steps, r.bodies);
  r.device = backend == "cpu" ? cpuDeviceName() : sim->device();
  if (large) std::fprintf(stderr, "gem bench: ... done in %.1f s\n", secondsSince(start));
  return r;
}

// Built-in broadphases, the thesis's first (variable radius, the reference of the comparisons).
std::vector<std::string> builtInBroadphases() {
  std::vector<std::string> names;
  for (const char* n : {"variable_radius", "fixed_radius", "uniform_grid", "triangulation_mesh", "all_pairs"})
    for (const BroadphaseEntry* b : Registry::global().broadphases())
      if (b->name == n && b->origin == "built-in") names.push_back(n);
  for (const BroadphaseEntry* b : Registry::global().broadphases())
    if (b->origin == "built-in" && std::find(names.begin(), names.end(), b->name) == names.end()) names.push_back(b->name);
  return names;
}

bool cudaUsable() {
  const BackendEntry* cuda = findBackend("cuda");
  return cuda && cuda->available();
}

// What one run of a table is given: its CSV path, the backends it may use, and whether a table
// that cannot run (no CUDA) is skipped with a line (gem bench --table all) rather than an error.
struct TableRun {
  const BenchOptions& options;
  CaseScenarios& scenarios;
  std::string csvPath;
  bool partOfAll = false;
  bool skipCuda = false;  // --table all with no device and no --backend: the CPU rows only
};

std::vector<CaseKey> casesOf(const BenchOptions& o, std::vector<std::string> defaults) {
  std::vector<CaseKey> cases;
  for (const std::string& k : o.cases.empty() ? defaults : o.cases) cases.push_back(parseCase(k));
  return cases;
}

// The table's backends: --backend, else its defaults less cuda where --table all found no device.
// Each is checked now (a backend without a device is an InputError that says so); `allowed`
// limits them (blocks and copyback sweep CUDA settings). Empty: the table is skipped.
std::vector<std::string> backendsOf(const TableRun& run, const std::string& table, std::vector<std::string> defaults,
                                    const std::vector<std::string>& allowed) {
  std::vector<std::string> backends = run.options.backends.empty() ? defaults : run.options.backends;
  if (run.skipCuda) backends.erase(std::remove(backends.begin(), backends.end(), "cuda"), backends.end());
  std::vector<std::string> out;
  for (const std::string& b : backends) {
    if (std::find(allowed.begin(), allowed.end(), b) == allowed.end()) {
      if (run.partOfAll) continue;
      throw InputError(fmt::format("gem bench --table {}: --backend {}: this table times {} only", table, b, fmt::join(allowed, ", ")));
    }
    try {
      resolveBackend(b);
    } catch (const InputError& e) {
      throw InputError(fmt::format("gem bench --table {}: {}{}", table, e.what(),
                                   run.options.backends.empty() && std::find(allowed.begin(), allowed.end(), "cpu") != allowed.end()
                                       ? " (--backend cpu times the CPU rows alone)"
                                       : ""));
    }
    out.push_back(b);
  }
  if (out.empty())
    std::printf("%s table skipped: %s\n", table.c_str(),
                run.skipCuda ? "it needs the CUDA backend and there is no CUDA device" : "no backend of --backend applies");
  return out;
}

std::string caseList(const std::vector<CaseKey>& cases) {
  std::vector<std::string> names;
  for (const CaseKey& c : cases) names.push_back(c.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

void printTiming(const BenchOptions& o) {
  std::printf(
      "%ld timed steps per case (fewer for large fields; whole 200-step periods on a device) after a warm-up; "
      "median of 5 chunks; real time at the scenario's dt (0.1 s); scenes from %s\n",
      o.steps, benchScenariosDir().string().c_str());
}

// --table step: every case x backend x broadphase (the README's table).
void stepTable(const TableRun& run) {
  const BenchOptions& o = run.options;
  const auto cases = casesOf(o, {"456", "824", "10000"});
  const auto backends = backendsOf(run, "step", {"cpu"}, {"cpu", "cuda"});
  const std::vector<std::string> broadphases = o.broadphases.empty() ? std::vector<std::string>{"variable_radius"} : o.broadphases;
  std::printf("gem bench: ");
  printTiming(o);
  Table table("step", "", run.csvPath);
  table.printHeader();
  for (const CaseKey& c : cases)
    for (const std::string& backend : backends)
      for (const std::string& broadphase : broadphases) table.add(timeRow(run.scenarios, c, backend, broadphase, o.steps));
  table.finish();
}

// Each broadphase's speed against variable_radius on the same case and backend.
void printAgainstVariableRadius(const std::vector<Row>& rows) {
  for (const Row& base : rows) {
    if (base.broadphase != "variable_radius") continue;
    std::string line;
    for (const Row& r : rows)
      if (r.caseName == base.caseName && r.backend == base.backend && r.broadphase != base.broadphase)
        line += fmt::format("{}{} {:.2f}x", line.empty() ? "" : ", ", r.broadphase, base.seconds / r.seconds);
    if (!line.empty())
      std::printf("against variable_radius, %s on %s (speed, >1 faster): %s\n", base.caseName.c_str(), base.backend.c_str(), line.c_str());
  }
}

// --table fields (thesis 5.4, 5.5): the thesis fields on the CPU and the GPU, every broadphase.
void fieldsTable(const TableRun& run) {
  const BenchOptions& o = run.options;
  const auto cases = casesOf(o, {"456", "824"});
  const auto backends = backendsOf(run, "fields", {"cpu", "cuda"}, {"cpu", "cuda"});
  if (backends.empty()) return;
  const std::vector<std::string> broadphases = o.broadphases.empty() ? builtInBroadphases() : o.broadphases;
  std::printf(
      "gem bench --table fields: time per step CPU vs GPU on %s; fixed vs variable radius, and uniform grid, "
      "triangulation mesh and all pairs against variable radius\n",
      caseList(cases).c_str());
  printTiming(o);
  Table table("fields", "", run.csvPath);
  table.printHeader();
  for (const CaseKey& c : cases)
    for (const std::string& backend : backends)
      for (const std::string& broadphase : broadphases) table.add(timeRow(run.scenarios, c, backend, broadphase, o.steps));
  printAgainstVariableRadius(table.rows());
  table.finish();
}

// --table blocks and --table copyback: one CUDA setting swept per case.
void sweepTable(const TableRun& run, const std::string& name) {
  const BenchOptions& o = run.options;
  const bool blocks = name == "blocks";
  const auto cases = casesOf(o, blocks ? std::vector<std::string>{"3584", "7168"} : std::vector<std::string>{"824", "100000"});
  const auto backends = backendsOf(run, name, {"cuda"}, {"cuda"});
  if (backends.empty()) return;
  std::vector<int> values = blocks ? o.blockSizes : o.copyBackEvery;
  if (values.empty()) values = blocks ? std::vector<int>{32, 64, 128, 256, 512, 1024} : std::vector<int>{1, 2, 4, 8, 16, 32, 64, 128};
  const std::vector<std::string> broadphases = o.broadphases.empty() ? std::vector<std::string>{"variable_radius"} : o.broadphases;
  if (blocks)
    std::printf("gem bench --table blocks: CUDA threads per block (simulation.cuda_block_size) on %s\n", caseList(cases).c_str());
  else
    std::printf(
        "gem bench --table copyback: CUDA steps between copies of results to the host (simulation.copy_back_every, "
        "thesis 5.7) on %s; the time per step includes the copies\n",
        caseList(cases).c_str());
  printTiming(o);
  Table table(name, blocks ? "block_size" : "copy_back_every", run.csvPath);
  table.printHeader();
  for (const CaseKey& c : cases)
    for (const std::string& backend : backends)
      for (const std::string& broadphase : broadphases)
        for (int v : values)
          table.add(blocks ? timeRow(run.scenarios, c, backend, broadphase, o.steps, std::to_string(v), v)
                           : timeRow(run.scenarios, c, backend, broadphase, o.steps, std::to_string(v), {}, v));
  table.finish();
}

// `fields` copies of the case, each stepped on one thread (no pool) by a thread of its own, all
// at once: the copies' mean time a step. They share nothing but the machine (its caches above the
// core, its memory, its clock under load), so `fields` times one field's time over that mean is
// the work the machine does on that many cores when nothing is shared: what threads stepping one
// field could gain at most on this machine (docs/performance.md 3.23). Each copy is timed as
// timeRow times one; a copy that ends first leaves the others a little less disturbed, so the
// mean is a little kinder than a machine busy throughout.
Row independentFieldsRow(CaseScenarios& scenarios, const CaseKey& c, const std::string& broadphase, long steps, int fields) {
  const Scenario s = rowScenario(scenarios, c, "cpu", broadphase, steps, 1);
  const bool large = c.floes >= 50000;
  const auto begun = Clock::now();
  if (large) std::fprintf(stderr, "gem bench: %s, cpu, %s, %d independent fields...\n", c.name.c_str(), broadphase.c_str(), fields);
  std::vector<std::unique_ptr<Stepper>> sims;
  for (int k = 0; k < fields; ++k) sims.push_back(makeStepper(s));
  Row r;
  r.caseName = c.name, r.backend = "cpu", r.broadphase = broadphase, r.param = fmt::format("{} fields", fields);
  r.bodies = sims.front()->hostWorld().size();  // before the steps, as timeRow's (breaks add bodies)
  r.floes = sims.front()->hostWorld().count(BodyKind::Floe);
  std::vector<double> seconds(static_cast<size_t>(fields));
  std::vector<std::exception_ptr> errors(static_cast<size_t>(fields));
  std::latch start(fields);  // every field made before any is stepped
  std::vector<std::thread> threads;
  for (int k = 0; k < fields; ++k)
    threads.emplace_back([&, k] {
      start.arrive_and_wait();
      try {
        Stepper& sim = *sims[static_cast<size_t>(k)];
        seconds[static_cast<size_t>(k)] = timePerStep(sim, s, steps, sim.hostWorld().size());
      } catch (...) {
        errors[static_cast<size_t>(k)] = std::current_exception();
      }
    });
  for (std::thread& t : threads) t.join();
  for (const std::exception_ptr& e : errors)
    if (e) std::rethrow_exception(e);
  r.dt = s.dt;
  r.seconds = std::accumulate(seconds.begin(), seconds.end(), 0.0) / fields;
  r.device = cpuName() + fmt::format(" ({} independent fields, a thread each)", fields);
  if (large) std::fprintf(stderr, "gem bench: ... done in %.1f s\n", secondsSince(begun));
  return r;
}

// --table cpu: the CPU backend on one field over 1, 2, 4, 8 and every core's threads
// (simulation.threads), the thesis fields and 10^4, 10^5 floes; each row's speed-up over one
// thread, and after it as many independent one-thread fields stepped at once (the row's threads
// column says "N fields"): the speed-up the machine itself allows at that thread count.
void cpuTable(const TableRun& run) {
  const BenchOptions& o = run.options;
  const auto cases = casesOf(o, {"456", "824", "10000", "100000"});
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::vector<int> threads{1};
  for (int t : {2, 4, 8})
    if (t < cores) threads.push_back(t);
  if (cores > 1) threads.push_back(cores);
  const std::vector<std::string> broadphases = o.broadphases.empty() ? std::vector<std::string>{"variable_radius"} : o.broadphases;
  std::printf("gem bench --table cpu: threads stepping one field (simulation.threads) on %s; %d cores, %s\n", caseList(cases).c_str(),
              cores, cpuName().c_str());
  printTiming(o);
  Table table("cpu", "threads", run.csvPath);
  table.printHeader();
  const int asked = g_cpuThreads;
  for (const CaseKey& c : cases)
    for (const std::string& broadphase : broadphases) {
      double one = 0;
      for (int t : threads) {
        g_cpuThreads = t;
        const Row r = timeRow(run.scenarios, c, "cpu", broadphase, o.steps, std::to_string(t));
        table.add(r);
        if (t == 1) one = r.seconds;
        if (t == 1) continue;
        const Row fields = independentFieldsRow(run.scenarios, c, broadphase, o.steps, t);
        table.add(fields);
        std::printf("  %d threads: %.2fx one thread; %d independent fields: %.2fx one field's work (the most %d threads could gain here)\n",
                    t, one / r.seconds, t, t * one / fields.seconds, t);
      }
    }
  g_cpuThreads = asked;
  table.finish();
}

// --table scaling (thesis 5.6): 10^4 to 10^6 floes per broadphase on the GPU; the CPU at 10^4 and
// 10^5 with variable radius, for the GPU/CPU ratio.
void scalingTable(const TableRun& run) {
  const BenchOptions& o = run.options;
  const auto cases = casesOf(o, {"10000", "100000", "1000000"});
  const auto backends = backendsOf(run, "scaling", {"cuda", "cpu"}, {"cpu", "cuda"});
  if (backends.empty()) return;
  constexpr long kAllPairsMax = 10000;
  std::printf(
      "gem bench --table scaling: %s; every built-in broadphase on the GPU, "
      "variable_radius on the CPU up to 10^5 floes; all_pairs only up to 10^4 floes\n",
      caseList(cases).c_str());
  printTiming(o);
  Table table("scaling", "", run.csvPath);
  table.printHeader();
  for (const CaseKey& c : cases)
    for (const std::string& backend : backends) {
      // The CPU rows: variable radius up to 10^5 unless --broadphase or --cases ask for more.
      if (backend == "cpu" && o.cases.empty() && c.floes > 100000) continue;
      const std::vector<std::string> broadphases = !o.broadphases.empty() ? o.broadphases
                                                   : backend == "cpu"     ? std::vector<std::string>{"variable_radius"}
                                                                          : builtInBroadphases();
      for (const std::string& broadphase : broadphases) {
        if (broadphase == "all_pairs" && c.floes > kAllPairsMax) {
          std::printf("%-20s %-7s %-18s skipped: all_pairs tests N^2/2 pairs, timed only up to 10^4 floes\n", c.name.c_str(),
                      backend.c_str(), broadphase.c_str());
          continue;
        }
        table.add(timeRow(run.scenarios, c, backend, broadphase, o.steps));
      }
    }
  // GPU/CPU speed ratio where a case has both on one broadphase.
  for (const Row& cpu : table.rows()) {
    if (cpu.backend != "cpu") continue;
    for (const Row& gpu : table.rows())
      if (gpu.backend != "cpu" && gpu.caseName == cpu.caseName && gpu.broadphase == cpu.broadphase)
        std::printf("GPU/CPU speed, %s, %s: %.1fx (%s %.4g ms, cpu %.4g ms per step)\n", cpu.caseName.c_str(), cpu.broadphase.c_str(),
                    cpu.seconds / gpu.seconds, gpu.backend.c_str(), gpu.seconds * 1e3, cpu.seconds * 1e3);
  }
  table.finish();
}

// --table resident: the CUDA drivers on the thesis fields as one world (the CPU on one core beside
// them), then ensembles of thesis-size worlds (the 456-hexagon field, a case each) run together on
// the resident driver, a block per world. A row: its wall time per step (host bookkeeping of every
// case included) and its device time per step (the launches and copies alone).
struct ResidentRow {
  std::string caseName, driver, device;
  int worlds = 1;
  long bodies = 0, floes = 0;
  double seconds = 0, deviceSeconds = 0;  // per step
};

std::string todayUtc() {
  const std::time_t now = std::time(nullptr);
  char text[16];
  std::strftime(text, sizeof text, "%Y-%m-%d", std::gmtime(&now));
  return text;
}

// Steppers stepped together, every one's step k before any one's step k + 1: seconds of wall and
// of device time per step over `steps` steps after `warm` steps.
std::pair<double, double> timeTogether(std::vector<std::unique_ptr<Stepper>>& sims, long warm, long steps) {
  for (long k = 0; k < warm; ++k)
    for (auto& sim : sims) sim->step();
  const double device0 = sims.front()->deviceSeconds();
  const auto start = Clock::now();
  for (long k = 0; k < steps; ++k)
    for (auto& sim : sims) sim->step();
  return {secondsSince(start) / static_cast<double>(steps), (sims.front()->deviceSeconds() - device0) / static_cast<double>(steps)};
}

void residentTable(const TableRun& run) {
  const BenchOptions& o = run.options;
  const BackendEntry* cuda = findBackend("cuda");
  if (!cudaUsable()) {
    if (run.skipCuda) {
      std::printf("resident table skipped: it times the CUDA drivers, and %s\n",
                  cuda ? "no CUDA device was found on this machine" : "this build has no CUDA backend");
      return;
    }
    throw InputError(std::string("gem bench --table resident: it times the CUDA drivers, and ") +
                     (cuda ? "no CUDA device was found on this machine" : "this build has no CUDA backend"));
  }
  const std::string date = todayUtc(), commit = GEM_COMMIT;
  const std::vector<long> ensembles = o.sizes.empty() ? std::vector<long>{10, 100, 1000, 10000} : o.sizes;
  std::printf(
      "gem bench --table resident: the thesis fields as one world on each CUDA driver (and the CPU, one core), then ensembles of "
      "456-hexagon worlds on the resident driver (--sizes: the world counts); %s, commit %s\n",
      date.c_str(), commit.c_str());
  std::printf("%-28s %7s %9s %-8s %10s %10s %14s %14s %16s  %s\n", "case", "worlds", "bodies", "driver", "ms/step", "device ms",
              "steps/s/world", "floe-steps/s", "dev floe-steps/s", "device");
  std::string csv =
      "case,worlds,bodies,driver,ms_per_step,device_ms_per_step,steps_per_s_per_world,floe_steps_per_s,device_floe_steps_per_s,device,"
      "date,commit\n";
  auto add = [&](const ResidentRow& r) {
    const double floeSteps = static_cast<double>(r.floes) / r.seconds;
    const double deviceFloeSteps = r.deviceSeconds > 0 ? static_cast<double>(r.floes) / r.deviceSeconds : 0;
    std::printf("%-28s %7d %9ld %-8s %10.4f %10.4f %14.0f %14.3g %16.3g  %s\n", r.caseName.c_str(), r.worlds, r.bodies, r.driver.c_str(),
                r.seconds * 1e3, r.deviceSeconds * 1e3, 1 / r.seconds, floeSteps, deviceFloeSteps, r.device.c_str());
    std::fflush(stdout);
    csv += fmt::format("\"{}\",{},{},{},{:.6f},{:.6f},{:.1f},{:.6g},{:.6g},\"{}\",{},{}\n", r.caseName, r.worlds, r.bodies, r.driver,
                       r.seconds * 1e3, r.deviceSeconds * 1e3, 1 / r.seconds, floeSteps, deviceFloeSteps, r.device, date, commit);
    if (!run.csvPath.empty()) writeFileAtomically(run.csvPath, csv);
  };
  // One world: each driver, and the CPU.
  for (const CaseKey& c : casesOf(o, {"456", "824"})) {
    for (const std::string driver : {"resident", "device", "cpu"}) {
      Scenario s = run.scenarios.get(c);
      s.backend = driver == "cpu" ? "cpu" : "cuda";
      s.threads = g_cpuThreads;
      if (driver != "cpu") s.cudaDriver = driver;
      s.steps = std::max<long>(s.steps, 2 * o.steps + 1000);
      std::vector<std::unique_ptr<Stepper>> sims;
      sims.push_back(makeStepper(s));
      ResidentRow r;
      r.caseName = c.name, r.driver = sims.front()->driver();
      r.bodies = sims.front()->hostWorld().size(), r.floes = sims.front()->hostWorld().count(BodyKind::Floe);
      r.device = driver == "cpu" ? cpuDeviceName() : sims.front()->device();
      // Whole 200-step periods (re-sorts, copy-backs) from a period's start.
      const long steps = std::max<long>(200, o.steps / 200 * 200);
      std::tie(r.seconds, r.deviceSeconds) = timeTogether(sims, 200, steps);
      add(r);
    }
  }
  // Ensembles: a 456-hexagon world per case, run together on the resident driver.
  for (long worlds : ensembles) {
    if (worlds < 1 || worlds > 100000)
      throw InputError(fmt::format("gem bench --table resident --sizes {}: from 1 to 100000 worlds", worlds));
    Scenario s = run.scenarios.get(parseCase("456"));
    s.backend = "cuda";
    s.cudaDriver = "resident";
    // Steps in whole copy-back batches (16), fewer for many worlds (each step of each case is also
    // the host's bookkeeping), at least one re-sort period.
    const long steps = std::clamp<long>(20000 / worlds / 16 * 16, 32, std::max<long>(32, o.steps / 16 * 16));
    s.steps = 16 + steps + 200;
    const auto setUp = Clock::now();
    std::fprintf(stderr, "gem bench: setting up %ld worlds...\n", worlds);
    const std::vector<Scenario> cases(static_cast<size_t>(worlds), s);
    std::vector<const Scenario*> pointers;
    for (const Scenario& one : cases) pointers.push_back(&one);
    std::vector<std::unique_ptr<Stepper>> sims = cuda->makeTogether(pointers);
    std::fprintf(stderr, "gem bench: %ld worlds set up in %.1f s\n", worlds, secondsSince(setUp));
    ResidentRow r;
    r.caseName = fmt::format("{} x 456 hexagons", worlds);
    r.worlds = static_cast<int>(worlds);
    r.driver = sims.front()->driver();
    r.device = sims.front()->device();
    for (auto& sim : sims) r.bodies += sim->hostWorld().size(), r.floes += sim->hostWorld().count(BodyKind::Floe);
    std::tie(r.seconds, r.deviceSeconds) = timeTogether(sims, 16, steps);
    add(r);
  }
  if (!run.csvPath.empty()) std::printf("CSV: %s\n", run.csvPath.c_str());
}

void geometryTable(const TableRun& run, const std::string& name) {
  runGeometryBench(GeometryBenchOptions{name, run.options.sizes, run.csvPath, run.options.reps});
  if (!run.csvPath.empty()) std::printf("CSV: %s\n", run.csvPath.c_str());
}

void runTable(const TableRun& run, const std::string& name) {
  if (name == "step")
    stepTable(run);
  else if (name == "fields")
    fieldsTable(run);
  else if (name == "blocks" || name == "copyback")
    sweepTable(run, name);
  else if (name == "scaling")
    scalingTable(run);
  else if (name == "resident")
    residentTable(run);
  else if (name == "cpu")
    cpuTable(run);
  else
    geometryTable(run, name);
}

// --csv: a file for one table; a directory with TABLE.csv for "all", or when it is a directory
// already or ends in '/'.
bool csvIsFolder(const BenchOptions& o) { return o.table == "all" || o.csv.back() == '/' || fs::is_directory(o.csv); }
std::string csvPathFor(const BenchOptions& o, const std::string& table) {
  if (o.csv.empty()) return "";
  return csvIsFolder(o) ? (fs::path(o.csv) / (table + ".csv")).string() : o.csv;
}

}  // namespace

int runBench(const BenchOptions& o) {
  const auto& tables = benchTables();
  if (std::find(tables.begin(), tables.end(), o.table) == tables.end())
    throw InputError(fmt::format("gem bench --table {}: valid tables are {}", o.table, fmt::join(tables, ", ")));
  if (o.steps < 1 || o.steps > 10000000) throw InputError(fmt::format("gem bench --steps {}: from 1 to 10^7", o.steps));
  for (int b : o.blockSizes)
    if (b < 32 || b > 1024 || b % 32) throw InputError(fmt::format("gem bench --blocks {}: a multiple of 32 from 32 to 1024", b));
  for (int k : o.copyBackEvery)
    if (k < 1) throw InputError(fmt::format("gem bench --copy-back {}: must be at least 1", k));
  if (!o.blockSizes.empty() && o.table != "blocks" && o.table != "all")
    throw InputError("gem bench --blocks: applies to --table blocks (or all)");
  if (!o.copyBackEvery.empty() && o.table != "copyback" && o.table != "all")
    throw InputError("gem bench --copy-back: applies to --table copyback (or all)");
  for (const std::string& c : o.cases) parseCase(c);  // bad input before any timing
  if (o.threads < 1 || o.threads > 1024) throw InputError(fmt::format("gem bench --threads {}: from 1 to 1024", o.threads));
  g_cpuThreads = o.threads;
  for (const std::string& b : o.broadphases) Registry::global().broadphase(b);
  // Where the CSV goes, made and checked before any timing.
  if (!o.csv.empty()) {
    if (csvIsFolder(o))
      requireOutputFolder(o.csv, "gem bench --csv");
    else
      requireOutputFile(o.csv, "gem bench --csv");
  }

  CaseScenarios scenarios;
  if (o.table != "all") {
    runTable(TableRun{o, scenarios, csvPathFor(o, o.table)}, o.table);
    return 0;
  }
  if (!o.cases.empty() || !o.broadphases.empty())
    throw InputError("gem bench --table all: each table has its own cases and broadphases; name one table to choose them");
  const bool skipCuda = o.backends.empty() && !cudaUsable();
  const std::vector<std::string> all{"fields", "blocks", "copyback", "scaling", "intersection", "triangulation"};
  std::printf("gem bench --table all: %s\n", fmt::format("{}", fmt::join(all, ", ")).c_str());
  if (skipCuda)
    std::printf("** CUDA rows skipped: %s; the CPU rows and columns run **\n",
                findBackend("cuda") ? "no CUDA device found on this machine" : "this build has no CUDA backend");
  for (const std::string& name : all) {
    std::printf("\n== %s\n", name.c_str());
    std::fflush(stdout);
    runTable(TableRun{o, scenarios, csvPathFor(o, name), true, skipCuda}, name);
  }
  return 0;
}

}  // namespace gem
