// Host-only: reads an EnvironmentalForce's parameters, shared by wind.cpp and current.cpp.
#pragma once
#include "events/environmental_force.hpp"
#include "framework/api/registry.hpp"
#include "framework/api/table_reader.hpp"

namespace gem {

// Keys: force (N/m^2), direction_deg, speed (m/s, along speed_direction_deg, default direction_deg),
// drag_coefficient, density.
inline EnvironmentalForce::Params parseEnvironmentalForce(TableReader& t, Real density, Real coefficient, Real relative) {
  EnvironmentalForce::Params p{};
  const Real force = t.getReal("force", 0);
  const Real direction = t.getReal("direction_deg", 0) * kPi / 180;
  const Real speed = t.getNonNegative("speed", 0);
  const Real speedDirection = t.getReal("speed_direction_deg", direction * 180 / kPi) * kPi / 180;
  p.stress = {force * std::cos(direction), force * std::sin(direction)};
  p.flowVelocity = {speed * std::cos(speedDirection), speed * std::sin(speedDirection)};
  p.density = t.getPositive("density", density);
  p.coefficient = t.getNonNegative("drag_coefficient", coefficient);
  p.relative = relative;
  return p;
}

}  // namespace gem
