// Ship impact: hull frame angles and the vessel's 2.5D radii of gyration come from [vessel].
#include "events/ship_impact.hpp"

#include <algorithm>

#include "framework/api/registry.hpp"
#include "framework/scenario/scenario.hpp"
#include "framework/api/table_reader.hpp"
#include "framework/world/vessel.hpp"

namespace gem {

static ShipImpact::Params parseShipImpact(EventConfig& config) {
  TableReader& t = config.params;
  const VesselSpec& v = config.scenario.vessel;
  ShipImpact::Params p{};
  const HullGeometry hull = hullGeometry(v);
  for (size_t i = 0; i < hull.frameAnglesDeg.size(); ++i) p.frameAngle[i] = hull.frameAnglesDeg[i] * kPi / 180;
  p.stemX = hull.stemX;
  p.gyrationX2 = Real(0.003) * v.length * v.length;  // A.67-A.69
  p.gyrationY2 = Real(0.05) * v.length * v.length;
  p.gyrationZ2 = Real(0.06) * v.length * v.length;
  p.pressure = t.getPositive("pressure", Real(1e6));
  p.flexuralStrength = t.getPositive("flexural_strength", Real(0.5e6));
  p.hullFriction = t.getNonNegative("hull_friction", Real(0.1));
  return p;
}

GEM_REGISTER_PAIR_EVENT(ShipImpact, "ship_impact", "2.5D ship-ice impact force at contact onset, logged to impacts.csv; flags flexural failure (A.50-A.99)", true, parseShipImpact);

}  // namespace gem
