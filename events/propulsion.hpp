// Vessel propulsion with the net-thrust model (docs/model.md 7, thesis eq. 3.2):
//
//   T_net = T_bollard - C_res V^3,   C_res = T_bollard / V_ow^3   (T_net = 0 at the open-water speed)
//   dv    = T_net dt / M  along the heading                                              [m/s]
//
// V is the surge speed (velocity along the heading), m/s; T in N; M the vessel mass, kg.
// In pack ice the net thrust balances the mean ice force below V_ow: its mean is the resistance.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct Propulsion {
  // apply reads neither ctx.time nor ctx.step: the same at every step (registry.hpp, eventIsTimeInvariant).
  static constexpr bool kTimeInvariant = true;
  struct Params {
    Real bollardThrust;          // N
    Real resistanceCoefficient;  // C_res, N s^3/m^3
  };

  GEM_HD static Real netThrust(const Params& p, Real surgeSpeed) {
    return p.bollardThrust - p.resistanceCoefficient * surgeSpeed * surgeSpeed * surgeSpeed;
  }

  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (body.kind != BodyKind::Vessel) return;
    const Vec2 heading{std::cos(body.angle), std::sin(body.angle)};
    change.dv += (netThrust(p, dot(body.velocity, heading)) * ctx.dt / body.mass) * heading;
  }
};

}  // namespace gem
