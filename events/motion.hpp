// Motion (docs/model.md 2, thesis A.21 to A.23): semi-implicit Euler. The velocities already hold every
// impulse and force of the step; positions then move with them:
//
//   x += v_x dt,  y += v_y dt,  angle += omega dt
//
// The degrees of freedom are enforced here: walls never move; a 1-DOF vessel keeps only the
// component of its velocity along its heading and never turns.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct Motion {
  // apply reads neither ctx.time nor ctx.step: the same at every step (registry.hpp, eventIsTimeInvariant).
  static constexpr bool kTimeInvariant = true;
  struct Params {
    int unused;  // motion has no parameters
  };

  GEM_HD static void apply(const Params&, MotionBody& body, const StepContext& ctx) {
    if (body.dof == 0) {
      body.velocity = {0, 0};
      body.omega = 0;
      return;
    }
    if (body.dof == 1) {
      const Vec2 heading{std::cos(body.angle), std::sin(body.angle)};
      body.velocity = dot(body.velocity, heading) * heading;
      body.omega = 0;
    }
    body.position += ctx.dt * body.velocity;
    body.angle += ctx.dt * body.omega;
  }
};

}  // namespace gem
