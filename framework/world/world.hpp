// The world state: every body as structure of arrays (docs/architecture.md "Speed habits"), in Real.
// Index i is a body's slot in the arrays; id[i] is its stable identity for outputs, which never
// changes and is never reused, even when floes break or leave as rubble.
#pragma once
#include <cstdint>
#include <string>
#include <functional>
#include <array>
#include <vector>

#include "framework/world/body_kind.hpp"
#include "framework/world/constants.hpp"
#include "geometry/polygon.hpp"
#include "geometry/portable_trig.hpp"

namespace gem {

const char* bodyKindName(BodyKind kind);

// One body as given by a scenario, a field generator or a .ice file: world coordinates.
struct BodySpec {
  BodyKind kind = BodyKind::Floe;
  std::vector<Vec2> vertices;  // world coordinates, convex (counter-clockwise after validation)
  Real thickness = 1;          // m
  Vec2 velocity{0, 0};         // m/s
  Real angularVelocity = 0;    // rad/s
  std::int64_t id = -1;        // -1: the world assigns the next free id
  std::string origin;          // where it came from, for error messages ("field", "floes[3]", "pack.ice:9:1: object 12")
};

// A body's shape and mass row as World::addBody makes it, written once for the host and the device
// (the resident CUDA kernel adds the pieces of a break itself): the centroid, the vertices about it
// (n into local), and the mass properties. Mass is rho_ice * area * thickness (docs/model.md 1); a
// wall keeps that mass but is immovable (invMass and invInertia 0).
struct BodyMassRow {
  Vec2 centroid;
  Real area, mass, invMass, gyration2, gyrationX2, gyrationY2, invInertia, principalAngle, radius;
};
// Trig: massProperties' (LibmTrig; PortableTrig for the pieces of a break, World::addPiece).
template <class Trig = LibmTrig>
GEM_HD inline BodyMassRow bodyMassRow(const Vec2* vertices, int n, Real thickness, bool immovable, Vec2* local) {
  const MassProperties mp = massProperties<Trig>(vertices, n);
  BodyMassRow row;
  row.centroid = mp.centroid;
  for (int k = 0; k < n; ++k) local[k] = vertices[k] - mp.centroid;
  row.area = mp.area;
  row.mass = kRhoIce * mp.area * thickness;
  row.invMass = immovable ? Real(0) : Real(1) / row.mass;
  row.gyration2 = mp.izz / mp.area;
  row.gyrationX2 = mp.ixx / mp.area;
  row.gyrationY2 = mp.iyy / mp.area;
  row.invInertia = immovable ? Real(0) : Real(1) / (row.mass * row.gyration2);
  row.principalAngle = mp.principalAngle;
  row.radius = boundingRadius(local, n);
  return row;
}

struct World {
  // Identity and shape.
  std::vector<std::int64_t> id;
  std::vector<BodyKind> kind;
  std::vector<int> vertexCount;
  std::vector<Vec2> localVertices;  // kMaxVertices per body, about the centroid, in the body frame
  // Kinematics: centroid position, orientation and their rates.
  std::vector<Real> x, y, angle, vx, vy, omega;
  // Mass properties. invMass and invInertia are 0 for walls (immovable); the vessel's
  // constrained degrees of freedom are handled by its dof (see Vessel).
  std::vector<Real> area, thickness, mass, invMass, invInertia;
  std::vector<Real> gyration2;               // r_z^2 = I_zz / A (floes), m^2: the 2D impulse's r^2
  std::vector<Real> gyrationX2, gyrationY2;  // principal r_x^2, r_y^2 (the 2.5D impact, A.80 to A.82)
  std::vector<Real> principalAngle;          // body-frame angle of the principal x axis, rad
  std::vector<Real> radius;                  // bounding radius about the centroid, m
  std::int64_t nextId = 0;

  int size() const { return static_cast<int>(id.size()); }
  const Vec2* local(int i) const { return &localVertices[static_cast<size_t>(i) * kMaxVertices]; }
  Vec2* local(int i) { return &localVertices[static_cast<size_t>(i) * kMaxVertices]; }
  Vec2 position(int i) const { return {x[i], y[i]}; }
  Vec2 velocity(int i) const { return {vx[i], vy[i]}; }
  // World vertices of body i into out (kMaxVertices long); returns the count.
  int worldVertices(int i, Vec2* out) const {
    toWorld(local(i), vertexCount[i], position(i), angle[i], out);
    return vertexCount[i];
  }

  // Adds a body from world-coordinate vertices (already validated: convex, CCW, finite).
  // Mass is rho_ice * area * thickness (docs/model.md 1); a wall keeps that mass but is immovable
  // (invMass and invInertia 0); the vessel's mass is set by its owner (addVessel).
  int addBody(const BodySpec& spec);
  // The same for a piece of a broken floe, its mass properties by the portable trigonometry
  // (geometry/portable_trig.hpp): the resident CUDA kernel makes the very same rows on the device.
  int addPiece(const BodySpec& spec);
  // Removes the bodies whose flag is set, keeping the order of the others.
  // forEachTask, when given, runs tasks 0 .. count - 1 on the caller's threads (a topology event
  // passes framework/api/parallel.hpp's parallelEach when the CPU stepper has lent its pool): each
  // array is then compacted by a task of its own, the vertices by ranges of rows. The result is the
  // same either way.
  using TaskRunner = std::function<void(int count, const std::function<void(int)>& task)>;
  void removeBodies(const std::vector<char>& remove, const TaskRunner& forEachTask = nullptr);
  // The arrays a permute() leaves behind, kept by a caller that permutes again and again (the CPU
  // stepper re-sorts every 200 steps) and passed back in: the next permute() writes into them
  // instead of fresh arrays. At 10^5 floes fresh arrays were 50 MB to zero and page in on one
  // thread, most of a re-sort's 100 ms on the development machine.
  struct PermuteRoom {
    std::vector<std::int64_t> id;
    std::vector<BodyKind> kind;
    std::vector<int> vertexCount;
    std::array<std::vector<Real>, 16> reals;  // in permute()'s order of the Real arrays
    std::vector<Vec2> vertices;
  };
  // Reorders all arrays by the permutation (new slot k holds old slot order[k]); forEachTask as for
  // removeBodies (then the arrays, and ranges of the vertices, are tasks). The same either way, and
  // with or without room.
  void permute(const std::vector<int>& order, const TaskRunner& forEachTask = nullptr, PermuteRoom* room = nullptr);
  // The order of the bodies along a Morton (Z-order) curve through their centroids: neighbours in
  // space become neighbours in memory (docs/architecture.md "Speed habits"). Ties keep slot order.
  // forEachTask as for removeBodies (then ranges of slots are tasks); the same order either way.
  std::vector<int> curveOrder(const TaskRunner& forEachTask = nullptr) const;  // sorted by curveKey, ties by slot
  // Total mass of the floes, kg.
  double floeMass() const;
  int count(BodyKind k) const;
};

// The Morton key of World::curveOrder, written once for the host and the device (the CUDA backend
// re-sorts on the device and must get the very same order): the centroid's place in the box of all
// centroids [x0, x1] x [y0, y1], on a 65536 x 65536 grid, x and y bits interleaved.
GEM_HD inline Real curveScale(Real x0, Real y0, Real x1, Real y1) {
  Real extent = x1 - x0 > y1 - y0 ? x1 - x0 : y1 - y0;
  if (!(extent > Real(1e-9))) extent = Real(1e-9);
  return 65535 / extent;
}
GEM_HD inline std::uint32_t curveKey(Real x, Real y, Real x0, Real y0, Real scale) {
  auto spread = [](std::uint32_t v) {  // the 16 bits of v to the even bits of the result
    v &= 0xffff;
    v = (v | (v << 8)) & 0x00ff00ff;
    v = (v | (v << 4)) & 0x0f0f0f0f;
    v = (v | (v << 2)) & 0x33333333;
    v = (v | (v << 1)) & 0x55555555;
    return v;
  };
  const auto gx = static_cast<std::uint32_t>((x - x0) * scale), gy = static_cast<std::uint32_t>((y - y0) * scale);
  return spread(gx) | (spread(gy) << 1);
}

}  // namespace gem
