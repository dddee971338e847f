// The step graph: the CUB calls of a step, one whole step enqueued phase by phase, the batch of
// steps captured as one CUDA graph with a device-side loop, and the host's batch loop around it.
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>

#include <algorithm>
#include <chrono>
#include <cstddef>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/device_step.hpp"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"

// The device phases of a step (see cuda_simulation.hpp for the list), one file each (step_phases.cuh).
// The rules every driver applies (the prefilter, degrees of freedom, what an impulse does to a body,
// the time of a step) come from framework/step/phases.hpp, the same functions the CPU stepper calls;
// what the phases' files write is how the device runs them in parallel while keeping the CPU's
// order of every sum (tests: golden hashes, CUDA vs CPU).

namespace gem::cuda {

// ---- CubCalls ----------------------------------------------------------------------------------

void CubCalls::check(cudaError_t status, const size_t& need, const char* what) {
  ::gem::cuda::check(status, what, __FILE__, __LINE__);
  if (sizing) bytes = std::max(bytes, need);
}
void CubCalls::cellSort(int n, int bits) {
  size_t need = sizing ? 0 : bytes;
  check(cub::DeviceRadixSort::SortPairs(temp, need, d.cellKey.get(), d.cellKeySorted.get(), d.slot.get(), d.slotSorted.get(), n, 0, bits,
                                        d.stream),
        need, "cub SortPairs (cells)");
}
void CubCalls::scanPartners(int n) {
  size_t need = sizing ? 0 : bytes;
  check(cub::DeviceScan::ExclusiveSum(temp, need, d.partnerCount.get(), d.partnerOffset.get(), n + 1, d.stream), need,
        "cub ExclusiveSum (partners)");
}
void CubCalls::sortCandidates(int capacity, int bits) {
  size_t need = sizing ? 0 : bytes;
  check(cub::DeviceRadixSort::SortKeys(temp, need, d.candKey.get(), d.candKeySorted.get(), capacity, 0, bits, d.stream), need,
        "cub SortKeys (device broadphase pairs)");
}
void CubCalls::scanFlags(int capacity) {
  size_t need = sizing ? 0 : bytes;
  check(cub::DeviceScan::ExclusiveSum(temp, need, d.flag.get(), d.flagOffset.get(), capacity + 1, d.stream), need,
        "cub ExclusiveSum (flags)");
}
void CubCalls::sortKeys(int capacity, int bits) {
  size_t need = sizing ? 0 : bytes;
  check(cub::DeviceRadixSort::SortKeys(temp, need, d.contactKey.get(), d.sortedKeys.get(), capacity, 0, bits, d.stream), need,
        "cub SortKeys (contact ids)");
}
void CubCalls::sortB(int capacity, int bits) {
  size_t need = sizing ? 0 : bytes;
  check(cub::DeviceRadixSort::SortPairs(temp, need, d.bKey.get(), d.bKeySorted.get(), d.bIndex.get(), d.bIndexSorted.get(), capacity, 0,
                                        bits, d.stream),
        need, "cub SortPairs (b side)");
}

namespace {

// ---- the step's edges ----------------------------------------------------------------------------

// The batch's start: its record counters and step count (previousContacts carries over).
__global__ void beginBatchKernel(StepStats* s) {
  for (int q = 0; q < kMaxRecordStreams; ++q) s->recordCount[q] = 0;
  s->stepsDone = 0;
  s->halt = kRunning;
}

// One block for the start and the end of a step: its threads share the worlds' records (a lone
// run has one; a sweep's batch one per case), and no launch is added per step for them.
static unsigned stepEdgeThreads(int worlds) { return static_cast<unsigned>(std::min(std::max(worlds, 32), 1024)); }

// A step's start: its context (the host's formula, time = index x dt), the counters it may rewind
// to, and each world's record emptied.
__global__ void beginStepKernel(const BatchControl* c, StepStats* s, StepContext* ctx, int worlds, WorldStepRecord* worldStats) {
  for (int w = threadIdx.x; w < worlds; w += blockDim.x) worldStats[w] = WorldStepRecord{0, {0, 0}, {0, 0}, {0, 0}, 0};
  if (threadIdx.x != 0) return;
  const long step = c->firstStep + s->stepsDone;
  *ctx = StepContext{c->dt, stepTime(step, c->dt), step};
  for (int q = 0; q < kMaxRecordStreams; ++q) s->recordBegin[q] = s->recordCount[q];
  s->overflow = 0;
}

// After the pair events: records past a buffer's end fail the step like too many candidates do.
__global__ void checkRecordsKernel(StepStats* s, int capacity) {
  for (int q = 0; q < kMaxRecordStreams; ++q)
    if (s->recordCount[q] > capacity) s->overflow = 1;
}

// A step's end: its record into the ring, and whether the loop goes on. It stops when the batch is
// done, after a step that recorded rows a topology event reads (haltStreams: the host's topology
// phase comes next), or at a step that overflowed (rewound: the host grows the buffers and runs it
// again).
__global__ void endStepKernel(cudaGraphConditionalHandle loop, bool inGraph, const BatchControl* c, StepStats* s, StepRecord* ring,
                              int worlds, const WorldStepRecord* worldStats, WorldStepRecord* worldRing, unsigned haltStreams) {
  // The worlds' records beside the step's, at its place in the ring (read before thread 0 moves on).
  const int done = s->stepsDone;
  if (!s->overflow)
    for (int w = threadIdx.x; w < worlds; w += blockDim.x) worldRing[static_cast<size_t>(done) * worlds + w] = worldStats[w];
  __syncthreads();
  if (threadIdx.x != 0) return;
  if (s->overflow) {
    for (int q = 0; q < kMaxRecordStreams; ++q) s->recordCount[q] = s->recordBegin[q];
    s->halt = kHaltOverflow;
  } else {
    StepRecord r{s->candidates, s->contacts, {}};
    bool topology = false;
    for (int q = 0; q < kMaxRecordStreams; ++q) {
      r.recordEnd[q] = s->recordCount[q];
      topology = topology || ((haltStreams >> q) & 1u && s->recordCount[q] > s->recordBegin[q]);
    }
    ring[s->stepsDone] = r;
    ++s->stepsDone;
    if (topology)
      s->halt = kHaltBreak;
    else if (s->stepsDone >= c->steps)
      s->halt = kHaltDone;
  }
  if (inGraph) cudaGraphSetConditional(loop, s->halt == kRunning ? 1u : 0u);
}

// Between two steps of the chained batch graph (captureStep): the next step runs only if the batch
// is still running. A kernel of the parent graph upstream of the conditional node it sets.
__global__ void gateStepKernel(cudaGraphConditionalHandle next, const StepStats* s) {
  cudaGraphSetConditional(next, s->halt == kRunning ? 1u : 0u);
}

// ---- a step, a batch -----------------------------------------------------------------------------

// Enqueues one whole step on d.stream: captured as the body of the batch graph's loop (inGraph),
// or launched directly when graphs are off (GEM_CUDA_GRAPH=0, for debugging).
void enqueueStep(DeviceState& d, cudaGraphConditionalHandle loop, bool inGraph) {
  cudaStream_t s = d.stream;
  const int n = d.n, capacity = d.capacity, block = d.block;
  const unsigned largeKey = d.tableSize;  // past every cell: large bodies sort to the end
  size_t bytes = d.tempBytes;
  CubCalls cubCalls{d, d.temp.get(), bytes, false};
  StepStats* stats = d.stats.get();

  beginStepKernel<<<1, stepEdgeThreads(d.worlds), 0, s>>>(d.control.get(), stats, d.ctx.get(), d.worlds, d.worldStats.get());
  GEM_CUDA_CHECK_LAUNCH();

  // 1. World vertices, boxes, views, cell keys.
  enqueuePrepare(d, largeKey);

  // 2. Broadphase: the candidate pairs, sorted by (a, b).
  const int* candidatesNeeded = enqueueBroadphase(d, cubCalls, largeKey);

  // 3. Narrowphase, compaction in order (with padding), onset, the two sorts.
  enqueueContacts(d, cubCalls, candidatesNeeded);

  // 4. Two-body events write into each contact's slot; solo events from the start-of-step state.
  const int records = d.recordCapacity;
  RecordSink sink{};
  for (int q = 0; q < d.recordStreams; ++q)
    sink.streams[q] = RecordBuffer{d.records[q].get(), d.recordStride[q], records, &stats->recordCount[q]};
  DevicePairData pairData{d.pairBodies.get(),
                          d.world.get(),
                          d.contactA.get(),
                          d.contactB.get(),
                          d.contacts.get(),
                          d.slots.get(),
                          capacity,
                          block,
                          &stats->contacts,
                          d.ctx.get(),
                          sink,
                          0};
  for (auto& e : d.pairEvents) {
    e->launchPairs(pairData, s);
    ++pairData.event;
  }
  checkRecordsKernel<<<1, 1, 0, s>>>(stats, records);
  GEM_CUDA_CHECK_LAUNCH();
  const DeviceSoloData soloData{d.soloBodies.get(), d.world.get(), d.changes.get(), n, block, d.ctx.get()};
  for (auto& e : d.soloEvents) e->launchSolo(soloData, s);

  // 5. Gather, motion, write back; then the counters to the host.
  enqueueGather(d);
  const DeviceMotionData motionData{d.motionBodies.get(), d.world.get(), n, block, d.ctx.get()};
  for (auto& e : d.motionEvents) e->launchMotion(motionData, s);
  enqueueWriteBack(d);
  enqueueCommitContacts(d);
  endStepKernel<<<1, stepEdgeThreads(d.worlds), 0, s>>>(loop, inGraph, d.control.get(), stats, d.ring.get(), d.worlds, d.worldStats.get(),
                                                        d.worldRing.get(), d.haltStreams);
  GEM_CUDA_CHECK_LAUNCH();
}

// Sizes every buffer for n and the capacity.
void prepareBuffers(DeviceState& d) {
  const size_t cap = static_cast<size_t>(d.capacity);
  d.candA.ensure(cap), d.candB.ensure(cap), d.candContact.ensure(cap), d.flag.ensure(cap + 1), d.flagOffset.ensure(cap + 1);
  d.contactA.ensure(cap), d.contactB.ensure(cap), d.contacts.ensure(cap), d.slots.ensure(cap), d.contactKey.ensure(cap);
  d.sortedKeys.ensure(cap), d.bKey.ensure(cap), d.bKeySorted.ensure(cap), d.bIndex.ensure(cap), d.bIndexSorted.ensure(cap);
  // Records of a whole batch: room for a row per contact in each stream at first; a batch that
  // fills a buffer stops there (the next batch starts them empty), and a single step that passes
  // one grows them all (DeviceStep::run).
  d.recordCapacity = std::max(d.recordCapacity, d.capacity);
  const size_t records = static_cast<size_t>(d.recordCapacity);
  for (int q = 0; q < d.recordStreams; ++q) d.records[q].ensure(records * static_cast<size_t>(d.recordStride[q]));
  d.previousKeys.ensureKeeping(cap, static_cast<size_t>(d.h_stats->previousContacts));

  size_t bytes = 1;
  CubCalls sizing{d, nullptr, bytes, true};
  sizing.cellSort(d.n, bitsFor(d.tableSize));
  sizing.scanPartners(d.n);
  sizing.scanFlags(d.capacity);
  sizing.sortKeys(d.capacity, std::min(64, 2 * d.idBits));
  sizing.sortB(d.capacity, bitsFor(static_cast<unsigned long long>(d.n)));
  if (d.broadphase) {
    d.candKey.ensure(cap), d.candKeySorted.ensure(cap), d.candCount.ensure(1);
    d.broadphase->reserve(d.stream);
    sizing.sortCandidates(d.capacity, 2 * d.slotBits);
  }
  d.temp.ensure(bytes);
  d.tempBytes = bytes;
}

// How the batch graph repeats its step (GEM_CUDA_GRAPH_LOOP): "while" (the default), one copy of
// the step inside a WHILE node whose last kernel decides whether it goes round again; or "chain",
// copy_back_every copies of the step one after the other, each inside an IF node that a small gate
// kernel between two steps opens while the batch runs. Both run the same kernels in the same order:
// the same results. The chain is a diagnostic of the memcheck report on a shared GPU
// (docs/reliability.md): on an H200 it made the report rare (2 runs in 51, against 3 in 3 with the
// WHILE node in the same session) but not absent, at 2 to 9 % more time a step.
bool graphLoopIsChain() {
  static const bool chain = [] {
    const char* v = std::getenv("GEM_CUDA_GRAPH_LOOP");
    return v && std::string(v) == "chain";
  }();
  return chain;
}
// The chain's length: its copies of the step make the graph's size (about 40 nodes a step), so a
// long copy_back_every runs as several launches of at most this many steps (same results).
constexpr int kChainedSteps = 32;
int stepsPerGraphLaunch(const DeviceState& d) { return graphLoopIsChain() ? std::min(d.ringSize, kChainedSteps) : d.ringSize; }

// Captures a batch as one graph, replayed every batch until n, a capacity or the ring changes:
//   copy the control in -> reset the batch's counters -> the steps (graphLoopIsChain's form; the
//   last kernel of a step decides whether the batch goes on) -> copy the ring and the counters out
//   to pinned memory.
// So a batch of up to copy_back_every steps is one launch and one host sync (thesis 5.7).
void captureStep(DeviceState& d) {
  prepareBuffers(d);
  d.dropGraph();
  // This stream's uploads and memsets finished before the capture: compute-sanitizer otherwise
  // reports reads of "not yet allocated" memory inside a WHILE body (NVIDIA/warp#1406). Only this
  // stream: a device-wide sync would also wait on (and so invalidate) another thread's capture
  // (a sweep runs several simulations on one device).
  GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
  cudaGraph_t graph = nullptr;
  GEM_CUDA_CHECK(cudaGraphCreate(&graph, 0));
  struct Owned {
    cudaGraph_t g;
    ~Owned() { cudaGraphDestroy(g); }
  } owned{graph};
  cudaGraphNode_t controlIn, begin, loop, ringOut, worldRingOut, statsOut;
  GEM_CUDA_CHECK(
      cudaGraphAddMemcpyNode1D(&controlIn, graph, nullptr, 0, d.control.get(), d.h_control, sizeof(BatchControl), cudaMemcpyHostToDevice));
  StepStats* stats = d.stats.get();
  void* beginArgs[] = {&stats};
  cudaKernelNodeParams beginParams{};
  beginParams.func = reinterpret_cast<void*>(beginBatchKernel);
  beginParams.gridDim = dim3(1);
  beginParams.blockDim = dim3(1);
  beginParams.kernelParams = beginArgs;
  GEM_CUDA_CHECK(cudaGraphAddKernelNode(&begin, graph, &controlIn, 1, &beginParams));

  // A conditional node after `after` whose body is one step captured from the stream; `decides`:
  // the handle the step's last kernel sets (WHILE: its own), none in the chain (inGraph false).
  auto addStepNode = [&](cudaGraphNode_t after, cudaGraphConditionalNodeType type, cudaGraphConditionalHandle handle, bool decides) {
    cudaGraphNodeParams params{};
    params.type = cudaGraphNodeTypeConditional;
    params.conditional.handle = handle;
    params.conditional.type = type;
    params.conditional.size = 1;
    cudaGraphNode_t node;
    GEM_CUDA_CHECK(cudaGraphAddNode(&node, graph, &after, nullptr, 1, &params));
    cudaGraph_t body = params.conditional.phGraph_out[0];
    GEM_CUDA_CHECK(cudaStreamBeginCaptureToGraph(d.stream, body, nullptr, nullptr, 0, cudaStreamCaptureModeThreadLocal));
    try {
      enqueueStep(d, handle, decides);
    } catch (...) {
      cudaStreamEndCapture(d.stream, &body);
      throw;
    }
    GEM_CUDA_CHECK(cudaStreamEndCapture(d.stream, &body));
    return node;
  };
  if (!graphLoopIsChain()) {
    cudaGraphConditionalHandle handle;
    GEM_CUDA_CHECK(cudaGraphConditionalHandleCreate(&handle, graph, 1, cudaGraphCondAssignDefault));
    loop = addStepNode(begin, cudaGraphCondTypeWhile, handle, true);
  } else {
    // Step k's IF node opens when the gate before it saw the batch running (the first always: a
    // batch has at least one step). A step past the batch's end leaves every later one closed.
    loop = begin;
    for (int k = 0; k < stepsPerGraphLaunch(d); ++k) {
      cudaGraphConditionalHandle handle;
      GEM_CUDA_CHECK(cudaGraphConditionalHandleCreate(&handle, graph, k == 0 ? 1u : 0u, cudaGraphCondAssignDefault));
      if (k > 0) {
        void* gateArgs[] = {&handle, &stats};
        cudaKernelNodeParams gateParams{};
        gateParams.func = reinterpret_cast<void*>(gateStepKernel);
        gateParams.gridDim = dim3(1);
        gateParams.blockDim = dim3(1);
        gateParams.kernelParams = gateArgs;
        cudaGraphNode_t gate;
        GEM_CUDA_CHECK(cudaGraphAddKernelNode(&gate, graph, &loop, 1, &gateParams));
        loop = gate;
      }
      loop = addStepNode(loop, cudaGraphCondTypeIf, handle, false);
    }
  }

  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&ringOut, graph, &loop, 1, d.h_ring, d.ring.get(),
                                          sizeof(StepRecord) * static_cast<size_t>(d.ringSize), cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&worldRingOut, graph, &loop, 1, d.h_worldRing, d.worldRing.get(),
                                          sizeof(WorldStepRecord) * static_cast<size_t>(d.ringSize) * static_cast<size_t>(d.worlds),
                                          cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaGraphAddMemcpyNode1D(&statsOut, graph, &loop, 1, d.h_stats, stats, sizeof(StepStats), cudaMemcpyDeviceToHost));
  GEM_CUDA_CHECK(cudaGraphInstantiate(&d.graph, graph, 0));
}

// The same batch with every kernel launched from the host, a sync per step (GEM_CUDA_GRAPH=0).
void runBatchUncaptured(DeviceState& d) {
  prepareBuffers(d);
  GEM_CUDA_CHECK(cudaMemcpyAsync(d.control.get(), d.h_control, sizeof(BatchControl), cudaMemcpyHostToDevice, d.stream));
  beginBatchKernel<<<1, 1, 0, d.stream>>>(d.stats.get());
  GEM_CUDA_CHECK_LAUNCH();
  do {
    enqueueStep(d, cudaGraphConditionalHandle{}, false);
    GEM_CUDA_CHECK(cudaMemcpyAsync(d.h_stats, d.stats.get(), sizeof(StepStats), cudaMemcpyDeviceToHost, d.stream));
    GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
  } while (d.h_stats->halt == kRunning);
  GEM_CUDA_CHECK(
      cudaMemcpyAsync(d.h_ring, d.ring.get(), sizeof(StepRecord) * static_cast<size_t>(d.ringSize), cudaMemcpyDeviceToHost, d.stream));
  GEM_CUDA_CHECK(cudaMemcpyAsync(d.h_worldRing, d.worldRing.get(),
                                 sizeof(WorldStepRecord) * static_cast<size_t>(d.ringSize) * static_cast<size_t>(d.worlds),
                                 cudaMemcpyDeviceToHost, d.stream));
}

}  // namespace

std::pair<long, double> DeviceStep::captures() const { return {m_state->captures, m_state->captureSeconds}; }

void DeviceStep::configure(int copyBackEvery, int blockSize) {
  DeviceState& d = *m_state;
  if (copyBackEvery < 1 || blockSize < 32 || blockSize > 1024 || blockSize % 32)
    throw std::invalid_argument("DeviceStep::configure: copy_back_every >= 1, block size a multiple of 32 up to 1024");
  if (copyBackEvery != d.ringSize) d.setRing(copyBackEvery, d.worlds);
  if (blockSize != d.block) d.dropGraph();
  d.block = blockSize;
}

void DeviceStep::run(long firstStep, Real dt, int steps, DeviceBatchResult& result) {
  DeviceState& d = *m_state;
  result.steps.clear(), result.worldSteps.clear();
  for (auto& rows : result.records) rows.clear();
  result.edits = DeviceBodyEdits{};
  result.order.clear(), result.worldBefore.clear();
  result.hostTopology = false;
  result.worlds = d.worlds;
  if (d.n == 0) {
    result.steps.assign(static_cast<size_t>(steps), StepRecord{});
    result.worldSteps.assign(static_cast<size_t>(steps) * static_cast<size_t>(d.worlds), WorldStepRecord{});
    return;
  }
  if (d.resident) {
    runResident(d, firstStep, dt, steps, result);
    return;
  }
  static const bool useGraph = [] {
    const char* v = std::getenv("GEM_CUDA_GRAPH");  // 0: launch the kernels one by one (debugging)
    return !(v && v[0] == '0');
  }();
  long next = firstStep;
  int remaining = steps;
  while (remaining > 0) {
    *d.h_control = BatchControl{next, dt, std::min(remaining, useGraph ? stepsPerGraphLaunch(d) : d.ringSize)};
    if (!useGraph) {
      awaitHostCopies();
      runBatchUncaptured(d);
    } else {
      if (!d.graph) {
        const auto start = std::chrono::steady_clock::now();
        captureStep(d);
        ++d.captures;
        d.captureSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      }
      awaitHostCopies();  // the capture's sizing too (previousKeys.ensureKeeping copies on the device)
      GEM_CUDA_CHECK(cudaGraphLaunch(d.graph, d.stream));
    }
    GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
    const StepStats stats = *d.h_stats;
    const int done = stats.stepsDone;

    // The completed steps' records, appended; their ends shifted past what earlier batches added.
    const StepRecord last = done > 0 ? d.h_ring[done - 1] : StepRecord{};
    int base[kMaxRecordStreams] = {};
    for (int q = 0; q < d.recordStreams; ++q) {
      const size_t stride = static_cast<size_t>(d.recordStride[q]);
      std::vector<unsigned char>& rows = result.records[q];
      base[q] = static_cast<int>(rows.size() / stride);
      rows.resize(rows.size() + static_cast<size_t>(last.recordEnd[q]) * stride);
      d.records[q].download(rows.data() + static_cast<size_t>(base[q]) * stride, static_cast<size_t>(last.recordEnd[q]) * stride);
    }
    for (int k = 0; k < done; ++k) {
      StepRecord r = d.h_ring[k];
      for (int q = 0; q < kMaxRecordStreams; ++q) r.recordEnd[q] += base[q];
      result.steps.push_back(r);
    }
    result.worldSteps.insert(result.worldSteps.end(), d.h_worldRing,
                             d.h_worldRing + static_cast<size_t>(done) * static_cast<size_t>(d.worlds));
    next += done;
    remaining -= done;
    if (stats.halt == kHaltBreak) break;
    if (stats.halt != kHaltOverflow) continue;
    // A step overflowed and left the state alone: grow what it passed, re-capture, run it again.
    if (stats.candidatesNeeded > d.capacity) {
      d.capacity = stats.candidatesNeeded + stats.candidatesNeeded / 2 + 256;
    } else if (done == 0) {
      d.recordCapacity *= 4;  // one step's records alone passed the buffers (a batch that filled them just stops)
    }
    d.dropGraph();
  }
}

}  // namespace gem::cuda
