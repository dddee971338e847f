// Autopilot of a 3-DOF vessel (docs/model.md 7, thesis eq. 3.3, 3.4): uncoupled PD controls
//
//   M_yaw   = -(G_1 d(theta) + G_2 d(theta)/dt)     yaw moment, N m
//   F_sway  = -(G_3 d(y) + G_4 dy/dt)               sway force across the track, N
//   domega  = M_yaw dt / I_z,   dv = F_sway dt / M  (along the track's normal)
//
// d(theta): heading minus the set heading; d(y): distance to port of the set track line.
// Default gains make each loop critically damped with a natural period of 30 s (choice):
// G_1 = I_z w^2, G_2 = 2 I_z w, G_3 = M w^2, G_4 = 2 M w, w = 2 pi / 30 s.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct Autopilot {
  // apply reads neither ctx.time nor ctx.step: the same at every step (registry.hpp, eventIsTimeInvariant).
  static constexpr bool kTimeInvariant = true;
  struct Params {
    Real setHeading;        // rad
    Vec2 trackPoint;        // a point of the set track line, m
    Real g1, g2, g3, g4;    // N m/rad, N m s/rad, N/m, N s/m
    Real mass, yawInertia;  // kg, kg m^2
  };

  GEM_HD static void apply(const Params& p, const SoloBody& body, VelocityChange& change, const StepContext& ctx) {
    if (body.kind != BodyKind::Vessel || body.dof != 3) return;
    Real headingError = body.angle - p.setHeading;
    headingError = std::atan2(std::sin(headingError), std::cos(headingError));  // wrap to (-pi, pi]
    const Vec2 across{-std::sin(p.setHeading), std::cos(p.setHeading)};         // to port of the track
    const Real offset = dot(body.position - p.trackPoint, across);
    const Real offsetRate = dot(body.velocity, across);
    const Real yawMoment = -(p.g1 * headingError + p.g2 * body.omega);
    const Real swayForce = -(p.g3 * offset + p.g4 * offsetRate);
    change.domega += yawMoment * ctx.dt / p.yawInertia;
    change.dv += (swayForce * ctx.dt / p.mass) * across;
  }
};

}  // namespace gem
