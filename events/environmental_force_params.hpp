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
  // Ranges far beyond any sea or sky (docs/scenario.md 2.6), that keep the first step finite.
  const Real force = t.getRealIn("force", 0, -1e4, 1e4);
  const Real directionDeg = t.getRealIn("direction_deg", 0, -360, 360);
  const Real direction = directionDeg * kPi / 180;
  const Real speed = t.getRealIn("speed", 0, 0, 100);
  const Real speedDirection = t.getRealIn("speed_direction_deg", directionDeg, -360, 360) * kPi / 180;
  p.stress = {force * std::cos(direction), force * std::sin(direction)};
  p.flowVelocity = {speed * std::cos(speedDirection), speed * std::sin(speedDirection)};
  p.density = t.getPositive("density", density, 1e4);
  p.coefficient = t.getRealIn("drag_coefficient", coefficient, 0, 10);
  p.relative = relative;
  return p;
}

}  // namespace gem
