// Autopilot: set heading and track from [vessel]; gains from [events.autopilot] or the defaults.
#include "events/autopilot.hpp"

#include "framework/api/registry.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/world/vessel.hpp"

namespace gem {

static Autopilot::Params parseAutopilot(EventConfig& config) {
  TableReader& t = config.params;
  const VesselSpec& v = config.scenario.vessel;
  Autopilot::Params p{};
  p.setHeading = t.getReal("heading_deg", v.headingDeg) * kPi / 180;
  p.trackPoint = v.position;
  p.mass = v.mass;
  p.yawInertia = v.mass * vesselYawGyration2(v.length);
  const Real period = t.getPositive("period", 30);
  const Real w = 2 * kPi / period;
  p.g1 = t.getNonNegative("g1", p.yawInertia * w * w);
  p.g2 = t.getNonNegative("g2", 2 * p.yawInertia * w);
  p.g3 = t.getNonNegative("g3", p.mass * w * w);
  p.g4 = t.getNonNegative("g4", 2 * p.mass * w);
  return p;
}

GEM_REGISTER_SOLO_EVENT(Autopilot, "autopilot", "PD heading and track keeping of a 3-DOF vessel (eq. 3.3, 3.4)", true, parseAutopilot);

}  // namespace gem
