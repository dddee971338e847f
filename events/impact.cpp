#include "events/impact.hpp"

#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/scenario/scenario.hpp"

namespace gem {

// The one ship-ice friction coefficient: [events.ship_impact] hull_friction, read here too (without
// marking the table's keys: ship_impact reads and checks its own table) so that the impact's
// kinematics and the flexural limit use the same mu. Default 0.1, as ship_impact's.
Real shipIceFriction(const Scenario& scenario) {
  TableReader t(scenario.eventTable("ship_impact"), "events.ship_impact", scenario.fileName);
  return t.getRealIn("hull_friction", kDefaultHullFriction, 0, 10);
}

static Impact::Params parseImpact(EventConfig& config) {
  Impact::Params p{};
  p.friction = config.params.getRealIn("friction", 0, 0, 10);
  p.vesselFriction = shipIceFriction(config.scenario);
  return p;
}

GEM_REGISTER_PAIR_EVENT(
    Impact, "impact",
    "inelastic impulse I = M_ec V_c at the contact point (A.31-A.49), Coulomb friction (vessel-floe: ship_impact's hull_friction)", true,
    parseImpact);

}  // namespace gem
