// Wind: [events.wind], off unless the scenario gives the table (docs/scenario.md).
#include "events/environmental_force_params.hpp"

namespace gem {

static EnvironmentalForce::Params parseWind(EventConfig& config) {
  return parseEnvironmentalForce(config.params, kRhoAir, Real(1.2e-3), 0);
}

GEM_REGISTER_SOLO_EVENT(EnvironmentalForce, "wind", "wind stress on floes: a given force per area (A.108-A.113) or rho_a C_a |U_a| U_a",
                        false, parseWind);

}  // namespace gem
