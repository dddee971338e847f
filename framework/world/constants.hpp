// Physical constants shared by host and device code (docs/model.md 1, 4, 7). Values that a researcher
// may want to change are event parameters instead; these are the defaults they start from.
#pragma once
#include "geometry/config.hpp"

namespace gem {
constexpr Real kRhoIce = 900;          // kg/m^3
constexpr Real kRhoWater = 1025;       // kg/m^3
constexpr Real kRhoAir = Real(1.3);    // kg/m^3
constexpr Real kGravity = Real(9.81);  // m/s^2

// The fastest a body may start (docs/scenario.md): far beyond any ship or floe, and small enough
// that no step from it overflows. Each velocity component, m/s, and the angular velocity, rad/s.
constexpr Real kMostStartSpeed = 100;
constexpr Real kMostStartAngularSpeed = 100;

// A floe's thickness, m: from young ice of a centimetre to an iceberg. Thinner, a floe's mass and
// moment of inertia become so small that the first impulse on it overflowed the step.
constexpr Real kLeastIceThickness = Real(0.01), kMostIceThickness = 1000;
}  // namespace gem
