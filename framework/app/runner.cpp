#include "framework/app/runner.hpp"

#include <unistd.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <csignal>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <functional>
#include <memory>
#include <stdexcept>

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "events/propulsion.hpp"
#include "framework/output/atomic_file.hpp"
#include "framework/output/checkpoint.hpp"
#include "framework/output/csv.hpp"
#include "framework/output/run_folder.hpp"
#include "framework/output/run_folder_lock.hpp"
#include "framework/api/errors.hpp"
#include "framework/field/ice_file.hpp"
#include "framework/output/ice_file_writer.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/row_text.hpp"
#include "framework/app/interrupt.hpp"
#include "framework/app/plugin_loader.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/step/stepper.hpp"
#include "framework/output/vtk_writer.hpp"

namespace gem {

namespace {

struct Accumulator {
  double sum = 0, min = INFINITY, max = -INFINITY;
  long count = 0;
  void add(double v) {
    sum += v, ++count;
    min = std::min(min, v), max = std::max(max, v);
  }
  Stats stats() const { return count ? Stats{min, sum / count, max, count} : Stats{}; }
};

// A finite double as summary.json has always written it, 9 significant digits (an integral value
// without a fraction: "100", not "100.0"); NaN and infinities, which JSON lacks, as null.
nlohmann::ordered_json jsonNumber(double v) {
  if (!std::isfinite(v)) return nullptr;
  // strtod, not stod: a subnormal value (below 2.2e-308) is read back as it is, where stod throws.
  const double rounded = std::strtod(fmt::format("{:.9g}", v).c_str(), nullptr);
  if (rounded == std::trunc(rounded) && std::fabs(rounded) < 1e15) return static_cast<std::int64_t>(rounded);
  return rounded;
}

nlohmann::ordered_json jsonStats(const Stats& s) {
  nlohmann::ordered_json out;
  out["min"] = s.count ? jsonNumber(s.min) : nullptr;
  out["mean"] = s.count ? jsonNumber(s.mean) : nullptr;
  out["max"] = s.count ? jsonNumber(s.max) : nullptr;
  return out;
}

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  return s >= 3600 ? fmt::format("{}h{:02}m", s / 3600, (s / 60) % 60) : fmt::format("{}m{:02}s", s / 60, s % 60);
}

void writeStateCsv(const std::filesystem::path& file, const World& w) {
  AtomicFile out(file);
  out.stream() << "id,kind,x,y,angle,vx,vy,omega,area,thickness,mass,vertices\n";
  // Every number with 9 significant digits, as printf's "%.9g" (row_text.hpp; a sweep writes a
  // state.csv a case, 10^4 to 10^6 numbers each).
  Vec2 v[kMaxVertices];
  std::string row, vertices;
  for (int i = 0; i < w.size(); ++i) {
    const int n = w.worldVertices(i, v);
    vertices.clear();
    for (int k = 0; k < n; ++k) {
      if (k) vertices += ' ';
      appendGeneral(vertices, static_cast<double>(v[k].x), 9);
      vertices += ' ';
      appendGeneral(vertices, static_cast<double>(v[k].y), 9);
    }
    row.clear();
    appendInteger(row, w.id[i]);
    row += ',';
    row += csvField(bodyKindName(w.kind[i]));
    for (const Real value : {w.x[i], w.y[i], w.angle[i], w.vx[i], w.vy[i], w.omega[i], w.area[i], w.thickness[i], w.mass[i]}) {
      row += ',';
      appendGeneral(row, static_cast<double>(value), 9);
    }
    row += ',';
    row += csvQuoted(vertices);
    row += '\n';
    out.stream() << row;
  }
  out.commit();
}

// The run-folder files of the registered record streams (impacts.csv, a plugin's): a new run and a
// resume clear what an earlier run left of them.
std::vector<std::string> recordFileNames() {
  std::vector<std::string> files;
  for (const RecordOutputEntry* output : Registry::global().recordOutputs()) files.push_back(output->file);
  return files;
}

}  // namespace

// summary.json through nlohmann-json, so that every string (a device name with quotes or
// backslashes) is escaped; the keys in the order docs/scenario.md 4.1 lists them.
std::string summaryJson(const RunSummary& s) {
  nlohmann::ordered_json j;
  j["gem_version"] = GEM_VERSION;
  j["completed"] = s.completed;
  j["stop_reason"] = s.stopReason;
  j["steps"] = s.steps;
  j["sim_time_s"] = jsonNumber(s.simTime);
  j["wall_time_s"] = jsonNumber(s.wallTime);
  j["real_time_factor"] = jsonNumber(s.wallTime > 0 ? s.simTime / s.wallTime : INFINITY);
  j["backend"] = s.backend;
  j["driver"] = s.driver;
  j["broadphase"] = s.broadphase;
  j["device"] = s.device;
  j["floes_initial"] = s.floesInitial;
  j["floes_final"] = s.floesFinal;
  j["floes_broken"] = s.floesBroken;
  j["ice_mass_initial_kg"] = jsonNumber(s.iceMassInitial);
  j["ice_mass_final_kg"] = jsonNumber(s.iceMassFinal);
  j["rubble_mass_kg"] = jsonNumber(s.rubbleMass);
  j["cases_on_device"] = s.casesOnDevice;
  // The record streams' totals (ship_impact's "impacts" and "impact_force_n").
  for (const RecordTotals& t : s.records) {
    if (!t.countKey.empty()) j[t.countKey] = t.count;
    if (!t.statisticKey.empty()) j[t.statisticKey] = jsonStats(t.statistic);
    if (!t.countInIceKey.empty()) j[t.countInIceKey] = t.countInIce;
    if (!t.statisticInIceKey.empty()) j[t.statisticInIceKey] = jsonStats(t.statisticInIce);
  }
  j["ship_speed"] = jsonStats(s.shipSpeed);
  j["net_thrust_n"] = jsonStats(s.netThrust);
  j["resistance_mean_n"] = s.netThrust.count ? jsonNumber(s.netThrust.mean) : nullptr;
  j["ship_speed_in_ice"] = jsonStats(s.shipSpeedInIce);
  j["resistance_in_ice_n"] = s.netThrustInIce.count ? jsonNumber(s.netThrustInIce.mean) : nullptr;
  // The layout GEM has always written (one key a line, the min/mean/max objects on theirs); every
  // key and value through nlohmann's dump, so strings are escaped, and invalid UTF-8 (a device
  // name cut mid-character) is replaced rather than thrown.
  const auto dump = [](const nlohmann::ordered_json& v) {
    return v.dump(-1, ' ', false, nlohmann::ordered_json::error_handler_t::replace);
  };
  std::string out = "{\n";
  size_t k = 0;
  for (const auto& [key, value] : j.items()) {
    std::string text;
    if (value.is_object()) {
      for (const auto& [name, inner] : value.items()) text += (text.empty() ? "{" : ", ") + dump(name) + ": " + dump(inner);
      text += "}";
    } else {
      text = dump(value);
    }
    out += "  " + dump(key) + ": " + text + (++k < j.size() ? ",\n" : "\n");
  }
  return out + "}\n";
}

namespace {

// One run's outputs, step by step (the observers, docs/model.md 8 phase 7): opened when it starts,
// a row per step, the summary when it ends, and what it wrote kept if it fails.
class ScenarioRun {
 public:
  // The stepper outlives the run (a case run together with others is stepped to the end even
  // when its outputs fail).
  // checkpoint: a checkpoint's payload (resumeScenario) to go on from, else null for a new run.
  ScenarioRun(const Scenario& scenario, Stepper& stepper, const std::string* checkpoint = nullptr)
      : m_scenario(scenario), m_stepper(&stepper), m_dir(scenario.output.dir), m_lock(m_dir) {
    Stepper& sim = *m_stepper;
    m_summary.backend = sim.backend();  // "auto" may have fallen back to the cpu
    m_summary.driver = sim.driver();
    m_summary.broadphase = scenario.broadphase;
    m_summary.outputDir = scenario.output.dir.string();
    m_summary.device = sim.device();
    const OutputSpec& out = scenario.output;
    m_frames = out.frameEvery > 0;
    const VesselSpec& vessel = scenario.vessel;
    m_thrust = Propulsion::Params{vessel.bollardThrust,
                                  vessel.bollardThrust / (vessel.openWaterSpeed * vessel.openWaterSpeed * vessel.openWaterSpeed)};
    if (checkpoint) {
      resumeFrom(*checkpoint);
      return;
    }
    m_summary.floesInitial = sim.hostWorld().count(BodyKind::Floe);
    m_summary.iceMassInitial = sim.hostWorld().floeMass();
    // What an earlier run left here goes (a stale summary or old frames must not sit beside this
    // run's files), and the scenario as read is recorded (scenario.toml).
    clearEarlierRun(m_dir, recordFileNames());
    std::vector<std::filesystem::path> environmentPlugins;
    for (const LoadedPlugin& plugin : loadedPlugins())
      if (plugin.fromEnvironment) environmentPlugins.push_back(plugin.path);
    recordScenario(m_dir, scenario, environmentPlugins);
    m_scenarioChecksum = checksumOf(recordedScenarioText());

    auto has = [&](const char* f) { return std::find(out.formats.begin(), out.formats.end(), f) != out.formats.end(); };
    if (m_frames && has("vtk")) m_vtk = std::make_unique<VtkSeriesWriter>(m_dir, out.vtkBinary);
    if (m_frames && has("ice")) m_ice = std::make_unique<IceFileWriter>(m_dir / "frames.ice");
    m_timeseries = std::make_unique<AtomicFile>(m_dir / "timeseries.csv");
    m_timeseries->stream() << "t,ship_x,ship_y,ship_heading,ship_speed,net_thrust,ice_force_x,contacts\n";
    // The record streams' files, from the events that own them (ship_impact: impacts.csv).
    for (const RecordOutputEntry* output : Registry::global().recordOutputs()) {
      const int stream = sim.records().streams().find(output->stream);
      if (stream < 0) continue;  // no event of this run opened it
      m_recordFiles.push_back(RecordFile{output, stream, std::make_unique<AtomicFile>(m_dir / output->file), {}, {}});
      m_recordFiles.back().file->stream() << output->header << "\n";
    }
    if (m_frames) writeFrames();
    // The stop rule's starting point: the field's extent (the domain, else the floes' bounding
    // box) and the vessel's reach about its centroid (its bounding radius).
    const World& w = sim.hostWorld();
    if (scenario.hasDomain) {
      m_fieldLow = {scenario.domain.x0, scenario.domain.y0};
      m_fieldHigh = {scenario.domain.x1, scenario.domain.y1};
    } else {
      for (int i = 0; i < w.size(); ++i) {
        if (w.kind[i] == BodyKind::Vessel) continue;
        m_fieldLow = {std::min(m_fieldLow.x, w.x[i] - w.radius[i]), std::min(m_fieldLow.y, w.y[i] - w.radius[i])};
        m_fieldHigh = {std::max(m_fieldHigh.x, w.x[i] + w.radius[i]), std::max(m_fieldHigh.y, w.y[i] + w.radius[i])};
      }
    }
    for (int i = 0; i < w.size(); ++i)
      if (w.kind[i] == BodyKind::Vessel) m_vesselReach = w.radius[i];
    m_lastVesselPosition = sim.vessel().position;
  }

  // The scenario's stop rule (simulation.stop_when) after the step just recorded: the reason the
  // run ends here, or nullptr to go on.
  const char* stopRuleReached() {
    if (m_scenario.stopWhen == "duration") return nullptr;
    const VesselSample v = m_stepper->vessel();
    if (!v.present) return nullptr;
    if (m_scenario.stopWhen == "distance") {
      m_travelled += norm(v.position - m_lastVesselPosition);  // the path, step by step
      m_lastVesselPosition = v.position;
      return m_travelled >= m_scenario.stopDistance ? "distance" : nullptr;
    }
    // vessel_left_field: the hull's bounding circle overlaps the field's box, then no longer does.
    // A vessel that starts in open water before the field has not yet reached it, so it runs on.
    const bool overField = v.position.x + m_vesselReach >= m_fieldLow.x && v.position.x - m_vesselReach <= m_fieldHigh.x &&
                           v.position.y + m_vesselReach >= m_fieldLow.y && v.position.y - m_vesselReach <= m_fieldHigh.y;
    if (overField) m_reachedField = true;
    return m_reachedField && !overField ? "vessel_left_field" : nullptr;
  }

  // The outputs of step k (0-based), which sim().step() has just run.
  void record(long k) {
    Stepper& sim = *m_stepper;
    const Scenario& scenario = m_scenario;
    checkFinite(k);
    const VesselSample vessel = sim.vessel();
    // The transit of the field (thesis 6.2.1.3, 6.2.2.2 L1268): the whole hull inside the field's x
    // range at the end of the step. The speed, the resistance and the in-ice record totals use it.
    const bool inIce = vessel.present && scenario.hasDomain && vessel.position.x - scenario.vessel.length / 2 >= scenario.domain.x0 &&
                       vessel.position.x + scenario.vessel.length / 2 <= scenario.domain.x1;
    std::string row;
    for (RecordFile& f : m_recordFiles) {
      const StepRecords& records = sim.records();
      for (int r = 0; r < records.rowCount(f.stream); ++r) {
        const void* record = records.record(f.stream, r);
        row.clear();  // a writeRow that appends still writes its own row only
        f.output->writeRow(record, row);
        f.file->stream() << row;
        const double value = f.output->statisticValue ? f.output->statisticValue(record) : 0;
        f.statistic.add(value);
        if (inIce) f.statisticInIce.add(value);
      }
    }
    const Vec2 forward{std::cos(vessel.heading), std::sin(vessel.heading)};
    const Real surge = dot(vessel.velocity, forward);
    if (vessel.present) {
      m_speed.add(surge);
      m_netThrust.add(Propulsion::netThrust(m_thrust, surge));
      if (inIce) {
        m_speedInIce.add(surge);
        m_netThrustInIce.add(Propulsion::netThrust(m_thrust, surge));
      }
    }
    if ((k + 1) % scenario.output.timeseriesEvery == 0) {
      // t with 6 significant digits, the vessel's columns with 9, as printf's "%g" (row_text.hpp:
      // fmt's fixed precision was a quarter of the batched load study's host time).
      row.clear();
      appendGeneral(row, static_cast<double>(sim.time()), 6);
      if (vessel.present) {
        const double columns[] = {vessel.position.x,     vessel.position.y, vessel.heading, surge, Propulsion::netThrust(m_thrust, surge),
                                  sim.vesselIceForce().x};
        requireFiniteRow(k, columns);
        for (double c : columns) {
          row += ',';
          appendGeneral(row, c, 9);
        }
        row += ',';
      } else {
        row += ",,,,,,,";
      }
      appendInteger(row, sim.contactCount());
      row += '\n';
      m_timeseries->stream() << row;
    }
    if (m_frames && (k + 1) % scenario.output.frameEvery == 0) writeFrames();
  }

  // A timeseries.csv row whose derived values are not finite (a finite but enormous surge makes
  // the net thrust infinite) stops the run before the row is written, as a non-finite state does.
  void requireFiniteRow(long k, const double (&columns)[6]) const {
    static const char* const names[] = {"ship_x", "ship_y", "ship_heading", "ship_speed", "net_thrust", "ice_force_x"};
    for (int c = 0; c < 6; ++c)
      if (!std::isfinite(columns[c]))
        throw std::runtime_error(
            fmt::format("step {} (t = {:.6g} s): the vessel's {} is no longer finite (ship speed {} m/s); the run stops here", k + 1,
                        m_stepper->time(), names[c], columns[3]));
  }

  // A non-finite state (a floe at 1e300 m/s, say) stops the run, naming the body and the step,
  // before any NaN reaches a file: exit 1, what was written so far kept whole. The CPU's world is
  // checked every step (a pass over the bodies, cheap beside a step); a device backend's vessel
  // every step and its whole world at every frame and at the end, when it is on the host anyway.
  void checkFinite(long k) {
    Stepper& sim = *m_stepper;
    const VesselSample v = sim.vessel();
    const bool fullCheck = sim.backend() == "cpu" || (m_frames && (k + 1) % m_scenario.output.frameEvery == 0) || k + 1 == m_scenario.steps;
    auto finite = [](Real a) { return std::isfinite(a); };
    if (v.present && !(finite(v.position.x) && finite(v.position.y) && finite(v.heading) && finite(v.velocity.x) && finite(v.velocity.y)))
      throw std::runtime_error(
          fmt::format("step {} (t = {:.6g} s): the vessel's state is no longer finite; the run stops here", k + 1, sim.time()));
    if (!fullCheck) return;
    // The body's whole state, the angle and angular velocity too (an infinite spin once showed
    // only finite x, y, vx and vy).
    const std::string notFinite = nonFiniteState(sim.hostWorld(), k + 1, sim.time());
    if (!notFinite.empty()) throw std::runtime_error(notFinite + "; the run stops here");
  }

  // The run ends after stepsRun steps, for the reason given (the duration, a stop rule, or a
  // signal: then completed is false): the last files, state.csv, and summary.json last of all.
  RunSummary finish(double wallTime, long stepsRun, const std::string& reason = "duration", bool completed = true) {
    Stepper& sim = *m_stepper;
    m_summary.wallTime = m_wallBefore + wallTime;
    m_summary.steps = stepsRun;
    m_summary.stopReason = reason;
    m_summary.completed = completed;
    m_summary.simTime = sim.time();
    const World& world = sim.hostWorld();
    m_summary.floesFinal = world.count(BodyKind::Floe);
    m_summary.iceMassFinal = world.floeMass();
    m_summary.rubbleMass = sim.rubbleMass();
    m_summary.floesBroken = sim.floesBroken();
    m_summary.shipSpeed = m_speed.stats();
    m_summary.records.clear();
    for (const RecordFile& f : m_recordFiles)
      m_summary.records.push_back(RecordTotals{f.output->countKey, f.output->statisticKey, f.statistic.count, f.statistic.stats(),
                                               f.output->countInIceKey, f.output->statisticInIceKey, f.statisticInIce.count,
                                               f.statisticInIce.stats()});
    m_summary.netThrust = m_netThrust.stats();
    m_summary.shipSpeedInIce = m_speedInIce.stats();
    m_summary.netThrustInIce = m_netThrustInIce.stats();
    closeFiles();
    writeStateCsv(m_dir / "state.csv", world);
    writeFileAtomically(m_dir / "summary.json", summaryJson(m_summary));
    // A whole run needs no checkpoint; one a signal stopped keeps it (written just before), to
    // go on from with gem run --resume.
    std::error_code ignored;
    if (completed) std::filesystem::remove(m_dir / kCheckpointFile, ignored);
    return m_summary;
  }

  // output.checkpoint_every: whether a checkpoint is due after `stepsRun` steps (never after the
  // last: the run is about to end whole).
  bool checkpointDue(long stepsRun, double wallSeconds) const {
    const OutputSpec& out = m_scenario.output;
    if (stepsRun >= m_scenario.steps) return false;
    if (out.checkpointEverySteps > 0 && stepsRun % out.checkpointEverySteps == 0) return true;
    return out.checkpointEverySeconds > 0 && wallSeconds - m_lastCheckpointWall >= out.checkpointEverySeconds;
  }

  // RUN_DIR/checkpoint.gem, after the step just recorded: the stepper's state, the totals, and
  // where each output file stands (flushed first, so that the bytes it vouches for are in them).
  void saveCheckpoint(double wallSeconds) {
    Stepper& sim = *m_stepper;
    BinaryWriter out;
    out.put(sim.backend()), out.put(sim.driver()), out.put(m_scenarioChecksum);
    putStepperState(out, sim.saveState());
    out.put(m_wallBefore + wallSeconds), out.put(m_summary.floesInitial), out.put(m_summary.iceMassInitial);
    out.put(m_speed), out.put(m_netThrust), out.put(m_speedInIce), out.put(m_netThrustInIce);
    out.put(m_fieldLow), out.put(m_fieldHigh), out.put(m_vesselReach), out.put(m_reachedField), out.put(m_lastVesselPosition);
    out.put(m_travelled);
    out.put(m_timeseries->tempPath().filename().string()), out.put(m_timeseries->flushedSize());
    out.put(static_cast<std::uint64_t>(m_recordFiles.size()));
    for (RecordFile& f : m_recordFiles) {
      out.put(f.output->file), out.put(f.file->tempPath().filename().string()), out.put(f.file->flushedSize());
      out.put(f.statistic), out.put(f.statisticInIce);
    }
    out.put(static_cast<bool>(m_vtk));
    if (m_vtk) m_vtk->save(out);
    out.put(static_cast<bool>(m_ice));
    if (m_ice) m_ice->save(out);
    writeCheckpointFile(m_dir / kCheckpointFile, out.bytes());
    m_lastCheckpointWall = wallSeconds;
  }

  // The run failed: keep what it produced (whole rows only), but write no summary.json.
  void abandon() { closeFiles(); }

  RunSummary& summary() { return m_summary; }

 private:
  void writeFrames() {
    Stepper& sim = *m_stepper;
    if (m_vtk) m_vtk->addFrame(sim.hostWorld(), sim.time(), sim.contactForces());
    if (m_ice) m_ice->addFrame(sim.hostWorld(), sim.time());
  }
  // The state saveCheckpoint wrote, read back in its order: the stepper's, the totals, and each
  // output file cut to where the checkpoint left it.
  void resumeFrom(const std::string& payload) {
    Stepper& sim = *m_stepper;
    const std::string name = (m_dir / kCheckpointFile).string();
    BinaryReader in(payload, name);
    in.get<std::string>(), in.get<std::string>();  // the backend and driver, which resumeScenario chose by
    in.get(m_scenarioChecksum);
    if (m_scenarioChecksum != checksumOf(recordedScenarioText()))
      throw InputError(fmt::format("{}: {} changed since the checkpoint was written; a run resumes only with the scenario it ran", name,
                                   (m_dir / "scenario.toml").string()));
    StepperState state;
    getStepperState(in, state);
    sim.restoreState(state);
    in.get(m_wallBefore), in.get(m_summary.floesInitial), in.get(m_summary.iceMassInitial);
    in.get(m_speed), in.get(m_netThrust), in.get(m_speedInIce), in.get(m_netThrustInIce);
    in.get(m_fieldLow), in.get(m_fieldHigh), in.get(m_vesselReach), in.get(m_reachedField), in.get(m_lastVesselPosition);
    in.get(m_travelled);
    const std::filesystem::path timeseries = m_dir / "timeseries.csv";
    const auto timeseriesTemp = in.get<std::string>();
    m_timeseries = std::make_unique<AtomicFile>(timeseries, earlierTempPath(timeseries, timeseriesTemp), in.get<std::uint64_t>());
    const auto files = in.get<std::uint64_t>();
    std::vector<const RecordOutputEntry*> outputs;
    for (const RecordOutputEntry* output : Registry::global().recordOutputs())
      if (sim.records().streams().find(output->stream) >= 0) outputs.push_back(output);
    if (files != outputs.size()) throw InputError(name + ": damaged (its record files are not this run's)");
    for (const RecordOutputEntry* output : outputs) {
      const auto file = in.get<std::string>();
      if (file != output->file) throw InputError(name + ": damaged (its record files are not this run's)");
      const std::filesystem::path path = m_dir / file;
      const auto temp = in.get<std::string>();
      const auto bytes = in.get<std::uint64_t>();
      m_recordFiles.push_back(RecordFile{output,
                                         sim.records().streams().find(output->stream),
                                         std::make_unique<AtomicFile>(path, earlierTempPath(path, temp), bytes),
                                         {},
                                         {}});
      in.get(m_recordFiles.back().statistic), in.get(m_recordFiles.back().statisticInIce);
    }
    if (in.get<bool>()) m_vtk = std::make_unique<VtkSeriesWriter>(m_dir, m_scenario.output.vtkBinary, in);
    if (in.get<bool>()) m_ice = std::make_unique<IceFileWriter>(m_dir / "frames.ice", in);
    if (!in.atEnd()) throw InputError(name + ": damaged (bytes past its end)");
    // What the stopped run wrote at its end (summary, state, plots) describes a run that is not
    // over: gone, once the resume is sure to go ahead.
    clearRunEnd(m_dir, recordFileNames());
  }

  // scenario.toml as the run folder holds it (a checkpoint belongs to that text).
  std::string recordedScenarioText() const {
    std::ifstream in(m_dir / "scenario.toml", std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
  }

  void closeFiles() {
    m_timeseries->commit();
    for (RecordFile& f : m_recordFiles) f.file->commit();
    if (m_vtk) m_vtk->finish();
    if (m_ice) m_ice->finish();
  }

  const Scenario& m_scenario;
  Stepper* m_stepper;
  std::filesystem::path m_dir;
  RunSummary m_summary;
  bool m_frames = false;
  std::unique_ptr<VtkSeriesWriter> m_vtk;
  std::unique_ptr<IceFileWriter> m_ice;
  RunFolderLock m_lock;  // before any file of the folder is opened
  std::unique_ptr<AtomicFile> m_timeseries;
  struct RecordFile {
    const RecordOutputEntry* output;
    int stream;
    std::unique_ptr<AtomicFile> file;
    Accumulator statistic;       // of output->statisticValue, or only the count
    Accumulator statisticInIce;  // the same over the transit (the in-ice window)
  };
  std::vector<RecordFile> m_recordFiles;
  Propulsion::Params m_thrust{};
  Accumulator m_speed, m_netThrust, m_speedInIce, m_netThrustInIce;
  // The stop rule's state (stopRuleReached).
  Vec2 m_fieldLow{INFINITY, INFINITY}, m_fieldHigh{-INFINITY, -INFINITY};
  Real m_vesselReach = 0;
  bool m_reachedField = false;
  Vec2 m_lastVesselPosition{0, 0};
  double m_travelled = 0;
  // Checkpoints: the wall seconds of the run's earlier parts (a resumed run's), the last
  // checkpoint's wall time in this part, and the scenario.toml they belong to.
  double m_wallBefore = 0, m_lastCheckpointWall = 0;
  std::uint32_t m_scenarioChecksum = 0;
};

// "SIGINT", "SIGTERM": the stop reason of a run a signal ended.
std::string signalName(int signal) {
  return signal == SIGINT ? "SIGINT" : signal == SIGTERM ? "SIGTERM" : signal == SIGHUP ? "SIGHUP" : fmt::format("signal {}", signal);
}

}  // namespace

namespace {

// The steps of a run, new or resumed from a checkpoint's payload, with its outputs.
RunSummary runSteps(const Scenario& scenario, const RunOptions& options, const std::string* checkpoint) {
  const std::unique_ptr<Stepper> stepper = makeStepper(scenario);  // bad input throws here, before anything is written
  ScenarioRun run(scenario, *stepper, checkpoint);
  if (options.started) options.started(*stepper);
  Stepper& sim = *stepper;
  const auto start = std::chrono::steady_clock::now();
  auto lastProgress = start;
  auto wallSeconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const long firstStep = sim.stepIndex();  // 0, or the checkpoint's step
  long stepsRun = firstStep;
  const char* reason = "duration";
  try {
    for (long k = firstStep; k < scenario.steps; ++k) {
      stopIfInterrupted(k);
      sim.step();
      run.record(k);
      stepsRun = k + 1;
      const char* stop = run.stopRuleReached();
      if (!stop && options.checkpoints && sim.stateOnHost() && run.checkpointDue(stepsRun, wallSeconds()))
        run.saveCheckpoint(wallSeconds());
      if (options.progress && !options.quiet) {
        const auto now = std::chrono::steady_clock::now();
        if (now - lastProgress > std::chrono::milliseconds(250) || k + 1 == scenario.steps || stop) {
          lastProgress = now;
          const double wall = std::chrono::duration<double>(now - start).count();
          const double rate = (k + 1 - firstStep) / std::max(wall, 1e-9);
          std::fprintf(stderr, "\r  step %ld/%ld  t = %.1f s  %.0f steps/s  %.0fx real time  ETA %s   ", k + 1, scenario.steps,
                       static_cast<double>(sim.time()), rate, rate * scenario.dt, formatDuration((scenario.steps - k - 1) / rate).c_str());
          std::fflush(stderr);
        }
      }
      if (stop) {
        reason = stop;
        // A device backend has its state on the host only between copy-back batches: the steps it
        // has already run past the rule's (copy_back_every at most) are recorded too, as after
        // Ctrl-C, so that every file and the summary stop at one step.
        while (!sim.stateOnHost() && stepsRun < scenario.steps) {
          sim.step();
          run.record(stepsRun);
          ++stepsRun;
        }
        break;
      }
    }
  } catch (const Interrupted& e) {
    // Ctrl-C or SIGTERM between two steps: a checkpoint of the steps run (gem run --resume goes
    // on from it), every file closed whole, and a summary that says it is not the whole run. A
    // device backend has its state on the host only between copy-back batches: the steps it has
    // already run (copy_back_every at most) are recorded first, so that every file stops at one step.
    try {
      while (!sim.stateOnHost() && stepsRun < scenario.steps) {
        sim.step();
        run.record(stepsRun);
        ++stepsRun;
      }
      if (options.checkpoints) run.saveCheckpoint(wallSeconds());
    } catch (const std::exception& failed) {
      std::fprintf(stderr, "gem: no checkpoint written: %s\n", failed.what());
    }
    run.finish(wallSeconds(), stepsRun, signalName(e.signal()), false);
    stopIfInterrupted(stepsRun);  // its message names the step the files stop at
    throw;
  } catch (...) {
    run.abandon();
    throw;
  }
  if (options.progress && !options.quiet) std::fprintf(stderr, "\n");
  return run.finish(wallSeconds(), stepsRun, reason);
}

}  // namespace

RunSummary runScenario(const Scenario& scenario, const RunOptions& options) { return runSteps(scenario, options, nullptr); }

ScenarioCheck checkScenarioFirstStep(const Scenario& scenario) {
  resolveBackend(scenario.backend);
  CpuStepper sim(scenario);  // builds the field, checks every body and overlap, parses every event
  // One step on the CPU, written nowhere: a scenario whose values pass every range but whose first
  // step is not finite (gem run would stop at step 1) is refused with gem run's words.
  sim.setDeliverLogs(false);
  sim.step();
  const std::string notFinite = nonFiniteState(sim.world(), 1, sim.time());
  if (!notFinite.empty()) throw InputError(fmt::format("{}: {}; gem run stops there", scenario.fileName, notFinite));
  return ScenarioCheck{sim.world().size(), sim.world().count(BodyKind::Floe), sim.events().size()};
}

RunSummary resumeScenario(Scenario scenario, const RunOptions& options) {
  const std::filesystem::path file = scenario.output.dir / kCheckpointFile;
  const std::string payload = readCheckpointFile(file);
  // The backend and driver that wrote it: another one's arithmetic would not give the same files.
  BinaryReader in(payload, file.string());
  const auto backend = in.get<std::string>(), driver = in.get<std::string>();
  const BackendEntry* entry = findBackend(backend);
  if (!entry || !entry->available())
    throw InputError(fmt::format("{}: the run was on the {} backend, which {}; it resumes only where that backend runs", file.string(),
                                 backend, entry ? "has no device here" : "this gem was built without"));
  scenario.backend = backend;
  if (backend == "cuda") scenario.cudaDriver = driver;
  return runSteps(scenario, options, &payload);
}

std::vector<std::string> runScenariosTogether(const std::vector<const Scenario*>& scenarios, std::vector<std::unique_ptr<Stepper>> steppers,
                                              const std::function<void(long step, long steps)>& progress) {
  if (scenarios.size() != steppers.size() || scenarios.empty())
    throw std::invalid_argument("runScenariosTogether: one stepper per scenario, one scenario at least");
  const long steps = scenarios.front()->steps;
  for (const Scenario* s : scenarios)
    if (s->steps != steps) throw std::invalid_argument("runScenariosTogether: the scenarios must have the same number of steps");
  const size_t count = scenarios.size();
  std::vector<std::string> failures(count);
  std::vector<std::unique_ptr<ScenarioRun>> runs(count);
  for (size_t i = 0; i < count; ++i) {
    try {
      runs[i] = std::make_unique<ScenarioRun>(*scenarios[i], *steppers[i]);
    } catch (const std::exception& e) {
      failures[i] = e.what();
    }
  }
  // A stepper left without its run (its outputs could not be opened) is still stepped: it shares
  // the others' steps.
  const auto start = std::chrono::steady_clock::now();
  auto wallSeconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  // A case whose stop rule fired is finished there (its files and summary written) and is still
  // stepped with the others, its outputs no longer recorded. On a device backend that is at the end
  // of the copy-back batch the rule fired in (the state is on the host only there): the case
  // records the steps up to it, as a run alone does (runSteps).
  std::vector<char> done(count, 0);
  std::vector<const char*> stopping(count, nullptr);
  auto finishCase = [&](size_t i, long stepsRun, const std::string& reason, bool completed) {
    try {
      runs[i]->summary().casesOnDevice = static_cast<int>(count);
      runs[i]->finish(wallSeconds(), stepsRun, reason, completed);
    } catch (const std::exception& e) {
      failures[i] = e.what();
    }
    done[i] = 1;
  };
  auto running = [&](size_t i) { return runs[i] && failures[i].empty() && !done[i]; };
  long k = 0;
  try {
    for (; k < steps; ++k) {
      stopIfInterrupted(k);
      // Every case's step k before any case's step k + 1; then each one's outputs.
      for (size_t i = 0; i < count; ++i) steppers[i]->step();
      bool anyRunning = false;
      for (size_t i = 0; i < count; ++i) {
        if (!running(i)) continue;
        try {
          runs[i]->record(k);
          if (!stopping[i]) stopping[i] = runs[i]->stopRuleReached();
          if (stopping[i] && steppers[i]->stateOnHost()) finishCase(i, k + 1, stopping[i], true);
        } catch (const std::exception& e) {
          failures[i] = e.what();
          runs[i]->abandon();
        }
        anyRunning = anyRunning || running(i);
      }
      if (progress) progress(k + 1, steps);
      if (!anyRunning) break;
    }
  } catch (const Interrupted& e) {
    // Every case still running keeps its whole files and a summary saying it did not complete. A
    // device backend has its cases' state on the host only between copy-back batches: the steps
    // the device has already run are recorded first, as a run alone does (runSteps).
    auto onHost = [&] {
      for (const auto& s : steppers)
        if (!s->stateOnHost()) return false;
      return true;
    };
    try {
      for (; k < steps && !onHost(); ++k) {
        for (size_t i = 0; i < count; ++i) steppers[i]->step();
        for (size_t i = 0; i < count; ++i) {
          if (!running(i)) continue;
          try {
            runs[i]->record(k);
          } catch (const std::exception& failed) {  // this case's own fault (a state no longer finite)
            failures[i] = failed.what();
            runs[i]->abandon();
          }
        }
      }
    } catch (const std::exception& failed) {
      // The shared device state failed: the cases still running fail with it, as below.
      for (size_t i = 0; i < count; ++i)
        if (running(i)) {
          failures[i] = fmt::format("step {} of cases run together on one device: {}", k, failed.what());
          runs[i]->abandon();
        }
    }
    for (size_t i = 0; i < count; ++i)
      if (running(i)) finishCase(i, k, stopping[i] ? stopping[i] : signalName(e.signal()), stopping[i] != nullptr);
    throw;
  } catch (const std::exception& e) {
    // The shared device state failed: every case that was still running fails with it.
    for (size_t i = 0; i < count; ++i) {
      if (!running(i)) continue;
      failures[i] = fmt::format("step {} of cases run together on one device: {}", k, e.what());
      runs[i]->abandon();
    }
    return failures;
  }
  for (size_t i = 0; i < count; ++i)
    if (running(i)) finishCase(i, steps, stopping[i] ? stopping[i] : "duration", true);
  return failures;
}

}  // namespace gem
