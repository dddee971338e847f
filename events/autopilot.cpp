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
  // Ranges that keep the first step finite (docs/scenario.md 2.6); the default gains, from the
  // vessel's ranges and these, stay well inside theirs.
  p.setHeading = t.getRealIn("heading_deg", v.headingDeg, -360, 360) * kPi / 180;
  p.trackPoint = v.position;
  p.mass = v.mass;
  p.yawInertia = v.mass * vesselYawGyration2(v.length);
  const Real period = t.getRealIn("period", 30, Real(0.01), 1e6);
  const Real w = 2 * kPi / period;
  constexpr Real kMostGain = Real(1e30);
  p.g1 = t.getRealIn("g1", p.yawInertia * w * w, 0, kMostGain);
  p.g2 = t.getRealIn("g2", 2 * p.yawInertia * w, 0, kMostGain);
  p.g3 = t.getRealIn("g3", p.mass * w * w, 0, kMostGain);
  p.g4 = t.getRealIn("g4", 2 * p.mass * w, 0, kMostGain);
  return p;
}

GEM_REGISTER_SOLO_EVENT(Autopilot, "autopilot", "PD heading and track keeping of a 3-DOF vessel (eq. 3.3, 3.4)", true, parseAutopilot);

}  // namespace gem
