// Current: [events.current], off unless the scenario gives the table (docs/scenario.md).
#include "events/environmental_force_params.hpp"

namespace gem {

static EnvironmentalForce::Params parseCurrent(EventConfig& config) {
  return parseEnvironmentalForce(config.params, kRhoWater, Real(5.5e-3), 1);
}

GEM_REGISTER_SOLO_EVENT(EnvironmentalForce, "current",
                        "current stress on floes: a given force per area (A.108-A.113) or rho_w C_w |U_w - v| (U_w - v)", false,
                        parseCurrent);

}  // namespace gem
