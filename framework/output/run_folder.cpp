#include "framework/output/run_folder.hpp"

#include <unistd.h>

#include <algorithm>
#include <functional>
#include <sstream>

#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"
#include "framework/output/checkpoint.hpp"

namespace gem {

namespace {
using Predicate = std::function<bool(const std::filesystem::path&)>;
void removePlots(const std::filesystem::path& dir, const Predicate& staleTemporary);

// The outputs of a run that the next run in the folder replaces (besides the record streams' files,
// the frames and the plots). gem-run.toml: GEM 0.2's name for scenario.toml.
const std::vector<std::string>& runOutputs() {
  static const std::vector<std::string> files{"summary.json", "state.csv",    "timeseries.csv", "frames.pvd",   "frames.ice",
                                              "gem.log",      "gem-run.toml", kMovieFile,       kCheckpointFile};
  return files;
}

// A temporary of another process (an earlier run that was killed; never this run's own): the name
// of a file GEM writes there (`isGemFile`) followed by ".tmp-" and a process id, as AtomicFile
// names them. A user's file stays, whatever its name (important.tmp-1, notes.tmp-2.txt).
bool staleTemporaryOf(const std::filesystem::path& p, const std::function<bool(const std::string&)>& isGemFile) {
  static const std::string own = std::to_string(::getpid());
  const std::string name = p.filename().string();
  const size_t at = name.rfind(".tmp-");
  if (at == std::string::npos || at == 0) return false;
  const std::string pid = name.substr(at + 5);
  if (pid.empty() || pid.find_first_not_of("0123456789") != std::string::npos || pid == own) return false;
  return isGemFile(name.substr(0, at));
}

// A frame file of frames/: frame_ and digits, .vtp.
bool isFrameFile(const std::string& name) {
  return name.size() > 10 && name.rfind("frame_", 0) == 0 && name.compare(name.size() - 4, 4, ".vtp") == 0 &&
         name.find_first_not_of("0123456789", 6) == name.size() - 4;
}

// Every stale temporary in the folder (of its files and the record streams', `recordFiles`) and in
// frames/ (plots/ is removePlots').
void removeStaleTemporaries(const std::filesystem::path& dir, const std::vector<std::string>& recordFiles) {
  namespace fs = std::filesystem;
  std::error_code ec;
  auto isRunFile = [&](const std::string& name) {
    // scenario.toml and a sweep's case.toml are written the same way, though never removed;
    // frames.ice's writer keeps its frames in frames.ice.frames.tmp-PID (ice_file_writer.cpp).
    return name == "scenario.toml" || name == "case.toml" || name == "frames.ice.frames" ||
           std::find(runOutputs().begin(), runOutputs().end(), name) != runOutputs().end() ||
           std::find(recordFiles.begin(), recordFiles.end(), name) != recordFiles.end();
  };
  for (const bool frames : {false, true}) {
    const fs::path folder = frames ? dir / "frames" : dir;
    if (!fs::is_directory(folder, ec)) continue;
    for (const auto& entry : fs::directory_iterator(folder, ec))
      if (entry.is_regular_file(ec) && staleTemporaryOf(entry.path(), frames ? std::function<bool(const std::string&)>(isFrameFile)
                                                                             : std::function<bool(const std::string&)>(isRunFile)))
        fs::remove(entry.path(), ec);
  }
}

// A stale temporary of a plot (plots/).
bool stalePlotTemporary(const std::filesystem::path& p) {
  return staleTemporaryOf(p, [](const std::string& name) {
    for (const char* plot : kRunPlotNames)
      for (const char* extension : {".svg", ".png"})
        if (name == std::string(plot) + extension) return true;
    return false;
  });
}
}  // namespace

void clearEarlierRun(const std::filesystem::path& dir, const std::vector<std::string>& recordFiles) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // scenario.toml is not removed: it is rewritten whole by recordScenario (and may be the very file
  // this run reads).
  for (const std::string& f : runOutputs()) fs::remove(dir / f, ec);
  for (const std::string& f : recordFiles) fs::remove(dir / f, ec);
  removeStaleTemporaries(dir, recordFiles);
  const fs::path frames = dir / "frames";
  if (fs::is_directory(frames, ec)) {
    for (const auto& entry : fs::directory_iterator(frames, ec))
      if (entry.path().extension() == ".vtp") fs::remove(entry.path(), ec);
    if (fs::is_empty(frames, ec)) fs::remove(frames, ec);
  }
  removePlots(dir, stalePlotTemporary);
}

void clearRunEnd(const std::filesystem::path& dir, const std::vector<std::string>& recordFiles) {
  std::error_code ec;
  for (const char* f : {"summary.json", "state.csv", kMovieFile}) std::filesystem::remove(dir / f, ec);
  // Called once every file the resume continues is adopted: what temporaries are left are the
  // killed run's half-written ones (a checkpoint cut by kill -9 while it was being written).
  removePlots(dir, stalePlotTemporary);
  removeStaleTemporaries(dir, recordFiles);
}

namespace {

// The old plots describe the old run: gone, whether or not this run makes new ones (--no-plots).
void removePlots(const std::filesystem::path& dir, const Predicate& staleTemporary) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path plots = dir / "plots";
  if (fs::is_directory(plots, ec)) {
    for (const char* name : kRunPlotNames)
      for (const char* extension : {".svg", ".png"}) fs::remove(plots / (std::string(name) + extension), ec);
    for (const auto& entry : fs::directory_iterator(plots, ec))
      if (staleTemporary(entry.path())) fs::remove(entry.path(), ec);
    if (fs::is_empty(plots, ec)) fs::remove(plots, ec);
  }
}

// Copies into `into` every key of `from` it does not have, tables merged key by key and arrays of
// tables ([[floes]]) element by element, by index.
void addMissing(toml::table& into, const toml::table& from) {
  for (const auto& [key, value] : from) {
    if (!into.contains(key)) {
      into.insert(key, value);
    } else if (const toml::table* sub = value.as_table(); sub && into.get(key)->is_table()) {
      addMissing(*into.get(key)->as_table(), *sub);
    } else if (const toml::array* elements = value.as_array(); elements && into.get(key)->is_array()) {
      toml::array& intoElements = *into.get(key)->as_array();
      for (size_t k = 0; k < elements->size() && k < intoElements.size(); ++k)
        if (const toml::table* element = elements->get(k)->as_table(); element && intoElements.get(k)->is_table())
          addMissing(*intoElements.get(k)->as_table(), *element);
    }
  }
}

}  // namespace

void recordScenario(const std::filesystem::path& dir, const Scenario& scenario, const std::vector<std::filesystem::path>& morePlugins) {
  namespace fs = std::filesystem;
  std::error_code ec;
  toml::table root = scenario.root;
  // Every key as it took effect, the defaults the scenario left out included: those of its tables
  // (loadScenario) and of every event's parameters (the stepper). Only the keys the choices made
  // read are there (no stop_distance unless stop_when = "distance", no generator settings beside
  // a .ice field, the size keys of one generator only), so the record loads as the scenario did.
  if (scenario.defaultsTaken) addMissing(root, *scenario.defaultsTaken);
  auto table = [&](const char* name) -> toml::table& {
    if (!root.contains(name)) root.insert(name, toml::table{});
    return *root.get(name)->as_table();
  };
  table("simulation").insert_or_assign("seed", static_cast<std::int64_t>(scenario.seed));
  // The steps this run takes, whatever set them (duration, --steps, --duration).
  table("simulation").erase("duration");
  table("simulation").insert_or_assign("steps", static_cast<std::int64_t>(scenario.steps));
  // The [simulation] keys as this run has them, whatever set them ("auto" stays "auto": the backend
  // it picked is in summary.json and gem.log).
  toml::table& sim = table("simulation");
  sim.insert_or_assign("dt", static_cast<double>(scenario.dt));
  sim.insert_or_assign("backend", scenario.backend);
  sim.insert_or_assign("broadphase", scenario.broadphase);
  sim.insert_or_assign("threads", static_cast<std::int64_t>(scenario.threads));
  sim.insert_or_assign("cuda_driver", scenario.cudaDriver);
  sim.insert_or_assign("stop_when", scenario.stopWhen);
  if (scenario.stopWhen == "distance") sim.insert_or_assign("stop_distance", static_cast<double>(scenario.stopDistance));
  table("output").insert_or_assign("dir", scenario.output.dir.string());
  if (scenario.fieldKind == "file") table("field").insert_or_assign("file", scenario.fieldFile.lexically_normal().string());
  if (!morePlugins.empty()) {
    if (!root.contains("plugins")) root.insert("plugins", toml::array{});
    if (toml::array* listed = root.get("plugins")->as_array()) {
      for (const fs::path& plugin : morePlugins) {
        bool already = false;
        for (const toml::node& entry : *listed)
          if (const toml::table* t = entry.as_table())
            if (const auto path = t->get_as<std::string>("path"); path && fs::equivalent(fs::path(path->get()), plugin, ec)) already = true;
        if (!already) listed->push_back(toml::table{{"path", plugin.string()}, {"override", false}});
      }
    }
  }
  std::ostringstream out;
  out << "# The scenario of this run as gem read it: " << scenario.file.string() << "\n";
  // An override's value may span lines (a sweep's hull vertices): each line stays a comment, or
  // the rest of it would be read as TOML.
  for (const std::string& o : scenario.overrides) {
    std::string commented;
    for (const char c : o) commented += c == '\n' ? std::string("\n#   ") : std::string(1, c);
    out << "# --set " << commented << "\n";
  }
  out << "# gem " << GEM_VERSION << "; `gem run scenario.toml` repeats the run.\n\n";
  out << toml::toml_formatter{root, toml::toml_formatter::default_flags & ~toml::format_flags::indentation} << "\n";
  // A scenario kept in its own run folder under this name is the user's file: never overwritten.
  if (fs::equivalent(dir / "scenario.toml", scenario.file, ec)) return;
  writeFileAtomically(dir / "scenario.toml", out.str());
}

}  // namespace gem
