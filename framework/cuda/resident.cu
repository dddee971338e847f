// The resident driver's host side (resident.cuh): its buffers, the worlds' members, and a batch of
// steps as one launch per copy-back, with the same results (DeviceBatchResult) as the step graph's.
#include "framework/cuda/resident.cuh"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "framework/api/cuda_check.hpp"
#include "framework/api/device_array.hpp"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/step_phases.cuh"

namespace gem::cuda {

struct ResidentState {
  ResidentProgram program;
  DeviceArray<unsigned char> params;
  int paramsStride = 0;
  // The worlds' members, and the slots' worlds they were made from (rebuilt when those change:
  // a topology edit, a re-sort).
  std::vector<int> worldOfMembers;
  bool membersBuilt = false;
  DeviceArray<int> members, memberBegin, previousCount;
  int mostBodies = 0;
  // Per-world scratch (ResidentArgs).
  int capacity = 0, capacitySort = 0, bodySort = 0;
  int startCapacity = 0;  // GEM_CUDA_CAPACITY (tests force the regrowth path with it); 0: 4 x bodies + 256
  DeviceArray<unsigned long long> sweepKeys, pairKeys, idKeys, bKeys, previous;
  DeviceArray<Contact> candContact;
  DeviceArray<int> flag, survivors, contactA, contactB;
  DeviceArray<PairContact> contacts;
  DeviceArray<PairSlot> slots;
  DeviceArray<ResidentControl> control{1};
  ResidentControl* h_control = nullptr;  // pinned
  DeviceArray<int> recordCount{kMaxRecordStreams};
  // A checkpoint's contact keys (world 0), set into previous before the next launch.
  bool previousPending = false;
  std::vector<unsigned long long> pendingPrevious;
  long long phaseCycles[kResidentPhases] = {};  // block 0's, over every launch (GEM_CUDA_TIMING=1 prints them)
  long long pairCounts[3] = {};                 // its first world's candidate pairs, overlapping pairs, contacts
  // World vertices a launch's shared memory has room for: 8 a body at first, then what the largest
  // world needed (ResidentControl::verticesNeeded); GEM_RESIDENT_STAGE_VERTICES=0 keeps them in
  // global memory (for side-by-side timings; the results are the same).
  int vertexRoom = -1;
  long launches = 0, steps = 0;
  ResidentState() { GEM_CUDA_CHECK(cudaMallocHost(&h_control, sizeof(ResidentControl))); }
  ~ResidentState() {
    if (h_control) cudaFreeHost(h_control);
    const char* timing = std::getenv("GEM_CUDA_TIMING");
    if (!timing || timing[0] != '1' || steps == 0) return;
    int device = 0, kHz = 1;
    cudaGetDevice(&device);
    cudaDeviceGetAttribute(&kHz, cudaDevAttrClockRate, device);
    long long total = 0;
    for (long long c : phaseCycles) total += c;
    std::fprintf(stderr, "gem resident driver: %ld launches, %ld steps, block 0 %.2f us a step:", launches, steps,
                 1e3 * static_cast<double>(total) / kHz / static_cast<double>(steps));
    for (int k = 0; k < kResidentPhases; ++k)
      std::fprintf(stderr, "%s %s %.2f", k ? "," : "", kResidentPhaseNames[k],
                   1e3 * static_cast<double>(phaseCycles[k]) / kHz / static_cast<double>(steps));
    std::fprintf(stderr, " (us a step); world 0: %.1f candidate pairs, %.1f overlapping, %.1f contacts a step\n",
                 static_cast<double>(pairCounts[0]) / static_cast<double>(steps),
                 static_cast<double>(pairCounts[1]) / static_cast<double>(steps),
                 static_cast<double>(pairCounts[2]) / static_cast<double>(steps));
  }
};

void destroyResident(ResidentState* r) { delete r; }

namespace {

int powerOfTwoAtLeast(int n) {
  int m = 1;
  while (m < n) m <<= 1;
  return m;
}

// Each world's slots, ascending, one world after the other.
void buildMembers(DeviceState& d, ResidentState& r) {
  const int worlds = d.worlds;
  std::vector<int> begin(static_cast<size_t>(worlds) + 1, 0), members(d.worldHost.size());
  for (int w : d.worldHost) ++begin[static_cast<size_t>(w) + 1];
  r.mostBodies = 0;
  for (int w = 0; w < worlds; ++w) {
    r.mostBodies = std::max(r.mostBodies, begin[static_cast<size_t>(w) + 1]);
    begin[static_cast<size_t>(w) + 1] += begin[static_cast<size_t>(w)];
  }
  std::vector<int> at(begin.begin(), begin.end() - 1);
  for (size_t k = 0; k < d.worldHost.size(); ++k)
    members[static_cast<size_t>(at[static_cast<size_t>(d.worldHost[k])]++)] = static_cast<int>(k);
  r.members.upload(members.data(), members.size());
  r.memberBegin.upload(begin.data(), begin.size());
  r.worldOfMembers = d.worldHost;
  r.membersBuilt = true;
  r.bodySort = powerOfTwoAtLeast(std::max(r.mostBodies, 1));
  r.sweepKeys.ensure(static_cast<size_t>(worlds) * static_cast<size_t>(r.bodySort));
}

// Room for `capacity` candidate pairs in every world; the previous step's pairs are kept.
void sizeScratch(DeviceState& d, ResidentState& r, int capacity) {
  const size_t worlds = static_cast<size_t>(d.worlds);
  const int oldCapacity = r.capacity;
  std::vector<unsigned long long> kept;
  if (oldCapacity > 0) {
    kept.resize(worlds * static_cast<size_t>(oldCapacity));
    r.previous.download(kept.data(), kept.size());
  }
  r.capacity = capacity;
  r.capacitySort = powerOfTwoAtLeast(capacity);
  const size_t cap = static_cast<size_t>(capacity), sortCap = static_cast<size_t>(r.capacitySort);
  r.pairKeys.ensure(worlds * sortCap), r.idKeys.ensure(worlds * sortCap), r.bKeys.ensure(worlds * sortCap);
  r.candContact.ensure(worlds * cap), r.flag.ensure(worlds * 2 * (cap + 1)), r.survivors.ensure(worlds * cap);
  r.contactA.ensure(worlds * cap), r.contactB.ensure(worlds * cap), r.contacts.ensure(worlds * cap), r.slots.ensure(worlds * cap);
  r.previous.ensure(worlds * cap);
  if (oldCapacity == 0) {
    std::vector<int> zero(worlds, 0);
    r.previousCount.upload(zero.data(), zero.size());
    return;
  }
  // The kept pairs at the new stride (a world never has more than the old capacity of them).
  std::vector<unsigned long long> moved(worlds * cap, 0);
  for (size_t w = 0; w < worlds; ++w)
    std::copy_n(kept.begin() + static_cast<std::ptrdiff_t>(w * static_cast<size_t>(oldCapacity)), oldCapacity,
                moved.begin() + static_cast<std::ptrdiff_t>(w * cap));
  r.previous.upload(moved.data(), moved.size());
}

}  // namespace

void DeviceStep::useResident(const ResidentProgram& program, const std::vector<unsigned char>& params, int paramsStride) {
  DeviceState& d = *m_state;
  d.resident.reset(new ResidentState);
  ResidentState& r = *d.resident;
  r.program = program;
  r.paramsStride = paramsStride;
  r.params.upload(params.data(), std::max<size_t>(params.size(), 1));
  if (const char* start = std::getenv("GEM_CUDA_CAPACITY")) r.startCapacity = std::max(1, std::atoi(start));
}

bool DeviceStep::resident() const { return m_state->resident != nullptr; }

std::vector<unsigned long long> residentPreviousKeys(const DeviceState& d) {
  const ResidentState& r = *d.resident;
  if (r.previousPending) return r.pendingPrevious;
  if (r.capacity == 0) return {};  // no launch yet: no contact
  int count = 0;
  r.previousCount.download(&count, 1);
  std::vector<unsigned long long> keys(static_cast<size_t>(count));
  r.previous.download(keys.data(), keys.size());
  return keys;
}

void setResidentPreviousKeys(DeviceState& d, std::vector<unsigned long long> keys) {
  d.resident->pendingPrevious = std::move(keys);
  d.resident->previousPending = true;
}

void runResident(DeviceState& d, long firstStep, Real dt, int steps, DeviceBatchResult& result) {
  ResidentState& r = *d.resident;
  if (!r.membersBuilt || r.worldOfMembers != d.worldHost) buildMembers(d, r);
  if (r.capacity == 0) sizeScratch(d, r, r.startCapacity > 0 ? r.startCapacity : 4 * r.mostBodies + 256);
  if (r.previousPending) {
    const int count = static_cast<int>(r.pendingPrevious.size());
    if (count > r.capacity) sizeScratch(d, r, count + count / 2 + 256);
    r.previous.uploadAt(0, r.pendingPrevious.data(), r.pendingPrevious.size());
    r.previousCount.uploadAt(0, &count, 1);
    r.previousPending = false;
  }
  // Records of a whole launch: room for a row per pair at first; a launch that fills a buffer
  // stops there, and a single step that passes one grows them all.
  d.recordCapacity = std::max(d.recordCapacity, r.capacity);
  for (int q = 0; q < d.recordStreams; ++q)
    d.records[q].ensure(static_cast<size_t>(d.recordCapacity) * static_cast<size_t>(d.recordStride[q]));
  // One block per world, as many at once as the device keeps resident; more worlds take turns.
  int device = 0, multiprocessors = 1;
  GEM_CUDA_CHECK(cudaGetDevice(&device));
  GEM_CUDA_CHECK(cudaDeviceGetAttribute(&multiprocessors, cudaDevAttrMultiProcessorCount, device));
  if (r.vertexRoom < 0) {
    const char* stage = std::getenv("GEM_RESIDENT_STAGE_VERTICES");
    r.vertexRoom = stage && std::strcmp(stage, "0") == 0 ? 0 : 8 * r.mostBodies;
  }
  const std::size_t shared = residentSharedBytes(r.mostBodies, r.vertexRoom);
  const int grid = std::max(1, std::min(d.worlds, multiprocessors * std::max(1, residentBlocksPerMultiprocessor(shared))));

  // GEM_RESIDENT_CLIP=thread: the contact geometry a thread a pair, as before the warp's clipping
  // (a switch for the side-by-side figures in docs/performance.md; the results are the same).
  static const bool clipByThread = [] {
    const char* v = std::getenv("GEM_RESIDENT_CLIP");
    return v && std::strcmp(v, "thread") == 0;
  }();
  awaitHostCopies();  // members, params, the kept pairs: read by the launches below
  long next = firstStep;
  int remaining = steps;
  while (remaining > 0) {
    const int batch = std::min(remaining, d.ringSize);
    GEM_CUDA_CHECK(cudaMemsetAsync(r.control.get(), 0, sizeof(ResidentControl), d.stream));
    GEM_CUDA_CHECK(cudaMemsetAsync(r.recordCount.get(), 0, sizeof(int) * kMaxRecordStreams, d.stream));
    ResidentArgs a{};
    a.prepare = prepareArgsOf(d, d.tableSize, false);
    a.x = d.x.get(), a.y = d.y.get(), a.angle = d.angle.get(), a.vx = d.vx.get(), a.vy = d.vy.get(), a.omega = d.omega.get();
    a.vessel = d.vessel.get();
    a.motion = d.motionBodies.get();
    a.impulseOfId = d.worlds == 1 ? d.contactImpulseOfId.get() : nullptr;
    a.members = r.members.get(), a.memberBegin = r.memberBegin.get(), a.worlds = d.worlds;
    a.capacity = r.capacity, a.capacitySort = r.capacitySort, a.bodySort = r.bodySort;
    a.sweepKeys = r.sweepKeys.get(), a.pairKeys = r.pairKeys.get(), a.idKeys = r.idKeys.get(), a.bKeys = r.bKeys.get();
    a.previous = r.previous.get(), a.previousCount = r.previousCount.get();
    a.candContact = r.candContact.get(), a.flag = r.flag.get(), a.survivors = r.survivors.get(), a.contactA = r.contactA.get(),
    a.contactB = r.contactB.get();
    a.contacts = r.contacts.get(), a.slots = r.slots.get();
    a.program = r.program;
    a.params = r.params.get(), a.paramsStride = r.paramsStride;
    for (int q = 0; q < d.recordStreams; ++q)
      a.sink.streams[q] = RecordBuffer{d.records[q].get(), d.recordStride[q], d.recordCapacity, r.recordCount.get() + q};
    a.haltStreams = d.haltStreams;
    a.firstStep = next, a.dt = dt, a.steps = batch;
    a.clipByThread = clipByThread;
    a.sharedBytes = shared;
    a.ring = d.ring.get(), a.worldRing = d.worldRing.get(), a.control = r.control.get();
    launchResident(a, grid, shared, d.stream);
    GEM_CUDA_CHECK(cudaMemcpyAsync(r.h_control, r.control.get(), sizeof(ResidentControl), cudaMemcpyDeviceToHost, d.stream));
    GEM_CUDA_CHECK(
        cudaMemcpyAsync(d.h_ring, d.ring.get(), sizeof(StepRecord) * static_cast<size_t>(batch), cudaMemcpyDeviceToHost, d.stream));
    GEM_CUDA_CHECK(cudaMemcpyAsync(d.h_worldRing, d.worldRing.get(),
                                   sizeof(WorldStepRecord) * static_cast<size_t>(batch) * static_cast<size_t>(d.worlds),
                                   cudaMemcpyDeviceToHost, d.stream));
    GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
    const ResidentControl control = *r.h_control;
    const int done = control.stepsDone;
    ++r.launches;
    r.steps += done;
    for (int k = 0; k < kResidentPhases; ++k) r.phaseCycles[k] += control.phaseCycles[k];
    for (int k = 0; k < 3; ++k) r.pairCounts[k] += control.pairCounts[k];
    if (r.vertexRoom > 0 && control.verticesNeeded > r.vertexRoom) r.vertexRoom = control.verticesNeeded + control.verticesNeeded / 8;

    // The completed steps' records, appended; their ends shifted past what earlier launches added.
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
      StepRecord s = d.h_ring[k];
      for (int q = 0; q < kMaxRecordStreams; ++q) s.recordEnd[q] += base[q];
      result.steps.push_back(s);
    }
    result.worldSteps.insert(result.worldSteps.end(), d.h_worldRing,
                             d.h_worldRing + static_cast<size_t>(done) * static_cast<size_t>(d.worlds));
    next += done;
    remaining -= done;
    if (control.haltReason == kHaltBreak) break;
    if (control.haltReason != kHaltOverflow) continue;
    // A step overflowed and left every world alone: grow what it passed, run it again.
    if (control.candidatesNeeded > r.capacity) {
      sizeScratch(d, r, control.candidatesNeeded + control.candidatesNeeded / 2 + 256);
      d.recordCapacity = std::max(d.recordCapacity, r.capacity);
      for (int q = 0; q < d.recordStreams; ++q)
        d.records[q].ensure(static_cast<size_t>(d.recordCapacity) * static_cast<size_t>(d.recordStride[q]));
    } else if (done == 0 || (done < batch / 2 && d.recordCapacity < (1 << 24))) {
      // One step's records alone passed the buffers (4x), or a launch filled them in less than half
      // its steps (2x; many worlds log many rows a step): more room, so launches keep their length.
      d.recordCapacity *= done == 0 ? 4 : 2;
      for (int q = 0; q < d.recordStreams; ++q)
        d.records[q].ensure(static_cast<size_t>(d.recordCapacity) * static_cast<size_t>(d.recordStride[q]));
    }
  }
}

}  // namespace gem::cuda
