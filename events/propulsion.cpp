// Propulsion: thrust and open-water speed come from [vessel]; [events.propulsion] only turns it off.
#include "events/propulsion.hpp"

#include "framework/api/registry.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

static Propulsion::Params parsePropulsion(EventConfig& config) {
  const VesselSpec& v = config.scenario.vessel;
  Propulsion::Params p{};
  p.bollardThrust = v.bollardThrust;
  p.resistanceCoefficient = v.bollardThrust / (v.openWaterSpeed * v.openWaterSpeed * v.openWaterSpeed);
  return p;
}

GEM_REGISTER_SOLO_EVENT(Propulsion, "propulsion", "vessel net thrust T_bollard - C_res V^3, zero at the open-water speed (eq. 3.2)", true,
                        parsePropulsion);

}  // namespace gem
