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

// The farthest from the origin a coordinate of the domain, the vessel or a floe may be, m: ten
// thousand kilometres. Past it the geometry's tolerances (relative to the coordinates) swallow a
// floe's shape: a floe 1e300 m out was refused as "not convex" instead of by its coordinates.
constexpr Real kMostCoordinate = 1e7;
}  // namespace gem
