// Internal to framework/cuda: the per-body and per-pair work of a step, written once for both CUDA
// drivers. The device-wide driver (prepare.cu, contacts.cu, gather.cu) runs each function as one
// thread of a kernel over all bodies or all candidates; the resident driver (resident.cu) runs the
// same functions in block-strided loops inside its one kernel. The rules they apply come from
// framework/step/phases.hpp, as the CPU stepper's do.
#pragma once
#include <cstdint>

#include "framework/api/event_api.hpp"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"
#include "geometry/contact.hpp"
#include "geometry/polygon.hpp"
#include "geometry/sat.hpp"

namespace gem::cuda {

// Phase 1's inputs and outputs, as DeviceState's arrays.
struct PrepareArgs {
  int n;
  const std::int64_t* id;
  const BodyKind* kind;
  const int *vertexCount, *dof;
  const Vec2* local;
  const Real *x, *y, *angle, *vx, *vy, *omega, *area, *thickness, *mass, *invMass, *invInertia, *gyration2, *gyrationX2, *gyrationY2,
      *principalAngle;
  const unsigned char* isLarge;
  const int* world;
  std::int64_t idStride;  // the events see each case's own ids (PairBody::id)
  Real cell;
  unsigned mask, largeKey;
  Vec2* worldVertices;
  Box* boxes;
  PairBody* pairBodies;
  SoloBody* soloBodies;
  VelocityChange* changes;
  unsigned* cellKey;  // nullptr: no hashed grid (the resident driver finds its pairs otherwise)
  int* slot;
};

struct DeviceState;
// The arrays of d; grid: with the hashed grid's cell keys (the device-wide driver), else without.
PrepareArgs prepareArgsOf(DeviceState& d, unsigned largeKey, bool grid);

#if defined(__CUDACC__)
// Phase 1 for body i after its world vertices (toWorld) are written and its box found: the box,
// the events' views (which point at the world vertices), the cell key.
__device__ inline void finishBody(const PrepareArgs& a, int i, const Box& box) {
  a.boxes[i] = box;
  PairBody b = pairBodyOf(a, i, a.dof[i], a.worldVertices + static_cast<size_t>(i) * kMaxVertices, a.vertexCount[i]);
  b.id -= static_cast<std::int64_t>(a.world[i]) * a.idStride;
  a.pairBodies[i] = b;
  a.soloBodies[i] = SoloBody{b.kind, b.dof, b.position, b.angle, b.velocity, b.omega, b.mass, b.area, b.thickness};
  a.changes[i] = VelocityChange{{0, 0}, 0};
  if (!a.cellKey) return;
  // A small body lives in the cell of its box's lower-left corner; large ones stay out of the grid.
  a.cellKey[i] = a.isLarge[i] ? a.largeKey : cellHash(cellCoord(box.x0, a.cell), cellCoord(box.y0, a.cell), a.world[i], a.mask);
  a.slot[i] = i;
}

// Phase 1 for body i: as CpuStepper::narrowphase's box loop and CpuStepper::step's view loops. A
// driver may run it in pieces (the resident kernel turns a world's vertices in one flat loop over
// all of them): toWorldPoint for each vertex, then finishBody with the box of the result.
__device__ inline void prepareBody(const PrepareArgs& a, int i) {
  Vec2* v = a.worldVertices + static_cast<size_t>(i) * kMaxVertices;
  const int count = a.vertexCount[i];
  toWorld(a.local + static_cast<size_t>(i) * kMaxVertices, count, Vec2{a.x[i], a.y[i]}, a.angle[i], v);
  finishBody(a, i, boundingBox(v, count));
}

// Phase 3 for candidate pair (a, b): the prefilter (phases.hpp), then the contact geometry. Bodies
// of two worlds never touch. Returns whether they touch; out is written when the prefilter passed.
__device__ inline bool contactOfPair(int a, int b, const Vec2* worldVertices, const int* vertexCount, const Real* x, const Real* y,
                                     const Box* boxes, const Real* invMass, const int* world, Contact& out) {
  if (world[a] != world[b] || !mayTouch(invMass[a], invMass[b], boxes[a], boxes[b])) return false;
  out = computeContact(worldVertices + static_cast<size_t>(a) * kMaxVertices, vertexCount[a], Vec2{x[a], y[a]},
                       worldVertices + static_cast<size_t>(b) * kMaxVertices, vertexCount[b], Vec2{x[b], y[b]});
  return out.touching;
}

// The first half of contactOfPair: the prefilter and the separating-axis test, which reject most
// pairs cheaply. contactOfPair is false whenever this is (it runs the same test first), so a driver
// may test every pair with this and run contactOfPair on the survivors only.
__device__ inline bool overlapOfPair(int a, int b, const Vec2* worldVertices, const int* vertexCount, const Box* boxes, const Real* invMass,
                                     const int* world) {
  if (world[a] != world[b] || !mayTouch(invMass[a], invMass[b], boxes[a], boxes[b])) return false;
  return convexOverlap(worldVertices + static_cast<size_t>(a) * kMaxVertices, vertexCount[a],
                       worldVertices + static_cast<size_t>(b) * kMaxVertices, vertexCount[b]);
}

// Phase 5 for one body: its contact impulses summed in the CPU's order (the CPU loop visits contact
// k's a then b, and a body's contacts as b, which all have a < it, come before its contacts as a),
// then the motion events' view of it. asB(q), q < countB: its contacts as b, in contact order;
// [firstA, endA): its contacts as a. No atomics: the same sums in the same order on every driver.
// onBody: the sum of its contact impulses (N s), as the CPU sums it (the frames' contact_force).
template <class ContactsAsB>
__device__ inline MotionBody gatherBody(const PairBody& b, VelocityChange total, ContactsAsB asB, int countB, int firstA, int endA,
                                        const PairContact* contacts, const PairSlot* slots, bool isVessel, Vec2* vesselImpulse,
                                        Vec2& onBody) {
  onBody = Vec2{0, 0};
  for (int q = 0; q < countB; ++q) {
    const int k = asB(q);
    const Vec2 j = slots[k].impulse;
    if (j.x == 0 && j.y == 0) continue;
    onBody += j;
    addContactImpulse(b, j, contacts[k].geometry.point, total);
  }
  for (int k = firstA; k < endA; ++k) {
    const Vec2 j = slots[k].impulse;
    if (j.x == 0 && j.y == 0) continue;
    onBody += -j;
    addContactImpulse(b, -j, contacts[k].geometry.point, total);
  }
  if (isVessel) *vesselImpulse = onBody;
  return MotionBody{b.kind, b.dof, b.position, b.angle, b.velocity + total.dv, b.omega + total.domega};
}

// The end of phase 5 for body i: its moved state written back, and its world's vessel record.
__device__ inline void writeBackBody(const MotionBody& b, int i, Real* x, Real* y, Real* angle, Real* vx, Real* vy, Real* omega,
                                     bool isVessel, WorldStepRecord& record) {
  x[i] = b.position.x;
  y[i] = b.position.y;
  angle[i] = b.angle;
  vx[i] = b.velocity.x;
  vy[i] = b.velocity.y;
  omega[i] = b.omega;
  if (!isVessel) return;
  record.vesselPosition = b.position;
  record.vesselVelocity = b.velocity;
  record.vesselAngle = b.angle;
}
#endif

}  // namespace gem::cuda
