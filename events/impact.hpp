// Inelastic impact between two bodies (docs/model.md 4, thesis A.31 to A.49): the ice-crushing event.
// All normal kinetic energy at the contact point is absorbed:
//
//   M_ec = 1 / (1/M_e1 + 1/M_e2),  M_ek = M_k / (l_k^2 + m_k^2 + eta_k^2 / r_k^2)      [kg]
//   I_in = M_ec V_c  when V_c > 0, else 0                                                [N s]
//
// V_c is the closing speed of the two contact points along n (m/s). The impulse acts at c along n,
// equal and opposite. Coulomb friction (thesis 3.2.1, L425: the friction direction "is determined" in
// every collision; A.1.5, L1624: "a second force is added in the tangential direction"): a tangential
// impulse that stops the sliding at c, at most mu I_in. Vessel-floe pairs use the one ship-ice
// coefficient, [events.ship_impact] hull_friction (0.1), the mu_h of the flexural limit too; every
// other pair (ice-ice, ice-wall) uses [events.impact] friction (0: the thesis gives no value).
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct Scenario;

// The one ship-ice friction coefficient mu_h (docs/model.md 4): [events.ship_impact] hull_friction.
constexpr Real kDefaultHullFriction = Real(0.1);
Real shipIceFriction(const Scenario& scenario);  // host only: reads the scenario's table

struct Impact {
  static constexpr int kOrder = event_order::kImpulses;  // docs/plugins.md "Order"
  struct Params {
    Real friction;        // mu of ice-ice and wall pairs, dimensionless
    Real vesselFriction;  // mu of vessel-floe pairs: ship_impact's hull_friction, dimensionless
  };

  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot& slot,
                           const StepContext&, const RecordSink&) {
    const Vec2 n = contact.geometry.normal, c = contact.geometry.point;
    const Real closing = closingSpeed(a, b, contact);
    if (!(closing > 0)) return;
    const Real inverseMass = inverseEffectiveMass(a, n, c) + inverseEffectiveMass(b, n, c);
    if (!(inverseMass > 0)) return;  // two immovable bodies
    const Real normalImpulse = closing / inverseMass;
    slot.addNormal(normalImpulse, n);
    const bool vesselFloe =
        (a.kind == BodyKind::Vessel && b.kind == BodyKind::Floe) || (a.kind == BodyKind::Floe && b.kind == BodyKind::Vessel);
    const Real mu = vesselFloe ? p.vesselFriction : p.friction;
    if (mu > 0) {
      const Vec2 t = perpLeft(n);
      const Real sliding = dot(pointVelocity(a, c) - pointVelocity(b, c), t);
      const Real inverseTangentMass = inverseEffectiveMass(a, t, c) + inverseEffectiveMass(b, t, c);
      if (inverseTangentMass > 0) {
        Real tangentImpulse = sliding / inverseTangentMass;
        const Real limit = mu * normalImpulse;
        tangentImpulse = tangentImpulse > limit ? limit : (tangentImpulse < -limit ? -limit : tangentImpulse);
        slot.addTangent(tangentImpulse, t);
      }
    }
  }
};

}  // namespace gem
