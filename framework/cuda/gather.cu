// Phase 5 of a step, around the motion events: each body's contact impulses gathered in the
// CPU's order, then the motion written back into the state.
#include "framework/api/cuda_check.hpp"
#include "framework/cuda/body_phases.cuh"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"

namespace gem::cuda {
namespace {

__device__ inline int lowerBound(const int* v, int n, int x) {
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (v[mid] < x)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

// Each body sums its contacts in contact order: the CPU loop visits contact k's a then b, and a
// body's contacts as b (a < i) all come before its contacts as a (sorted by a). No atomics.
// contactA and bKeySorted are sorted with the padding (slot n) last, so searching the whole
// capacity finds only real contacts.
__global__ void gatherKernel(int n, const int* world, const int* vesselSlot, const PairBody* bodies, const VelocityChange* changes,
                             int capacity, const int* contactA, const int* bKeySorted, const int* bIndexSorted, const PairContact* contacts,
                             const PairSlot* slots, MotionBody* motion, WorldStepRecord* worldStats, const std::int64_t* id,
                             Real* impulseOfId) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const bool isVessel = i == vesselSlot[world[i]];
  const int firstB = lowerBound(bKeySorted, capacity, i);
  int endB = firstB;
  while (endB < capacity && bKeySorted[endB] == i) ++endB;
  const int firstA = lowerBound(contactA, capacity, i);
  int endA = firstA;
  while (endA < capacity && contactA[endA] == i) ++endA;
  Vec2 onBody;
  motion[i] = gatherBody(
      bodies[i], changes[i], [&](int q) { return bIndexSorted[firstB + q]; }, endB - firstB, firstA, endA, contacts, slots, isVessel,
      &worldStats[world[i]].vesselImpulse, onBody);
  if (impulseOfId) impulseOfId[id[i]] = norm(onBody);
}

// The only write of the state; skipped when the step overflowed, so it can simply be run again.
__global__ void writeBackKernel(int n, const int* world, const int* vesselSlot, const MotionBody* motion, Real* x, Real* y, Real* angle,
                                Real* vx, Real* vy, Real* omega, const StepStats* stats, WorldStepRecord* worldStats) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= n || stats->overflow) return;
  const bool isVessel = i == vesselSlot[world[i]];
  writeBackBody(motion[i], i, x, y, angle, vx, vy, omega, isVessel, worldStats[world[i]]);
}

}  // namespace

void enqueueGather(DeviceState& d) {
  cudaStream_t s = d.stream;
  const int n = d.n, capacity = d.capacity, block = d.block;
  gatherKernel<<<blocksFor(n, block), block, 0, s>>>(n, d.world.get(), d.vessel.get(), d.pairBodies.get(), d.changes.get(), capacity,
                                                     d.contactA.get(), d.bKeySorted.get(), d.bIndexSorted.get(), d.contacts.get(),
                                                     d.slots.get(), d.motionBodies.get(), d.worldStats.get(), d.id.get(),
                                                     d.worlds == 1 ? d.contactImpulseOfId.get() : nullptr);
  GEM_CUDA_CHECK_LAUNCH();
}

void enqueueWriteBack(DeviceState& d) {
  cudaStream_t s = d.stream;
  const int n = d.n, block = d.block;
  StepStats* stats = d.stats.get();
  writeBackKernel<<<blocksFor(n, block), block, 0, s>>>(n, d.world.get(), d.vessel.get(), d.motionBodies.get(), d.x.get(), d.y.get(),
                                                        d.angle.get(), d.vx.get(), d.vy.get(), d.omega.get(), stats, d.worldStats.get());
  GEM_CUDA_CHECK_LAUNCH();
}

}  // namespace gem::cuda
