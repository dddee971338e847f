// Ship-ice impact force, 2.5D (docs/model.md 5, thesis A.50 to A.99). The kinematics stay 2D (impact
// and elastic_contact move the bodies); at every ship-ice collision, each step in which the vessel
// and a floe overlap and their contact points approach (V_n > 0; thesis 3.2, 6.2.2: "each ship-ice
// collision event"), this event evaluates the 3D impact force, logs it, and asks for a flexural
// break when the edge fails. A floe pushed along the bow is struck, and logged, again and again.
//
//   3D normal (principal frames): (l_r cos beta, m_r cos beta, sin beta)
//   moment arms (z = 0):  lambda = n_z y_r,  mu = -n_z x_r,  eta = n_y x_r - n_x y_r   (A.60 corrected)
//   Co_s = n_x^2 + n_y^2/1.5 + n_z^2/2 + lambda^2/(1.25 r_xs^2) + mu^2/(2 r_ys^2) + eta^2/(1.6 r_zs^2)
//   Co_f = n_x^2 + n_y^2 + n_z^2/2 + lambda^2/(2 r_xf^2) + mu^2/(2 r_yf^2) + eta^2/r_zf^2
//   M_e = 1 / (Co_s/M_s + Co_f/M_f),  V_nb = V_n cos beta
//   F_n = 1.3104 P_0^(1/3) fa^(1/3) M_e^(2/3) V_nb^(4/3)                                    [N]
//   fa^(1/3) = (0.012 phi + 0.6)(1.38 - 0.027 beta + 0.0004 beta^2)          (phi, beta in degrees)
//   F_lim = 0.382 sigma_f h^2 phi K_v / ((sin b - mu_h cos b) - 0.039 (cos b + mu_h sin b))   (phi in rad)
//   K_v = max(1, 2.14 FR^0.33),  FR = V_nb / sqrt(g h)
//   logged force = min(F_n, F_lim); broke when F_n > F_lim;  L_cusp = 1.2 min(20 h / K_v, L_c)
//
// beta: frame angle of the vessel edge at c; phi: apex angle of the floe vertex inside the overlap
// nearest c (180 degrees when no floe vertex entered the vessel: a floe edge met a hull corner).
#pragma once
#include <cmath>

#include "events/break_request.hpp"
#include "framework/api/event_api.hpp"

namespace gem {

// A ship-ice impact, one collision step (docs/model.md 5): a row of the stream "impacts", which
// ship_impact.cpp writes to impacts.csv.
struct ImpactRecord {
  Real time;
  std::int64_t floeId;
  Real floeMass, thickness, apexDeg, frameAngleDeg;
  Vec2 point, normal;  // world contact point; normal from the vessel into the floe
  Real xFromStem, yFromCenterline;
  Real closingSpeed;  // V_n, m/s
  Real force;         // min(F_n, F_lim), N
  Real forceLimit;    // F_lim, N (infinite when the edge cannot fail in bending)
  bool broke;
};

constexpr const char* kImpactStream = "impacts";

struct ShipImpact {
  static constexpr int kOrder = event_order::kObservers;  // reads the contact, applies no impulse
  struct Params {
    Real frameAngle[kMaxVertices];            // beta per vessel edge (edge i joins vertex i and i + 1), rad
    Real gyrationX2, gyrationY2, gyrationZ2;  // vessel r_xs^2, r_ys^2, r_zs^2 (A.67-A.69), m^2
    Real stemX;                               // stem position along the vessel's x axis from its centroid, m
    Real pressure;                            // P_0, Pa (1 MPa)
    Real flexuralStrength;                    // sigma_f, Pa (0.5 MPa)
    Real hullFriction;                        // mu_h (0.1)
    RecordStream<ImpactRecord> impacts;       // the impact log
    RecordStream<BreakRequest> breaks;        // floes whose edge failed, for flexural_breaking
  };

  struct Result {
    Real effectiveMass;  // M_e, kg
    Real normalSpeed;    // V_nb, m/s
    Real forceNormal;    // F_n, N
    Real forceLimit;     // F_lim, N (infinity when the edge cannot fail in bending)
    Real force;          // min(F_n, F_lim), N
    Real froudeFactor;   // K_v
    bool broke;
  };

  // The 3D mass reduction coefficient of one body for the tilted normal (A.50-A.82): `vessel`
  // selects the ship's hydrodynamic factors. (x_r, y_r): contact point in the principal frame.
  GEM_HD static Real massReduction(bool vessel, Real nx, Real ny, Real nz, Real xr, Real yr, Real rx2, Real ry2, Real rz2) {
    const Real lambda = nz * yr, mu = -nz * xr, eta = ny * xr - nx * yr;
    if (vessel)
      return nx * nx + ny * ny / Real(1.5) + nz * nz / 2 + lambda * lambda / (Real(1.25) * rx2) + mu * mu / (2 * ry2) +
             eta * eta / (Real(1.6) * rz2);
    return nx * nx + ny * ny + nz * nz / 2 + lambda * lambda / (2 * rx2) + mu * mu / (2 * ry2) + eta * eta / rz2;
  }

  // Co of body k: rotate n and (c - centroid) into k's principal frame, then tilt by beta.
  GEM_HD static Real bodyReduction(bool vessel, const PairBody& k, Vec2 c, Vec2 n, Real beta, Real rx2, Real ry2, Real rz2) {
    const Real cp = std::cos(k.principalAngle), sp = std::sin(k.principalAngle);
    const Vec2 nr = rotate(n, cp, -sp), r = rotate(c - k.position, cp, -sp);
    return massReduction(vessel, nr.x * std::cos(beta), nr.y * std::cos(beta), std::sin(beta), r.x, r.y, rx2, ry2, rz2);
  }

  // The force of docs/model.md 5 for vessel s and floe f meeting at c with normal n (vessel into floe),
  // closing speed vn (m/s), frame angle beta and apex angle phi (rad).
  GEM_HD static Result evaluate(const Params& p, const PairBody& s, const PairBody& f, Vec2 c, Vec2 n, Real vn, Real beta, Real phi) {
    Result r{};
    const Real coS = bodyReduction(true, s, c, n, beta, p.gyrationX2, p.gyrationY2, p.gyrationZ2);
    const Real coF = bodyReduction(false, f, c, n, beta, f.gyrationX2, f.gyrationY2, f.gyration2);
    r.effectiveMass = Real(1) / (coS / s.mass + coF / f.mass);
    r.normalSpeed = vn * std::cos(beta);
    const Real betaDeg = beta * 180 / kPi, phiDeg = phi * 180 / kPi;
    const Real fa13 = (Real(0.012) * phiDeg + Real(0.6)) * (Real(1.38) - Real(0.027) * betaDeg + Real(0.0004) * betaDeg * betaDeg);
    r.forceNormal = Real(1.3104) * std::cbrt(p.pressure) * fa13 * std::pow(r.effectiveMass, Real(2) / 3) *
                    std::pow(r.normalSpeed > 0 ? r.normalSpeed : Real(0), Real(4) / 3);
    const Real h = f.thickness;
    const Real froude = r.normalSpeed / std::sqrt(kGravity * h);
    r.froudeFactor = Real(2.14) * std::pow(froude > 0 ? froude : Real(0), Real(0.33));
    r.froudeFactor = r.froudeFactor > 1 ? r.froudeFactor : Real(1);
    const Real sb = std::sin(beta), cb = std::cos(beta), mu = p.hullFriction;
    const Real denominator = (sb - mu * cb) - Real(0.039) * (cb + mu * sb);
    r.forceLimit = denominator > 0 ? Real(0.382) * p.flexuralStrength * h * h * phi * r.froudeFactor / denominator : Real(INFINITY);
    r.broke = r.forceNormal > r.forceLimit;
    r.force = r.broke ? r.forceLimit : r.forceNormal;
    return r;
  }

  // Index of the polygon edge nearest to point c.
  GEM_HD static int nearestEdge(const Vec2* v, int n, Vec2 c) {
    int best = 0;
    Real bestDistance2 = Real(INFINITY);
    for (int i = 0; i < n; ++i) {
      const Vec2 a = v[i], e = v[(i + 1) % n] - a;
      Real t = dot(c - a, e) / dot(e, e);
      t = t < 0 ? 0 : (t > 1 ? 1 : t);
      const Real d2 = norm2(a + t * e - c);
      if (d2 < bestDistance2) bestDistance2 = d2, best = i;
    }
    return best;
  }

  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot&,
                           const StepContext& ctx, const RecordSink& sink) {
    const bool vesselFirst = a.kind == BodyKind::Vessel && b.kind == BodyKind::Floe;
    const bool vesselSecond = b.kind == BodyKind::Vessel && a.kind == BodyKind::Floe;
    if (!vesselFirst && !vesselSecond) return;
    const PairBody& s = vesselFirst ? a : b;
    const PairBody& f = vesselFirst ? b : a;
    const Vec2 c = contact.geometry.point;
    const Vec2 n = vesselFirst ? contact.geometry.normal : -contact.geometry.normal;  // vessel into floe
    const Vec2 vs = pointVelocity(s, c), vf = pointVelocity(f, c);
    const Real vn = dot(vs - vf, n);
    // Touching without approach: no impact. A floe that the inelastic impulse left moving with the
    // hull (no elastic push apart, elastic_contact.vessel = false) closes by rounding alone, a few
    // ulps of the speeds: that is no collision either.
    const Real roundingSpeed = (sizeof(Real) == sizeof(double) ? Real(1e-12) : Real(1e-5)) * (norm(vs) + norm(vf));
    if (!(vn > roundingSpeed)) return;

    const Real beta = p.frameAngle[nearestEdge(s.vertices, s.vertexCount, c)];
    const int apex = vesselFirst ? contact.geometry.apexVertexQ : contact.geometry.apexVertexP;
    const Real phi = apex >= 0 ? interiorAngle(f.vertices, f.vertexCount, apex) : kPi;
    const Result r = evaluate(p, s, f, c, n, vn, beta, phi);

    const Vec2 forward{std::cos(s.angle), std::sin(s.angle)};
    ImpactRecord record{};
    record.time = ctx.time;
    record.floeId = f.id;
    record.floeMass = f.mass;
    record.thickness = f.thickness;
    record.apexDeg = phi * 180 / kPi;
    record.frameAngleDeg = beta * 180 / kPi;
    record.point = c;
    record.normal = n;
    record.xFromStem = p.stemX - dot(c - s.position, forward);
    record.yFromCenterline = cross(forward, c - s.position);
    record.closingSpeed = vn;
    record.force = r.force;
    record.forceLimit = r.forceLimit;
    record.broke = r.broke;
    sink.push(p.impacts, record);
    if (r.broke) {
      const Real centroidDistance = norm(f.position - c);
      const Real bendingLength = 20 * f.thickness / r.froudeFactor;
      sink.push(p.breaks, BreakRequest{f.id, c, n, Real(1.2) * (bendingLength < centroidDistance ? bendingLength : centroidDistance)});
    }
  }
};

}  // namespace gem
