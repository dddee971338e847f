// What an event sees and writes. Host+device: event headers include only this and geometry/.
// A solo event sees one body (SoloBody) and adds to its velocity change (VelocityChange).
// A two-body event sees both bodies and their contact (PairBody, PairContact) and adds to the
// contact's own impulse slot (PairSlot); each body later sums its slots in a fixed order, so no
// floating-point atomics are ever needed (docs/architecture.md "Writing an event").
#pragma once
#include <cstdint>

#include "framework/api/record_stream.hpp"
#include "geometry/contact.hpp"
#include "framework/world/body_kind.hpp"
#include "framework/world/constants.hpp"
#include "geometry/polygon.hpp"

namespace gem {

struct StepContext {
  Real dt;    // s
  Real time;  // s, at the start of the step
  long step;  // index of the step being taken, from 0
};

// One body at the start of the step, as solo events see it.
struct SoloBody {
  BodyKind kind;
  int dof;  // 3 for floes, 1 or 3 for the vessel, 0 for walls
  Vec2 position;
  Real angle;
  Vec2 velocity;
  Real omega;
  Real mass, area, thickness;
};

// What solo events add up for one body during a step (docs/model.md 2: velocities change first).
struct VelocityChange {
  Vec2 dv;
  Real domega;
};

// One body as the motion event sees it: it owns the position update (docs/model.md 2).
struct MotionBody {
  BodyKind kind;
  int dof;
  Vec2 position;
  Real angle;
  Vec2 velocity;
  Real omega;
};

// One body of a contact pair. vertices are its world vertices for this step.
struct PairBody {
  BodyKind kind;
  int dof;
  std::int64_t id;
  Vec2 position;
  Real angle;
  Vec2 velocity;
  Real omega;
  Real mass, invMass, invInertia;
  Real gyration2;               // r_z^2, m^2
  Real gyrationX2, gyrationY2;  // principal r_x^2, r_y^2, m^2 (docs/model.md 5)
  Real principalAngle;          // world angle of the principal x axis, rad
  Real area, thickness;
  const Vec2* vertices;
  int vertexCount;
};

// The PairBody view of body i of a structure of arrays with World's member names: World on the
// host, the device arrays on the GPU. One definition, so both backends see identical bodies.
template <class Arrays>
GEM_HD inline PairBody pairBodyOf(const Arrays& a, int i, int dof, const Vec2* vertices, int vertexCount) {
  PairBody b;
  b.kind = a.kind[i];
  b.dof = dof;
  b.id = a.id[i];
  b.position = Vec2{a.x[i], a.y[i]};
  b.angle = a.angle[i];
  b.velocity = Vec2{a.vx[i], a.vy[i]};
  b.omega = a.omega[i];
  b.mass = a.mass[i];
  b.invMass = a.invMass[i];
  b.invInertia = a.invInertia[i];
  b.gyration2 = a.gyration2[i];
  b.gyrationX2 = a.gyrationX2[i];
  b.gyrationY2 = a.gyrationY2[i];
  b.principalAngle = a.angle[i] + a.principalAngle[i];  // world angle of the principal x axis
  b.area = a.area[i];
  b.thickness = a.thickness[i];
  b.vertices = vertices;
  b.vertexCount = vertexCount;
  return b;
}

// A contact between bodies a and b (a's slot < b's slot); geometry.normal points from a into b.
struct PairContact {
  Contact geometry;
  bool onset;  // the pair was not in contact in the previous step
};

// The impulse of all two-body events of one contact: +impulse acts on b at the contact point,
// -impulse on a (equal and opposite, docs/model.md 4). Events add through addNormal and addTangent,
// which also keep the normal and tangential parts apart: an event that runs later in the phase
// (event_order below) reads what earlier ones applied, e.g. a Coulomb friction event bounds its
// tangential impulse by mu x `normal` (docs/plugins.md "Order").
struct PairSlot {
  Vec2 impulse;      // N s, world frame: everything the events of this contact applied, on b
  Real normal = 0;   // N s, the sum of the addNormal parts (along the contact normal, a into b)
  Real tangent = 0;  // N s, the sum of the addTangent parts (along perpLeft(normal))

  // j along the unit normal n (contact.geometry.normal): j > 0 pushes the bodies apart.
  GEM_HD void addNormal(Real j, Vec2 n) {
    impulse += j * n;
    normal += j;
  }
  // j along the unit tangent t = perpLeft(n).
  GEM_HD void addTangent(Real j, Vec2 t) {
    impulse += j * t;
    tangent += j;
  }
};

// When an event runs within its phase: lower first, ties by name (docs/plugins.md "Order"). An
// event declares it as `static constexpr int kOrder = event_order::kImpulses;`; one that does not
// runs at kDefault. gem info prints each event's order.
namespace event_order {
constexpr int kForces = 100;     // steady contact forces (elastic_contact)
constexpr int kImpulses = 200;   // collision impulses (impact)
constexpr int kDefault = 300;    // after the built-in impulses: e.g. friction reading slot.normal
constexpr int kObservers = 400;  // events that only read and record (ship_impact's log)
}  // namespace event_order

// 1 / effective mass of a body for an impulse along unit n at point c (docs/model.md 4:
// Co = l^2 + m^2 + eta^2 / r^2, M_e = M / Co). A 1-DOF vessel moves only along its heading, so
// only the surge component of n counts and it cannot turn (choice: the constraint carries the
// rest); walls are immovable.
GEM_HD inline Real inverseEffectiveMass(const PairBody& b, Vec2 n, Vec2 c) {
  if (b.dof == 0) return 0;
  if (b.dof == 1) {
    Vec2 surge{std::cos(b.angle), std::sin(b.angle)};
    Real l = dot(n, surge);
    return b.invMass * l * l;
  }
  Real eta = cross(c - b.position, n);  // moment arm (A.36)
  return b.invMass * dot(n, n) + b.invInertia * eta * eta;
}

// Velocity of the material point of b at c: v + omega x (c - centroid).
GEM_HD inline Vec2 pointVelocity(const PairBody& b, Vec2 c) { return b.velocity + crossZ(b.omega, c - b.position); }

// Closing speed along n at c, positive when the contact points approach (docs/model.md 4).
GEM_HD inline Real closingSpeed(const PairBody& a, const PairBody& b, const PairContact& contact) {
  Vec2 c = contact.geometry.point;
  return dot(pointVelocity(a, c) - pointVelocity(b, c), contact.geometry.normal);
}

}  // namespace gem
