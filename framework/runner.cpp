#include "framework/runner.hpp"

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <memory>

#include <fmt/format.h>

#include "events/propulsion.hpp"
#include "framework/atomic_file.hpp"
#include "framework/errors.hpp"
#include "framework/ice_file.hpp"
#include "framework/stepper.hpp"
#include "framework/vtk_writer.hpp"

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

std::string jsonNumber(double v) { return std::isfinite(v) ? fmt::format("{:.9g}", v) : "null"; }

std::string jsonStats(const Stats& s) {
  if (s.count == 0) return R"({"min": null, "mean": null, "max": null})";
  return fmt::format(R"({{"min": {}, "mean": {}, "max": {}}})", jsonNumber(s.min), jsonNumber(s.mean), jsonNumber(s.max));
}

std::string formatDuration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  return s >= 3600 ? fmt::format("{}h{:02}m", s / 3600, (s / 60) % 60) : fmt::format("{}m{:02}s", s / 60, s % 60);
}

void writeStateCsv(const std::filesystem::path& file, const World& w) {
  AtomicFile out(file);
  out.stream() << "id,kind,x,y,angle,vx,vy,omega,area,thickness,mass,vertices\n";
  Vec2 v[kMaxVertices];
  for (int i = 0; i < w.size(); ++i) {
    const int n = w.worldVertices(i, v);
    std::string vertices;
    for (int k = 0; k < n; ++k) vertices += fmt::format("{}{:.9g} {:.9g}", k ? " " : "", v[k].x, v[k].y);
    out.stream() << fmt::format("{},{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},\"{}\"\n", w.id[i],
                                bodyKindName(w.kind[i]), w.x[i], w.y[i], w.angle[i], w.vx[i], w.vy[i], w.omega[i],
                                w.area[i], w.thickness[i], w.mass[i], vertices);
  }
  out.commit();
}

}  // namespace

std::string summaryJson(const RunSummary& s) {
  return fmt::format(
      "{{\n"
      "  \"gem_version\": \"{}\",\n  \"steps\": {},\n  \"sim_time_s\": {},\n  \"wall_time_s\": {},\n"
      "  \"real_time_factor\": {},\n  \"backend\": \"{}\",\n  \"broadphase\": \"{}\",\n  \"device\": \"{}\",\n"
      "  \"floes_initial\": {},\n  \"floes_final\": {},\n  \"floes_broken\": {},\n"
      "  \"ice_mass_initial_kg\": {},\n  \"ice_mass_final_kg\": {},\n  \"rubble_mass_kg\": {},\n"
      "  \"impacts\": {},\n  \"ship_speed\": {},\n  \"impact_force_n\": {},\n  \"net_thrust_n\": {},\n"
      "  \"resistance_mean_n\": {},\n  \"ship_speed_in_ice\": {},\n  \"resistance_in_ice_n\": {}\n}}\n",
      GEM_VERSION, s.steps, jsonNumber(s.simTime), jsonNumber(s.wallTime),
      jsonNumber(s.wallTime > 0 ? s.simTime / s.wallTime : INFINITY), s.backend, s.broadphase, s.device,
      s.floesInitial, s.floesFinal, s.floesBroken, jsonNumber(s.iceMassInitial), jsonNumber(s.iceMassFinal),
      jsonNumber(s.rubbleMass), s.impacts, jsonStats(s.shipSpeed), jsonStats(s.impactForce), jsonStats(s.netThrust),
      s.netThrust.count ? jsonNumber(s.netThrust.mean) : "null", jsonStats(s.shipSpeedInIce),
      s.netThrustInIce.count ? jsonNumber(s.netThrustInIce.mean) : "null");
}

RunSummary runScenario(const Scenario& scenario, const RunOptions& options) {
  RunSummary summary;
  summary.backend = resolveBackend(scenario.backend);
  summary.broadphase = scenario.broadphase;
  summary.outputDir = scenario.output.dir.string();

  std::unique_ptr<Stepper> stepper = makeStepper(scenario);  // bad input throws here, before anything is written
  Stepper& sim = *stepper;
  summary.device = sim.device();
  summary.backend = sim.backend();  // "auto" may have fallen back to the cpu
  summary.floesInitial = sim.hostWorld().count(BodyKind::Floe);
  summary.iceMassInitial = sim.hostWorld().floeMass();

  const auto& dir = scenario.output.dir;
  std::filesystem::create_directories(dir);
  std::filesystem::remove(dir / "summary.json");  // a stale summary must not describe this run

  const OutputSpec& out = scenario.output;
  const bool frames = out.frameEvery > 0;
  auto has = [&](const char* f) { return std::find(out.formats.begin(), out.formats.end(), f) != out.formats.end(); };
  std::unique_ptr<VtkSeriesWriter> vtk = frames && has("vtk") ? std::make_unique<VtkSeriesWriter>(dir) : nullptr;
  std::unique_ptr<IceFileWriter> ice = frames && has("ice") ? std::make_unique<IceFileWriter>(dir / "frames.ice") : nullptr;
  AtomicFile timeseries(dir / "timeseries.csv"), impacts(dir / "impacts.csv");
  timeseries.stream() << "t,ship_x,ship_y,ship_heading,ship_speed,net_thrust,ice_force_x,contacts\n";
  impacts.stream() << "t,floe_id,floe_mass,thickness,apex_deg,frame_angle_deg,x,y,nx,ny,x_from_stem,y_from_centerline,vn,fn,flim,broke\n";

  const VesselSpec& vessel = scenario.vessel;
  const Propulsion::Params thrust{vessel.bollardThrust,
                                  vessel.bollardThrust / (vessel.openWaterSpeed * vessel.openWaterSpeed * vessel.openWaterSpeed)};
  Accumulator speed, force, netThrust, speedInIce, netThrustInIce;
  const auto start = std::chrono::steady_clock::now();
  auto lastProgress = start;
  auto writeFrames = [&]() {
    if (vtk) vtk->addFrame(sim.hostWorld(), sim.time());
    if (ice) ice->addFrame(sim.hostWorld(), sim.time());
  };

  try {
    if (frames) writeFrames();
    for (long k = 0; k < scenario.steps; ++k) {
      sim.step();
      for (const ImpactRecord& r : sim.impacts()) {
        force.add(r.force);
        impacts.stream() << fmt::format("{:.6g},{},{:.9g},{:.6g},{:.6g},{:.6g},{:.9g},{:.9g},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.9g},{},{}\n",
                                        r.time, r.floeId, r.floeMass, r.thickness, r.apexDeg, r.frameAngleDeg, r.point.x,
                                        r.point.y, r.normal.x, r.normal.y, r.xFromStem, r.yFromCenterline, r.closingSpeed,
                                        r.force, std::isfinite(r.forceLimit) ? fmt::format("{:.9g}", r.forceLimit) : "inf",
                                        r.broke ? 1 : 0);
      }
      const VesselSample vessel = sim.vessel();
      const Vec2 forward{std::cos(vessel.heading), std::sin(vessel.heading)};
      const Real surge = dot(vessel.velocity, forward);
      if (vessel.present) {
        speed.add(surge);
        netThrust.add(Propulsion::netThrust(thrust, surge));
        // The steady part of the transit (thesis 6.2.1.3): the whole hull inside the field's x range.
        if (scenario.hasDomain && vessel.position.x - scenario.vessel.length / 2 >= scenario.domain.x0 &&
            vessel.position.x + scenario.vessel.length / 2 <= scenario.domain.x1) {
          speedInIce.add(surge);
          netThrustInIce.add(Propulsion::netThrust(thrust, surge));
        }
      }
      if ((k + 1) % out.timeseriesEvery == 0) {
        if (vessel.present)
          timeseries.stream() << fmt::format("{:.6g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{}\n", sim.time(),
                                             vessel.position.x, vessel.position.y, vessel.heading, surge,
                                             Propulsion::netThrust(thrust, surge), sim.vesselIceForce().x, sim.contactCount());
        else
          timeseries.stream() << fmt::format("{:.6g},,,,,,,{}\n", sim.time(), sim.contactCount());
      }
      if (frames && (k + 1) % out.frameEvery == 0) writeFrames();
      if (options.progress && !options.quiet) {
        const auto now = std::chrono::steady_clock::now();
        if (now - lastProgress > std::chrono::milliseconds(250) || k + 1 == scenario.steps) {
          lastProgress = now;
          const double wall = std::chrono::duration<double>(now - start).count();
          const double rate = (k + 1) / std::max(wall, 1e-9);
          std::fprintf(stderr, "\r  step %ld/%ld  t = %.1f s  %.0f steps/s  %.0fx real time  ETA %s   ", k + 1,
                       scenario.steps, static_cast<double>(sim.time()), rate, rate * scenario.dt,
                       formatDuration((scenario.steps - k - 1) / rate).c_str());
          std::fflush(stderr);
        }
      }
    }
  } catch (...) {
    // Keep what the failed run produced (whole rows only), but write no summary.json.
    timeseries.commit();
    impacts.commit();
    if (vtk) vtk->finish();
    if (ice) ice->finish();
    throw;
  }
  if (options.progress && !options.quiet) std::fprintf(stderr, "\n");
  summary.wallTime = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  summary.steps = scenario.steps;
  summary.simTime = sim.time();
  const World& world = sim.hostWorld();
  summary.floesFinal = world.count(BodyKind::Floe);
  summary.iceMassFinal = world.floeMass();
  summary.rubbleMass = sim.rubbleMass();
  summary.floesBroken = sim.floesBroken();
  summary.impacts = force.count;
  summary.shipSpeed = speed.stats();
  summary.impactForce = force.stats();
  summary.netThrust = netThrust.stats();
  summary.shipSpeedInIce = speedInIce.stats();
  summary.netThrustInIce = netThrustInIce.stats();

  timeseries.commit();
  impacts.commit();
  if (vtk) vtk->finish();
  if (ice) ice->finish();
  writeStateCsv(dir / "state.csv", world);
  writeFileAtomically(dir / "summary.json", summaryJson(summary));
  return summary;
}

}  // namespace gem
