// Internal to framework/cuda: the resident driver (docs/architecture.md "CUDA drivers"). Each world
// runs whole steps inside one thread block: prepare, its own pairs, narrowphase, pair events, solo
// events, gather, motion and write-back, with block barriers between the phases and many steps per
// launch. A launch of several worlds is cooperative (every block resident at once): a grid barrier
// per phase boundary keeps the worlds in lockstep, so that a step that overflows a buffer or asks
// for a break stops every world at the same step, as the device-wide driver's batch does.
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
// Lanes of each warp that clip contact pairs: all of them (1 and 4 were measured, 4.4).
constexpr int kResidentClipLanes = 32;
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
};

// What the worlds of a launch share on the device: the step's counters, double-buffered by the
// step's parity so that one can be read while the next step fills the other.
struct ResidentControl {
  int candidates[2], contacts[2], overflow[2], halt[2];
  int candidatesNeeded;  // the most any world needed in the launch (a capacity to grow to)
  int recordBegin[kMaxRecordStreams];
  int stepsDone, haltReason;
  // Where block 0's time went, in clock cycles, by phase (kResidentPhaseNames): GEM_CUDA_TIMING=1
  // prints them when the state goes.
  long long phaseCycles[12];
};
// The phases the kernel times (ResidentControl::phaseCycles).
constexpr int kResidentPhases = 12;
inline constexpr const char* kResidentPhaseNames[kResidentPhases] = {"prepare",         "sweep sort",
                                                                     "pairs",           "pair sort",
                                                                     "separating axes", "contact geometry and onset",
                                                                     "events",          "sorts",
                                                                     "first barrier",   "gather, motion, write-back",
                                                                     "second barrier",  "step edges"};

struct ResidentArgs {
  PrepareArgs prepare;  // the world's arrays, cellKey nullptr
  Real *x, *y, *angle, *vx, *vy, *omega;
  const int* vessel;  // per world: its vessel's slot, -1 none
  MotionBody* motion;
  Real* impulseOfId;  // one world: |its contact impulses| by body id (the frames' contact_force); else null
  // Worlds: world w's bodies are members[memberBegin[w] .. memberBegin[w + 1]), ascending slots.
  const int *members, *memberBegin;
  int worlds;
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
  int clipLanes;  // lanes of each warp that compute contact geometry (the rest wait)
  StepRecord* ring;
  WorldStepRecord* worldRing;
  ResidentControl* control;
};

enum ResidentPhase : int { kResidentPair = 0, kResidentSolo = 1, kResidentMotion = 2 };

// resident_events.cu: the built-in events the kernel holds. Returns the event's kind and the size
// of its Params, or -1 when the kernel does not hold an event of that name and phase.
int residentEventKind(const std::string& name, ResidentPhase phase, std::size_t* paramsSize);
// Shared memory for the sweep of a world of up to `bodies` bodies (its keys, boxes and inverse
// masses), or 0 past kResidentSharedBytes: the sweep then reads them from global memory.
std::size_t residentSharedBytes(int bodies);
constexpr std::size_t kResidentSharedBytes = 160 * 1024;
// The kernel, launched (cooperatively when grid > 1) on the stream with `shared` bytes of dynamic
// shared memory (residentSharedBytes of the largest world).
void launchResident(const ResidentArgs& args, int grid, std::size_t shared, cudaStream_t stream);
// Blocks of kResidentBlock threads that one multiprocessor keeps resident at once.
int residentBlocksPerMultiprocessor(std::size_t shared);

}  // namespace gem::cuda
