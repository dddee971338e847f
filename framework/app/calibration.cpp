#include "framework/app/calibration.hpp"

#include <cmath>
#include <cstdio>

#include <fmt/format.h>

#include "framework/output/atomic_file.hpp"
#include "framework/output/csv.hpp"
#include "framework/step/cpu_stepper.hpp"
#include "framework/world/vessel.hpp"

namespace gem {

namespace {

constexpr Real kFloeSide = 10;      // m
constexpr Real kGap = Real(0.005);  // m between the floe and the hull at placement

struct EdgeFrame {
  Vec2 midpoint, normal;  // ship frame about the centroid; outward unit normal
  Real length, frameAngleDeg;
};

EdgeFrame edgeFrame(const HullGeometry& hull, int edge) {
  const int n = static_cast<int>(hull.vertices.size());
  const Vec2 a = hull.vertices[edge], b = hull.vertices[(edge + 1) % n];
  const Vec2 e = b - a;
  return {Real(0.5) * (a + b), normalized(Vec2{e.y, -e.x}), norm(e), hull.frameAnglesDeg[edge]};
}

// The four starboard bow edges: the ones between the parallel body and the stem.
std::vector<int> bowEdges(const HullGeometry& hull) {
  std::vector<int> edges;
  for (int i = 0; i < static_cast<int>(hull.vertices.size()); ++i) {
    const EdgeFrame f = edgeFrame(hull, i);
    if (f.frameAngleDeg > 0 && f.normal.y <= Real(1e-9) && f.normal.x > 0) edges.push_back(i);
  }
  return edges;
}

// docs/model.md 5 written out directly for a vessel with heading 0 and a square floe (isotropic in
// plane, so its principal frame does not matter): the thesis's spreadsheet.
void directEvaluation(const Scenario& base, const EdgeFrame& edge, const CalibrationCase& c, Real apexDeg, CalibrationResult& out) {
  const VesselSpec& v = base.vessel;
  const Real beta = edge.frameAngleDeg * kPi / 180, phi = apexDeg * kPi / 180;
  const Real nx = edge.normal.x * std::cos(beta), ny = edge.normal.y * std::cos(beta), nz = std::sin(beta);
  // Vessel: the contact point is the edge's midpoint, in the ship's (principal) frame.
  const Real xs = edge.midpoint.x, ys = edge.midpoint.y, L = v.length;
  const Real lambdaS = nz * ys, muS = -nz * xs, etaS = ny * xs - nx * ys;
  const Real coS = nx * nx + ny * ny / 1.5 + nz * nz / 2 + lambdaS * lambdaS / (1.25 * 0.003 * L * L) + muS * muS / (2 * 0.05 * L * L) +
                   etaS * etaS / (1.6 * 0.06 * L * L);
  // Floe: the contact point lies on the floe's axis through its centroid along the normal.
  const Real reach = c.corner ? kFloeSide / std::sqrt(Real(2)) : kFloeSide / 2;
  const Real xf = -edge.normal.x * reach, yf = -edge.normal.y * reach;
  const Real rxy2 = kFloeSide * kFloeSide / 12, rz2 = kFloeSide * kFloeSide / 6;
  const Real lambdaF = nz * yf, muF = -nz * xf, etaF = ny * xf - nx * yf;
  const Real coF = nx * nx + ny * ny + nz * nz / 2 + lambdaF * lambdaF / (2 * rxy2) + muF * muF / (2 * rxy2) + etaF * etaF / rz2;
  const Real floeMass = kRhoIce * kFloeSide * kFloeSide * c.thickness;
  const Real me = 1 / (coS / v.mass + coF / floeMass);
  const Real vnb = c.speed * edge.normal.x * std::cos(beta);  // the floe is at rest; the ship moves along x
  const Real fa = (0.012 * apexDeg + 0.6) * (1.38 - 0.027 * edge.frameAngleDeg + 0.0004 * edge.frameAngleDeg * edge.frameAngleDeg);
  const Real fn = 1.3104 * std::cbrt(Real(1e6)) * fa * std::pow(me, Real(2) / 3) * std::pow(vnb, Real(4) / 3);
  const Real kv = std::max<Real>(1, 2.14 * std::pow(vnb / std::sqrt(kGravity * c.thickness), Real(0.33)));
  const Real mu = 0.1, denominator = (std::sin(beta) - mu * std::cos(beta)) - 0.039 * (std::cos(beta) + mu * std::sin(beta));
  out.directLimit = denominator > 0 ? 0.382 * 0.5e6 * c.thickness * c.thickness * phi * kv / denominator : Real(INFINITY);
  out.directForce = std::min(fn, out.directLimit);
}

}  // namespace

std::vector<CalibrationCase> calibrationCases(const Scenario& base) {
  const HullGeometry hull = hullGeometry(base.vessel);
  std::vector<CalibrationCase> cases;
  for (int edge : bowEdges(hull))
    for (bool corner : {true, false})
      for (Real speed : {Real(2), Real(5)})
        for (Real thickness : {Real(0.7), Real(1.2)})
          cases.push_back(
              {fmt::format("edge{}_{}_{}ms_{}m", edge, corner ? "corner" : "face", speed, thickness), edge, corner, speed, thickness});
  return cases;
}

CalibrationResult runCalibrationCase(const Scenario& base, const CalibrationCase& c) {
  CalibrationResult result;
  result.input = c;
  Scenario s = base;
  s.vessel.speed = c.speed;
  s.vessel.openWaterSpeed = c.speed;  // no net thrust: the ship keeps its speed until it strikes
  const HullGeometry hull = hullGeometry(s.vessel);
  const EdgeFrame edge = edgeFrame(hull, c.edge);

  // The floe: a corner (or the middle of a face) just off the edge's midpoint, along its normal.
  BodySpec floe;
  floe.kind = BodyKind::Floe;
  floe.thickness = c.thickness;
  floe.origin = c.name;
  const Vec2 n = edge.normal, t = perpLeft(n);
  const Real h = kFloeSide / 2;
  const Vec2 hull0 = s.vessel.position;  // heading 0: ship frame = world frame shifted
  if (c.corner) {
    const Vec2 tip = hull0 + edge.midpoint + kGap * n, centre = tip + (kFloeSide / std::sqrt(Real(2))) * n;
    const Real d = kFloeSide / std::sqrt(Real(2));
    floe.vertices = {centre - d * n, centre + d * t, centre + d * n, centre - d * t};
  } else {
    const Vec2 centre = hull0 + edge.midpoint + (kGap + h) * n;
    floe.vertices = {centre - h * n - h * t, centre - h * n + h * t, centre + h * n + h * t, centre + h * n - h * t};
  }
  if (signedArea(floe.vertices.data(), 4) < 0) reverseOrder(floe.vertices.data(), 4);
  s.floes = {floe};
  // The apex angle the direct evaluation uses: a corner is 90 deg; a face wider than the hull edge
  // has no vertex inside the hull (180 deg, docs/model.md 5), a narrower one puts its corners inside.
  result.apexDeg = c.corner || kFloeSide < edge.length ? 90 : 180;
  result.frameAngleDeg = edge.frameAngleDeg;
  directEvaluation(s, edge, c, result.apexDeg, result);

  CpuStepper sim(s);
  for (long k = 0; k < s.steps && !result.logged; ++k) {
    sim.step();
    const std::vector<ImpactRecord> impacts = sim.records().rows<ImpactRecord>(kImpactStream);
    if (!impacts.empty()) {
      result.logged = true;
      result.record = impacts.front();
    }
  }
  return result;
}

double runCalibration(const std::string& scenarioFile, const std::string& outDir, bool quiet) {
  const Scenario base = loadScenario(scenarioFile);
  std::string csv =
      "case,edge,orientation,speed_mps,thickness_m,frame_angle_deg,apex_deg,fn_logged_n,fn_direct_n,relative_difference,flim_logged_n,flim_"
      "direct_n,broke\n";
  double worst = 0;
  if (!quiet) std::printf("%-28s %6s %6s %14s %14s %9s\n", "case", "beta", "phi", "logged F [kN]", "direct F [kN]", "diff");
  for (const CalibrationCase& c : calibrationCases(base)) {
    const CalibrationResult r = runCalibrationCase(base, c);
    const double diff = r.logged ? (r.record.force - r.directForce) / r.directForce : 1.0;
    worst = std::max(worst, std::fabs(diff));
    if (!quiet)
      std::printf("%-28s %6.1f %6.1f %14.2f %14.2f %8.2f%%%s\n", c.name.c_str(), static_cast<double>(r.frameAngleDeg),
                  static_cast<double>(r.logged ? r.record.apexDeg : 0), r.record.force / 1e3, r.directForce / 1e3, 100 * diff,
                  r.logged ? "" : "  (no impact logged)");
    csv += fmt::format("{},{},{},{},{},{},{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{}\n", csvField(c.name), c.edge,
                       c.corner ? "corner" : "face", c.speed, c.thickness, r.frameAngleDeg, r.logged ? r.record.apexDeg : Real(NAN),
                       r.record.force, r.directForce, diff, r.record.forceLimit, r.directLimit, r.record.broke ? 1 : 0);
  }
  std::filesystem::create_directories(outDir);
  writeFileAtomically(std::filesystem::path(outDir) / "calibration.csv", csv);
  if (!quiet) std::printf("largest difference %.2f %%; table in %s/calibration.csv\n", 100 * worst, outDir.c_str());
  return worst;
}

}  // namespace gem
