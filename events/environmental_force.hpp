// Wind and current on floes (docs/model.md 7, thesis A.108 to A.113). Two forms, summed:
//
//   given stress:  dv = F dt / (rho_ice h) (cos theta, sin theta)           F in N/m^2 (A.108-A.113)
//   bulk formula:  tau = rho C |U - s v| (U - s v),  dv = tau dt / (rho_ice h)
//                  wind:    rho = rho_air,   C = C_a, s = 0 (air speed >> floe speed)
//                  current: rho = rho_water, C = C_w, s = 1 (stress from the relative velocity)
//
// U is the wind or current velocity, m/s. Both act on floes only (the vessel's is in its thrust
// model). One evaluator, registered twice (wind.cpp, current.cpp) with their own defaults.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct EnvironmentalForce {
  // apply reads neither ctx.time nor ctx.step: the same at every step (registry.hpp, eventIsTimeInvariant).
  static constexpr bool kTimeInvariant = true;
  struct Params {
    Vec2 stress;        // F (cos theta, sin theta), N/m^2
    Vec2 flowVelocity;  // U, m/s
    Real density;       // rho of the moving fluid, kg/m^3
    Real coefficient;   // C_a or C_w, dimensionless
    Real relative;      // s: 1 when the stress depends on the floe's velocity relative to U
  };

  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (body.kind != BodyKind::Floe) return;
    const Real perMass = ctx.dt / (kRhoIce * body.thickness);  // (m/s) per (N/m^2)
    const Vec2 slip = p.flowVelocity - p.relative * body.velocity;
    const Vec2 bulk = p.density * p.coefficient * norm(slip) * slip;
    change.dv += perMass * (p.stress + bulk);
  }
};

}  // namespace gem
