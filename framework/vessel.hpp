// The vessel: its hull (waterline polygon with a frame angle per edge) and how it enters the world.
#pragma once
#include <vector>

#include "framework/scenario.hpp"
#include "framework/world.hpp"

namespace gem {

// The hull in the ship's body frame about its area centroid, counter-clockwise, x forward.
struct HullGeometry {
  std::vector<Vec2> vertices;
  std::vector<Real> frameAnglesDeg;  // per edge, in the order of `vertices`
  Real stemX;                        // foremost x, m
  Vec2 centroidOffset;               // the centroid in the coordinates the hull was given in
};

HullGeometry hullGeometry(const VesselSpec& vessel);

// r_z^2 of the vessel in 2D: r_y = r_z = 0.25 L (MODEL.md 1, A.17-A.20).
inline Real vesselYawGyration2(Real length) { return Real(0.0625) * length * length; }

// Adds the vessel to the world at its position and heading, moving at its initial speed; sets its
// mass (given, else L B T C_B rho_w is not used: the scenario's mass wins) and 2D inertia.
int addVessel(World& world, const VesselSpec& vessel);

}  // namespace gem
