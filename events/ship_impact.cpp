// Ship impact: hull frame angles and the vessel's 2.5D radii of gyration come from [vessel].
#include "events/ship_impact.hpp"

#include "events/impact.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <fmt/format.h>

#include "framework/api/registry.hpp"
#include "framework/api/row_text.hpp"
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
  p.pressure = t.getPositive("pressure", Real(1e6), 1e9);
  p.flexuralStrength = t.getPositive("flexural_strength", Real(0.5e6), 1e9);
  p.hullFriction = t.getRealIn("hull_friction", kDefaultHullFriction, 0, 10);  // the impact's too (impact.cpp)
  p.impacts = config.records.open<ImpactRecord>(kImpactStream);
  p.breaks = config.records.open<BreakRequest>(kBreakStream);
  return p;
}

// impacts.csv, one row per impact (docs/scenario.md 4.4); summary.json counts the impacts and gives
// the statistics of their force, over the whole run and over the transit of the field.
// A row of impacts.csv: 9 significant digits for the masses, positions and forces, 6 for the rest,
// each as printf's "%g" (framework/api/row_text.hpp: a row per impact, fast).
static void writeImpactRow(const void* record, std::string& row) {
  const ImpactRecord& r = *static_cast<const ImpactRecord*>(record);
  row.clear();
  const auto number = [&row](Real value, int digits) {
    appendGeneral(row, static_cast<double>(value), digits);
    row += ',';
  };
  number(r.time, 6);
  appendInteger(row, r.floeId);
  row += ',';
  number(r.floeMass, 9), number(r.thickness, 6), number(r.apexDeg, 6), number(r.frameAngleDeg, 6);
  number(r.point.x, 9), number(r.point.y, 9), number(r.normal.x, 6), number(r.normal.y, 6);
  number(r.xFromStem, 6), number(r.yFromCenterline, 6), number(r.closingSpeed, 6), number(r.force, 9);
  if (std::isfinite(r.forceLimit))
    number(r.forceLimit, 9);
  else
    row += "inf,";
  row += r.broke ? "1\n" : "0\n";
}

// The whole run's totals ("impacts", "impact_force_n") and the transit's ("impacts_in_ice",
// "impact_force_in_ice_n": the steps with the whole hull in the field, thesis 6.2.2.2 L1268).
GEM_REGISTER_RECORD_OUTPUT_IN_ICE(
    kImpactStream, "impacts.csv",
    "t,floe_id,floe_mass,thickness,apex_deg,frame_angle_deg,x,y,nx,ny,x_from_stem,y_from_centerline,vn,fn,flim,broke", writeImpactRow,
    "impacts", "impact_force_n", [](const void* record) { return static_cast<double>(static_cast<const ImpactRecord*>(record)->force); },
    "impacts_in_ice", "impact_force_in_ice_n");

GEM_REGISTER_PAIR_EVENT(
    ShipImpact, "ship_impact",
    "2.5D ship-ice impact force at every collision (overlap and approach), logged to impacts.csv; flags flexural failure (A.50-A.99)", true,
    parseShipImpact);

}  // namespace gem
