// A spatially varying current (a plugin example, docs/plugins.md): a shear flow along x whose
// speed changes linearly across the channel, dragging each floe towards the water at its centroid.
//
//   U(y)  = (u0 + shear (y - y_ref), 0)                                   [m/s]
//   tau   = rho_w C_w |U - v| (U - v)                                     [N/m^2]
//   dv    = tau dt / (rho_ice h)                                          [m/s]
//
// The stress is the bulk formula of the built-in current event (docs/model.md 7, A.108 to A.113) with
// U taken at the floe's centroid instead of one U for the whole field. Floes only.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct ShearCurrent {
  // apply reads neither ctx.time nor ctx.step: the same at every step (registry.hpp, eventIsTimeInvariant).
  static constexpr bool kTimeInvariant = true;
  struct Params {
    Real u0;           // current speed along x at y = y_ref, m/s (0.2)
    Real shear;        // dU/dy, 1/s (0.01)
    Real yRef;         // m (0)
    Real rhoWater;     // kg/m^3 (1025)
    Real coefficient;  // C_w, dimensionless (5.5e-3)
  };

  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (body.kind != BodyKind::Floe) return;
    const Vec2 flow{p.u0 + p.shear * (body.position.y - p.yRef), Real(0)};
    const Vec2 slip = flow - body.velocity;
    change.dv += ctx.dt / (kRhoIce * body.thickness) * p.rhoWater * p.coefficient * norm(slip) * slip;
  }
};

}  // namespace gem
