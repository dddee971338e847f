// Internal to framework/cuda: the resident driver (docs/architecture.md "CUDA drivers"). Each world
// runs whole steps inside one thread block: prepare, its own pairs, narrowphase, pair events, solo
// events, gather, motion, write-back and the topology phase (flexural breaking: ResidentBreaking),
// with block barriers between the phases and many steps per launch. A launch of several worlds is
// cooperative (every block resident at once): a grid barrier per phase boundary keeps the worlds in
// lockstep, so that a step that overflows a buffer, or whose breaks need more room than a world
// has, stops every world at the same step, as the device-wide driver's batch does.
//
// The per-body and per-pair work is body_phases.cuh's, the device-wide driver's own; the events are
// the built-in evaluators, compiled into the kernel (resident_events.cu), so no physics is written
// again. Plugin events have no place in the kernel: a run with one uses the device-wide driver.
#pragma once
#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "framework/api/event_api.hpp"
#include "framework/api/record_stream.hpp"
#include "framework/cuda/body_phases.cuh"
#include "framework/cuda/device_step.hpp"

namespace gem::cuda {

// Threads per world: 16 warps, so that the narrowphase and the events of a thesis field (about 600
// candidate pairs, 60 contacts) take a round or two. At 128 registers a thread (the clipping's
// needs set the whole kernel's) one such block fills a multiprocessor's registers: one world a
// multiprocessor at a time (docs/performance.md 4.4).
constexpr int kResidentBlock = 512;
// The most events of each phase the kernel runs (a scenario has a handful).
constexpr int kResidentMaxEvents = 16;

// An event of the step as the kernel runs it: its place in resident_events.cu's table, and where
// its Params sit in each world's row of parameters.
struct ResidentEventCall {
  int kind;
  int paramsOffset;  // bytes into the world's row, 16-aligned
};
struct ResidentProgram {
  int pairCount = 0, soloCount = 0, motionCount = 0;
  ResidentEventCall pair[kResidentMaxEvents], solo[kResidentMaxEvents], motion[kResidentMaxEvents];
  // The topology phase in the kernel: where flexural_breaking's Params sit in each world's row
  // (residentTopologyKind), or -1 when the kernel does not run the scenario's topology events
  // (none, or one it does not hold): a step with their rows then ends the launch for the host's.
  int breakingOffset = -1;
  int breakingStream = -1;  // the record stream of its requests (the host's halt takes it out)
};

// The phases the kernel times (ResidentControl::phaseCycles, kResidentPhaseNames).
constexpr int kResidentPhases = 14;

// What the worlds of a launch share on the device: the step's counters, double-buffered by the
// step's parity so that one can be read while the next step fills the other.
struct ResidentControl {
  int candidates[2], contacts[2], overflow[2], halt[2];
  int candidatesNeeded;  // the most any world needed in the launch (a capacity to grow to)
  int recordBegin[kMaxRecordStreams];
  int stepsDone, haltReason;
  // Where block 0's time went, in clock cycles, by phase (kResidentPhaseNames): GEM_CUDA_TIMING=1
  // prints them when the state goes.
  long long phaseCycles[kResidentPhases];
  long long pairCounts[3];  // block 0's first world, over the launch: candidate pairs, overlapping, contacts
  int verticesNeeded;       // the most vertices a world had (the next launch's shared memory for them)
  int floesBroken;          // by the kernel's topology phase, every world (the state is made dense after)
  int resorted;             // 1: a world re-sorted its members along the curve (the state follows after)
};
// The phases' names, in the kernel's order.
inline constexpr const char* kResidentPhaseNames[kResidentPhases] = {
    "world vertices",   "boxes and views", "sweep sort", "pairs", "pair sort",     "separating axes",
    "contact geometry", "onset",           "events",     "sorts", "first barrier", "gather, motion, write-back",
    "second barrier",   "step edges"};

// The rows of a body the kernel writes when a break adds it (PrepareArgs holds them read-only).
struct ResidentBodyRows {
  std::int64_t* id;
  BodyKind* kind;
  int *vertexCount, *dof, *world;
  Vec2* local;
  Real *area, *thickness, *mass, *invMass, *invInertia, *gyration2, *gyrationX2, *gyrationY2, *principalAngle, *radius;
  unsigned char* isLarge;
};

// Breaks in the kernel: each world may add up to `spare` bodies in a launch, its t-th into the slot
// spareFirst + t x worlds + w past the state's bodies (spareUsed[w] of them taken: the slots a
// launch used lie together at the front, and the host reads back only those); a world
// whose step asks for more stops the launch there, and the host's topology phase does that step.
// A body that leaves is marked in gone[slot] and dropped from its world's members; its slot keeps
// its rows until the host makes the state dense again (runResident, DeviceStep::editBodies).
struct ResidentBreaking {
  int offset;  // ResidentProgram::breakingOffset (-1: none in the kernel)
  int spare, spareFirst;
  int* spareUsed;        // per world
  std::int64_t* nextId;  // per world: the case's next own id
  unsigned char* gone;   // per slot, spare slots included
  ResidentBodyRows rows;
};

struct ResidentArgs {
  PrepareArgs prepare;  // the world's arrays, cellKey nullptr
  Real *x, *y, *angle, *vx, *vy, *omega;
  const int* vessel;  // per world: its vessel's slot, -1 none
  MotionBody* motion;
  Real* impulseOfId;  // one world: |its contact impulses| by body id (the frames' contact_force); else null
  // Worlds: world w's bodies are members[memberBegin[w] .. memberBegin[w] + memberCount[w]), in the
  // order of its own run (ascending slots at a launch's start; the bodies a break adds after the
  // others; a re-sort in the kernel reorders them, and the host permutes the rows to match after the
  // launch), with room for the spare bodies a launch may add.
  int* members;
  const int* memberBegin;
  int* memberCount;
  int worlds;
  ResidentBreaking breaking;
  // The re-sort along the curve (docs/model.md 8) in the kernel, every kResortPeriod steps after the
  // topology phase, as the host's: each world's members ordered by their curve keys (the slots stay;
  // the host permutes the state to the members' order after the launch). placeScratch: bodySort
  // ints a world.
  bool resort;
  int* placeScratch;
  // Per-world scratch: `capacity` candidate pairs, pow2 of it for the sorts, `bodySort` for the sweep.
  int capacity, capacitySort, bodySort;
  unsigned long long *sweepKeys, *pairKeys, *idKeys, *bKeys, *previous;
  int* previousCount;
  Contact* candContact;
  int *flag, *survivors;  // flag: 2 x (capacity + 1) a world
  int *contactA, *contactB;
  PairContact* contacts;
  PairSlot* slots;
  // Events.
  ResidentProgram program;
  const unsigned char* params;  // worlds x paramsStride bytes
  int paramsStride;
  RecordSink sink;
  unsigned haltStreams;
  // The launch.
  long firstStep;
  Real dt;
  int steps;
  bool clipByThread;        // contact geometry a thread a pair (contactOfPair) instead of a warp a pair
  std::size_t sharedBytes;  // the launch's dynamic shared memory (residentSharedBytes)
  StepRecord* ring;
  WorldStepRecord* worldRing;
  ResidentControl* control;
};

enum ResidentPhase : int { kResidentPair = 0, kResidentSolo = 1, kResidentMotion = 2 };

// resident_events.cu: the built-in events the kernel holds. Returns the event's kind and the size
// of its Params, or -1 when the kernel does not hold an event of that name and phase.
int residentEventKind(const std::string& name, ResidentPhase phase, std::size_t* paramsSize);
// The topology events the kernel holds (only flexural_breaking): true, with the size of its
// Params, when the kernel can run `name` itself.
bool residentTopologyEvent(const std::string& name, std::size_t* paramsSize);
// A launch's dynamic shared memory holds, for the world a block steps: the sweep's keys, the boxes
// and inverse masses (bodySort of each), the offsets of each body's vertices and of each body's
// candidate pairs (bodySort + 1 of each), then as many of the world's vertices as fit in the rest
// (the narrowphase reads them there).
constexpr std::size_t kResidentSharedBytes = 160 * 1024;
// The bytes before the vertices, 16-aligned.
__host__ __device__ constexpr std::size_t residentBodyBytes(int bodySort) {
  return (static_cast<std::size_t>(bodySort) * (sizeof(unsigned long long) + sizeof(Box) + sizeof(Real)) +
          2 * (static_cast<std::size_t>(bodySort) + 1) * sizeof(int) + 15) /
         16 * 16;
}
// The dynamic shared memory of a launch whose largest world has `bodies` bodies and room for
// `vertices` of its vertices, at most kResidentSharedBytes: without the vertices when they do not
// fit (the narrowphase reads them from global memory), 0 when the bodies' part does not either.
// Only what is used is asked for: the rest of the multiprocessor's 256 KB is its L1 cache.
std::size_t residentSharedBytes(int bodies, int vertices);
// The kernel, launched (cooperatively when grid > 1) on the stream with `shared` bytes of dynamic
// shared memory (residentSharedBytes of the largest world).
void launchResident(const ResidentArgs& args, int grid, std::size_t shared, cudaStream_t stream);
// Blocks of kResidentBlock threads that one multiprocessor keeps resident at once.
int residentBlocksPerMultiprocessor(std::size_t shared);

}  // namespace gem::cuda
