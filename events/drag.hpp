// Water drag on floes (docs/model.md 7, thesis A.105 to A.107). The tutorial's first page.
//
//   dv_x  = -1/2 rho_w C_d v_x |v_x| dt / (rho_ice h)         (likewise v_y)         [m/s]
//   domega = -1/2 rho_w C_d omega |omega| L_rot dt / (rho_ice h)                     [rad/s]
//
// The thesis's omega formula lacks a length; its behaviour is L_rot = 1 m (kept as a parameter).
// Its own validation found this drag too weak for floes in open water, so two options are offered:
// form = "isotropic" uses |v| v instead of the per-component form, and `linear` (1/s) adds a
// linear skin-friction term -linear * v * dt. Units: SI. The vessel's water resistance is part of
// its net-thrust model (propulsion), so drag acts on floes only.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct Drag {
  // apply reads neither ctx.time nor ctx.step: the same at every step (registry.hpp, eventIsTimeInvariant).
  static constexpr bool kTimeInvariant = true;
  struct Params {
    Real cd;              // C_d, dimensionless (0.05)
    Real rhoWater;        // kg/m^3 (1025)
    Real rotationLength;  // L_rot, m (1)
    Real linear;          // 1/s (0)
    bool isotropic;       // |v| v instead of per component (false)
  };

  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (body.kind != BodyKind::Floe) return;
    const Real k = Real(0.5) * p.rhoWater * p.cd * ctx.dt / (kRhoIce * body.thickness);  // 1/m
    const Vec2 v = body.velocity;
    if (p.isotropic)
      change.dv -= k * norm(v) * v;
    else
      change.dv -= Vec2{k * v.x * std::fabs(v.x), k * v.y * std::fabs(v.y)};
    change.domega -= k * p.rotationLength * body.omega * std::fabs(body.omega);
    change.dv -= p.linear * ctx.dt * v;
    change.domega -= p.linear * ctx.dt * body.omega;
  }
};

}  // namespace gem
