// The step's rules, written once for every driver (docs/model.md 8, docs/architecture.md "The step"):
// the CPU stepper (step/cpu_stepper.cpp) and the CUDA kernels (framework/cuda/) call these, so
// that a rule changed here changes on every backend at once. Host and device (GEM_HD); plain data in,
// plain data out.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"
#include "framework/world/body_kind.hpp"
#include "geometry/polygon.hpp"

namespace gem {

// The time at the start of step `step`, s: the index times dt, never a running sum, so that every
// driver, every batch of device steps and every copy-back agree to the last bit.
GEM_HD inline Real stepTime(long step, Real dt) { return static_cast<Real>(step) * dt; }

// Bodies are re-sorted along the Morton curve (World::curveOrder) every this many steps, when the
// scenario keeps morton_sort on: neighbours in space stay neighbours in memory.
constexpr long kResortPeriod = 200;
// After `stepsTaken` steps (counted from 0), is it time to re-sort?
GEM_HD inline bool isResortStep(long stepsTaken) { return stepsTaken % kResortPeriod == 0; }

// A body's degrees of freedom: floes 3, walls 0 (immovable), the vessel as its scenario says (1:
// surge only, 3: surge, sway and yaw). docs/model.md 1.
GEM_HD inline int degreesOfFreedom(BodyKind kind, int vesselDof) {
  return kind == BodyKind::Wall ? 0 : (kind == BodyKind::Vessel ? vesselDof : 3);
}

// The narrowphase's prefilter of a candidate pair: two immovable bodies never need a contact, and
// bodies whose world-aligned boxes do not overlap cannot touch. A broadphase may propose more pairs
// than this lets through; applying the same test everywhere keeps the contacts, and so the
// trajectories, independent of the broadphase and the backend.
GEM_HD inline bool mayTouch(Real invMassA, Real invMassB, const Box& a, const Box& b) {
  if (invMassA == 0 && invMassB == 0) return false;
  return boxesOverlap(a, b);
}

// What one contact's impulse `impulse` (N s, acting on `body` at world point `point`) does to the
// body's velocities (docs/model.md 4): nothing for a wall; along its heading only for a 1-DOF
// vessel (the surge component; it cannot turn); linear and angular for 3 DOF.
GEM_HD inline void addContactImpulse(const PairBody& body, Vec2 impulse, Vec2 point, VelocityChange& total) {
  if (body.dof == 0) return;
  if (body.dof == 1) {
    const Vec2 heading{std::cos(body.angle), std::sin(body.angle)};
    total.dv += (body.invMass * dot(impulse, heading)) * heading;
    return;
  }
  total.dv += body.invMass * impulse;
  total.domega += body.invInertia * cross(point - body.position, impulse);
}

// The mean force of a step's impulse: force = impulse / dt (the vessel's ice force, N).
GEM_HD inline Vec2 forceOfImpulse(Vec2 impulse, Real dt) { return (Real(1) / dt) * impulse; }

}  // namespace gem
