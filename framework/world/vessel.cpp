#include "framework/world/vessel.hpp"

#include <algorithm>
#include <cmath>

namespace gem {

// The default hull, scaled to length L and beam B (thesis 3.2.2, Figures 3.4, 6.15: a 100 m x 20 m
// offshore supply vessel with a sloped ice-going bow). In units of L and B, from the stern:
//   parallel body from x = -0.5 L to +0.2 L (wall-sided, beta = 0), then a bow that narrows through
//   shoulders at x = 0.35 L (|y| = 0.4 B) and 0.45 L (|y| = 0.25 B) to a 0.15 B wide stem at +0.5 L.
//   Frame angles (beta, from vertical): shoulder 30 deg, mid-bow 45, fore-bow 55, stem 60; the
//   sides and the transom 0. The sloped bow is what lets floes fail in bending (F_lim finite).
void defaultHull(Real length, Real beam, std::vector<Vec2>& vertices, std::vector<Real>& frameAnglesDeg) {
  const Real l = length, b = beam;
  vertices = {{-0.5 * l, -0.5 * b}, {0.2 * l, -0.5 * b},  {0.35 * l, -0.4 * b}, {0.45 * l, -0.25 * b}, {0.5 * l, -0.075 * b},
              {0.5 * l, 0.075 * b}, {0.45 * l, 0.25 * b}, {0.35 * l, 0.4 * b},  {0.2 * l, 0.5 * b},    {-0.5 * l, 0.5 * b}};
  frameAnglesDeg = {0, 30, 45, 55, 60, 55, 45, 30, 0, 0};
}

HullGeometry hullGeometry(const VesselSpec& vessel) {
  HullGeometry h;
  h.vertices = vessel.hull;
  h.frameAnglesDeg = vessel.frameAnglesDeg;
  if (h.vertices.empty()) defaultHull(vessel.length, vessel.beam, h.vertices, h.frameAnglesDeg);
  const int n = static_cast<int>(h.vertices.size());
  if (signedArea(h.vertices.data(), n) < 0) {
    // Edge j of the reversed polygon is edge n - 2 - j of the given one.
    reverseOrder(h.vertices.data(), n);
    std::vector<Real> reversed(n);
    for (int j = 0; j < n; ++j) reversed[j] = h.frameAnglesDeg[((n - 2 - j) % n + n) % n];
    h.frameAnglesDeg = reversed;
  }
  h.centroidOffset = areaCentroid(h.vertices.data(), n);
  h.stemX = -INFINITY;
  for (Vec2& v : h.vertices) {
    v -= h.centroidOffset;
    h.stemX = std::max(h.stemX, v.x);
  }
  return h;
}

int addVessel(World& world, const VesselSpec& vessel) {
  const HullGeometry hull = hullGeometry(vessel);
  const Real heading = vessel.headingDeg * kPi / 180;
  BodySpec spec;
  spec.kind = BodyKind::Vessel;
  spec.thickness = vessel.draft;
  spec.origin = "vessel";
  for (Vec2 v : hull.vertices) spec.vertices.push_back(vessel.position + rotate(v, heading));
  const Vec2 forward{std::cos(heading), std::sin(heading)};
  spec.velocity = vessel.speed * forward;
  const int slot = world.addBody(spec);
  // The body frame is the ship frame (x forward), so angle is the heading itself.
  for (size_t k = 0; k < hull.vertices.size(); ++k) world.local(slot)[k] = hull.vertices[k];
  world.angle[slot] = heading;
  world.x[slot] = vessel.position.x;
  world.y[slot] = vessel.position.y;
  world.mass[slot] = vessel.mass;
  world.invMass[slot] = 1 / vessel.mass;
  world.gyration2[slot] = vesselYawGyration2(vessel.length);
  world.gyrationX2[slot] = (Real(0.33) * vessel.beam) * (Real(0.33) * vessel.beam);
  world.gyrationY2[slot] = world.gyration2[slot];
  world.invInertia[slot] = 1 / (vessel.mass * world.gyration2[slot]);
  world.principalAngle[slot] = 0;  // the ship's own axes
  return slot;
}

}  // namespace gem
