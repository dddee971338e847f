// Internal to framework/cuda: DeviceState, everything the device keeps for one DeviceStep (the
// world, the step's buffers, the records, the graph), and what the backend's files share about it.
#pragma once
#include <cuda_runtime.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/api/device_array.hpp"
#include "framework/cuda/device_step.hpp"
#include "geometry/contact.hpp"

namespace gem::cuda {

// The step graph's buffers: every reallocation counts in graphArrayReallocations(), and a captured
// graph that saw another count is captured again (device_state.cu's bakedValues).
template <class T>
using GraphArray = DeviceArray<T, DeviceArrayUse::Graph>;

// Scratch for the re-sort and the topology edits, outside the GraphArrays: growing it must not
// look like a change of the graph's buffers. It grows with room to spare: a break adds a body or
// two, and a cudaFree on each would wait for the whole device (every other simulation's stream).
using ReorderScratch = DeviceArray<unsigned char, DeviceArrayUse::Scratch>;

// What the host sets before each launch of the step graph (pinned; the graph's first node copies it).
struct BatchControl {
  long firstStep;  // index of the batch's first step
  Real dt;
  int steps;  // steps to run, at most the ring's length
};

// Why the batch's loop stopped (StepStats::halt).
enum : int { kRunning = 0, kHaltDone = 1, kHaltBreak = 2, kHaltOverflow = 3 };

// The batch's counters, on the device (kernels read and write them), copied to pinned host memory
// at the end of the batch: the one host sync of a batch of steps.
struct StepStats {
  int recordCount[kMaxRecordStreams];  // RecordSink's counters, over the whole batch
  int recordBegin[kMaxRecordStreams];  // at the start of the step: a step that fails rewinds to them
  int candidatesNeeded;                // the broadphase's pair count, even past the capacity
  int candidates;                      // min(needed, capacity)
  int contacts, previousContacts;
  int overflow;         // 1: candidates or records past their capacity: the step left the state alone
  int stepsDone, halt;  // completed steps of the batch, and why it stopped
};

// The resident driver's own buffers (resident.cu): the worlds' members and per-world scratch.
struct ResidentState;
void destroyResident(ResidentState*);
struct ResidentDeleter {
  void operator()(ResidentState* r) const { destroyResident(r); }
};

struct DeviceState {
  // World (structure of arrays, as World).
  GraphArray<std::int64_t> id;
  GraphArray<BodyKind> kind;
  GraphArray<int> vertexCount, dof;
  GraphArray<Vec2> local;
  GraphArray<Real> x, y, angle, vx, vy, omega, area, thickness, mass, invMass, invInertia, gyration2, gyrationX2, gyrationY2,
      principalAngle;
  GraphArray<Real> radius;  // bounding radius: what a device broadphase tests (docs/model.md 9)
  GraphArray<unsigned char> isLarge;
  GraphArray<int> large;
  std::vector<int> largeHost;  // the same slots, ascending: a topology edit shifts them on the host
  int largeCount = 0;
  int n = 0;
  // Worlds (DeviceStep::upload): each body's, and each world's vessel slot (-1: none), on the host
  // and on the device (a re-sort moves them without a new graph).
  int worlds = 1;
  GraphArray<int> world;
  std::vector<int> worldHost;
  std::vector<int> vesselHost{-1};
  GraphArray<int> vessel;
  GraphArray<WorldStepRecord> worldStats;  // this step's, per world
  // One world: each body's |sum of its contact impulses| over the last step, N s, by id (ids are
  // dense), for the frames' contact_force; 0 for a body without contact.
  GraphArray<Real> contactImpulseOfId;
  Real cell = 1;
  Real cellSetting = 0;  // uniform_grid's cell_size (0: twice the largest floe radius)
  unsigned tableSize = 64;
  int tableBits = 6;
  // Per step, per body.
  GraphArray<Vec2> worldVertices;
  GraphArray<Box> boxes;
  GraphArray<PairBody> pairBodies;
  GraphArray<SoloBody> soloBodies;
  GraphArray<VelocityChange> changes;
  GraphArray<MotionBody> motionBodies;
  // Grid.
  GraphArray<unsigned> cellKey, cellKeySorted;
  GraphArray<int> slot, slotSorted, cellStart, cellEnd;
  GraphArray<int> partnerCount, partnerOffset;
  GraphArray<int> largeChunk;  // per large body and chunk of bodies: its hits, then their offset in the row
  // A device broadphase (nullptr: the grid above): its pairs as keys, sorted into candA/candB.
  std::unique_ptr<CudaBroadphase> broadphase;
  GraphArray<unsigned long long> candKey, candKeySorted;
  GraphArray<int> candCount;
  int slotBits = 1;
  // Candidates and contacts.
  GraphArray<int> candA, candB, flag, flagOffset;
  GraphArray<Contact> candContact;
  GraphArray<int> contactA, contactB, bKey, bKeySorted, bIndex, bIndexSorted;
  GraphArray<PairContact> contacts;
  GraphArray<PairSlot> slots;
  GraphArray<unsigned long long> contactKey, previousKeys, sortedKeys;
  int idBits = 0;  // a contact's id pair is keyed (lo << idBits) | hi: a short radix sort
  // Records, over a batch of steps: the rows of each record stream (framework/api/record_stream.hpp).
  GraphArray<unsigned char> records[kMaxRecordStreams];
  int recordStride[kMaxRecordStreams] = {};
  int recordStreams = 0;
  unsigned haltStreams = 0;                       // streams whose rows end the batch (topology follows)
  int recordCapacity = 0;                         // rows of each record buffer (grows when a single step needs more)
  std::int64_t idStride = std::int64_t(1) << 62;  // several worlds: ids are world x idStride + own id
  GraphArray<StepStats> stats;
  GraphArray<StepContext> ctx;  // written on the device at the start of each step
  GraphArray<BatchControl> control;
  GraphArray<StepRecord> ring;             // one record per step of the batch
  GraphArray<WorldStepRecord> worldRing;   // ringSize x worlds
  int ringSize = 16;                       // simulation.copy_back_every
  int block = kBlock;                      // simulation.cuda_block_size
  StepStats* h_stats = nullptr;            // pinned
  BatchControl* h_control = nullptr;       // pinned: the graph's first node copies it to control
  StepRecord* h_ring = nullptr;            // pinned, ringSize records
  WorldStepRecord* h_worldRing = nullptr;  // pinned, ringSize x worlds records
  GraphArray<unsigned char> temp;          // CUB scratch, sized before capture
  // Topology edits and the rows they fetch: kept here, because a cudaFree waits for the whole
  // device, every other simulation's stream included (a sweep runs many at once).
  GraphArray<int> editRemoved, editOrder, fetchSlots;
  GraphArray<Real> fetchRows;
  GraphArray<unsigned long long> resortBounds;  // the re-sort along the curve's, likewise
  GraphArray<unsigned long long> resortKeys, resortKeysSorted;
  GraphArray<int> resortSlots, resortSlotsSorted;
  ReorderScratch permuteScratch, sortScratch;
  size_t tempBytes = 0;
  int capacity = 0;  // candidate (and contact) capacity the graph was captured for
  cudaStream_t stream = nullptr;
  cudaGraphExec_t graph = nullptr;
  long captures = 0;  // step graphs captured and instantiated (GEM_CUDA_TIMING)
  double captureSeconds = 0;
  std::vector<std::unique_ptr<CudaEventDriver>> pairEvents, soloEvents, motionEvents;
  std::unique_ptr<ResidentState, ResidentDeleter> resident;  // set: the resident driver steps (resident.cu)

  DeviceState() {
    GEM_CUDA_CHECK(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking));
    GEM_CUDA_CHECK(cudaMallocHost(&h_stats, sizeof(StepStats)));
    GEM_CUDA_CHECK(cudaMallocHost(&h_control, sizeof(BatchControl)));
    *h_stats = StepStats{};  // pinned memory starts undefined; previousContacts is read before a first step
    stats.ensure(1);
    ctx.ensure(1);
    control.ensure(1);
    setRing(ringSize, worlds);
    GEM_CUDA_CHECK(cudaMemset(stats.get(), 0, sizeof(StepStats)));
  }
  ~DeviceState() {
    if (graph) cudaGraphExecDestroy(graph);
    if (h_stats) cudaFreeHost(h_stats);
    if (h_control) cudaFreeHost(h_control);
    if (h_ring) cudaFreeHost(h_ring);
    if (h_worldRing) cudaFreeHost(h_worldRing);
    if (stream) cudaStreamDestroy(stream);
  }
  void setRing(int size, int worldCount) {
    dropGraph();  // first: the graph's last nodes copy into the pinned rings freed here
    if (h_ring) GEM_CUDA_CHECK(cudaFreeHost(h_ring));
    if (h_worldRing) GEM_CUDA_CHECK(cudaFreeHost(h_worldRing));
    h_ring = nullptr, h_worldRing = nullptr;
    ringSize = size;
    const size_t worldRecords = static_cast<size_t>(size) * static_cast<size_t>(worldCount);
    GEM_CUDA_CHECK(cudaMallocHost(&h_ring, sizeof(StepRecord) * static_cast<size_t>(size)));
    GEM_CUDA_CHECK(cudaMallocHost(&h_worldRing, sizeof(WorldStepRecord) * worldRecords));
    ring.ensure(static_cast<size_t>(size));
    worldRing.ensure(worldRecords);
    worldStats.ensure(static_cast<size_t>(worldCount));
  }
  // The step graph no longer matches the state (n, a buffer, the ring changed): the next batch
  // captures it anew. (Updating the executable graph in place, cudaGraphExecUpdate, was tried:
  // on the batched load study it saved 0.12 s of 4 s; instantiating is not where the time goes.)
  void dropGraph() {
    if (graph) GEM_CUDA_CHECK(cudaGraphExecDestroy(graph));
    graph = nullptr;
  }
};

inline int bitsFor(unsigned long long v) {
  int bits = 1;
  while (bits < 64 && (1ull << bits) <= v) ++bits;
  return bits;
}

// The host's plain cudaMemcpy and cudaMemset calls (uploads, a regrowth that keeps its contents)
// go to the legacy default stream, and a host-to-device copy or a memset may return before the
// device has done it; the simulation's stream is non-blocking, so nothing orders its work after
// them. Called before work is enqueued on d.stream: that work then sees every upload whole.
inline void awaitHostCopies() { GEM_CUDA_CHECK(cudaStreamSynchronize(cudaStreamLegacy)); }

// Everything that follows from n and the ids: the hash table, the key widths, the per-step buffers
// (device_state.cu).
void sizeForBodies(DeviceState& d, std::int64_t nextId);
// DeviceStep::editBodies on a state (edits.cu): the resident driver makes its state dense with it
// after a launch whose breaks added bodies in the kernel.
bool editDeviceBodies(DeviceState& d, const std::vector<int>& removedSlots, const World& from, int firstAdded,
                      const std::vector<int>& addedWorlds, const std::vector<int>& vesselDofs);
// The state's rows permuted (new slot k holds old slot order[k]; o: the same order on the device),
// the host's lists of worlds, large bodies and vessels with them (edits.cu): the re-sort along the
// curve, on the device-wide driver and after the resident kernel's.
void permuteDeviceState(DeviceState& d, const int* o, const std::vector<int>& order);
// Each world's vessel slot, to the device (device_state.cu).
void uploadVessels(DeviceState& d);
// The resident driver's contact keys of the last step, (lo << 32) | hi, sorted (world 0), and the
// same set before its next launch (resident.cu; checkpoints).
std::vector<unsigned long long> residentPreviousKeys(const DeviceState& d);
void setResidentPreviousKeys(DeviceState& d, std::vector<unsigned long long> keys);

}  // namespace gem::cuda
