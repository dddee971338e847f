// Coulomb friction between floes: the example of docs/plugins.md "Order". A pair event declared to
// run after impact (kOrder), which reads the normal impulse that earlier events of the phase applied
// to the contact (slot.normal) and bounds its own tangential impulse by mu times it: no need to
// recompute the impact.
#include "framework/api/event_api.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

GEM_PLUGIN("floe_friction", "0.1.0")

namespace gem {

struct FloeFriction {
  static constexpr int kOrder = event_order::kImpulses + 50;  // after impact, before the observers
  struct Params {
    Real mu;  // friction coefficient, dimensionless
  };
  GEM_HD static void apply(const Params& p, const PairBody& a, const PairBody& b, const PairContact& contact, PairSlot& slot,
                           const StepContext&, const RecordSink&) {
    if (a.kind != BodyKind::Floe || b.kind != BodyKind::Floe || !(slot.normal > 0)) return;
    const Vec2 n = contact.geometry.normal, c = contact.geometry.point, t = perpLeft(n);
    const Real sliding = dot(pointVelocity(a, c) - pointVelocity(b, c), t);  // m/s, of a relative to b along t
    const Real inverseMass = inverseEffectiveMass(a, t, c) + inverseEffectiveMass(b, t, c);
    if (!(inverseMass > 0)) return;
    Real j = sliding / inverseMass;  // the impulse that would stop the sliding
    const Real limit = p.mu * slot.normal;
    j = j > limit ? limit : (j < -limit ? -limit : j);
    slot.addTangent(j, t);
  }
};

static FloeFriction::Params parseFloeFriction(EventConfig& config) { return {config.params.getNonNegative("mu", Real(0.3))}; }

GEM_REGISTER_PAIR_EVENT(FloeFriction, "floe_friction", "Coulomb friction between floes, bounded by mu x the impact's normal impulse", false,
                        parseFloeFriction);

}  // namespace gem
