// Inelastic impact between two bodies (docs/model.md 4, thesis A.31 to A.49): the ice-crushing event.
// All normal kinetic energy at the contact point is absorbed:
//
//   M_ec = 1 / (1/M_e1 + 1/M_e2),  M_ek = M_k / (l_k^2 + m_k^2 + eta_k^2 / r_k^2)      [kg]
//   I_in = M_ec V_c  when V_c > 0, else 0                                                [N s]
//
// V_c is the closing speed of the two contact points along n (m/s). The impulse acts at c along n,
// equal and opposite. Optional Coulomb friction (mu = 0 by default, as in the thesis): a tangential
// impulse that stops the sliding at c, at most mu I_in.
#pragma once
#include <cmath>

#include "framework/api/event_api.hpp"

namespace gem {

struct Impact {
  static constexpr int kOrder = event_order::kImpulses;  // docs/plugins.md "Order"
  struct Params {
    Real friction;  // mu, dimensionless
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
    if (p.friction > 0) {
      const Vec2 t = perpLeft(n);
      const Real sliding = dot(pointVelocity(a, c) - pointVelocity(b, c), t);
      const Real inverseTangentMass = inverseEffectiveMass(a, t, c) + inverseEffectiveMass(b, t, c);
      if (inverseTangentMass > 0) {
        Real tangentImpulse = sliding / inverseTangentMass;
        const Real limit = p.friction * normalImpulse;
        tangentImpulse = tangentImpulse > limit ? limit : (tangentImpulse < -limit ? -limit : tangentImpulse);
        slot.addTangent(tangentImpulse, t);
      }
    }
  }
};

}  // namespace gem
