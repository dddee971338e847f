// The vessel: its hull (waterline polygon with a frame angle per edge) and how it enters the world.
#pragma once
#include <vector>

#include "framework/world/world.hpp"

namespace gem {

// The vessel as a scenario gives it ([vessel], docs/scenario.md).
struct VesselSpec {
  bool present = false;
  Real length = 100, beam = 20;  // m
  Real mass = Real(7.2e6);       // kg (thesis 6.2.1.1.2: 7200 t)
  Real draft = 6;                // m: the vessel's "thickness" for the elastic contact's h = min(h1, h2)
  Vec2 position{-60, 0};         // centroid at start, m
  Real headingDeg = 0;
  int dof = 1;
  Real bollardThrust = Real(370e3);  // N
  Real openWaterSpeed = Real(4.9);   // m/s
  Real speed = Real(4.9);            // initial speed, m/s (defaults to the open-water speed)
  std::vector<Vec2> hull;            // waterline, body frame (x forward, y to port), any origin
  std::vector<Real> frameAnglesDeg;  // one per hull edge (edge i joins vertex i and i+1)
};

// The default hull: 100 m x 20 m with a sloped bow (see vessel.cpp for the numbers).
void defaultHull(Real length, Real beam, std::vector<Vec2>& vertices, std::vector<Real>& frameAnglesDeg);

// The hull in the ship's body frame about its area centroid, counter-clockwise, x forward.
struct HullGeometry {
  std::vector<Vec2> vertices;
  std::vector<Real> frameAnglesDeg;  // per edge, in the order of `vertices`
  Real stemX;                        // foremost x, m
  Vec2 centroidOffset;               // the centroid in the coordinates the hull was given in
};

HullGeometry hullGeometry(const VesselSpec& vessel);

// r_z^2 of the vessel in 2D: r_y = r_z = 0.25 L (docs/model.md 1, A.17-A.20).
inline Real vesselYawGyration2(Real length) { return Real(0.0625) * length * length; }

// Adds the vessel to the world at its position and heading, moving at its initial speed; sets its
// mass (given, else L B T C_B rho_w is not used: the scenario's mass wins) and 2D inertia.
int addVessel(World& world, const VesselSpec& vessel);

}  // namespace gem
