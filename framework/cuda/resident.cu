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
  DeviceArray<int> members, memberBegin, memberCount, previousCount;
  std::vector<int> memberBeginHost;
  int mostBodies = 0;
  // Breaks in the kernel (ResidentBreaking): the new bodies a world may add in a launch
  // (GEM_RESIDENT_SPARE, default kSpareBodies; 0: every break ends the launch, as the device-wide
  // driver's does), each world's next id, the spare slots taken and the bodies gone.
  int spare = 0;
  std::vector<std::int64_t> nextIds;
  DeviceArray<std::int64_t> nextId;
  DeviceArray<int> spareUsed;
  DeviceArray<unsigned char> gone;
  bool resort = false;            // the re-sort along the curve in the kernel (scenario's morton_sort)
  DeviceArray<int> placeScratch;  // its scratch: bodySort ints a world
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
  long resortLaunches = 0;  // launches whose kernel re-sorted a world along the curve
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

// New bodies a world may add by breaks in one launch (ResidentBreaking). The 70-run load study
// breaks about 10 floes a case over its 3,600 steps; a launch is at most copy_back_every steps.
constexpr int kSpareBodies = 64;

// Each world's slots, ascending, one world after the other, each with room for its spare bodies.
void buildMembers(DeviceState& d, ResidentState& r) {
  const int worlds = d.worlds;
  std::vector<int> begin(static_cast<size_t>(worlds) + 1, 0), count(static_cast<size_t>(worlds), 0);
  for (int w : d.worldHost) ++count[static_cast<size_t>(w)];
  r.mostBodies = 0;
  for (int w = 0; w < worlds; ++w) {
    r.mostBodies = std::max(r.mostBodies, count[static_cast<size_t>(w)]);
    begin[static_cast<size_t>(w) + 1] = begin[static_cast<size_t>(w)] + count[static_cast<size_t>(w)] + r.spare;
  }
  std::vector<int> members(static_cast<size_t>(std::max(begin.back(), 1)), 0);
  std::vector<int> at(begin.begin(), begin.end() - 1);
  for (size_t k = 0; k < d.worldHost.size(); ++k)
    members[static_cast<size_t>(at[static_cast<size_t>(d.worldHost[k])]++)] = static_cast<int>(k);
  r.members.upload(members.data(), members.size());
  r.memberBegin.upload(begin.data(), begin.size());
  r.memberBeginHost = begin;
  r.memberCount.upload(count.data(), count.size());
  r.worldOfMembers = d.worldHost;
  r.membersBuilt = true;
  // A world grows by its spare bodies at most in a launch: the sorts and the shared memory have room.
  r.bodySort = powerOfTwoAtLeast(std::max(r.mostBodies + r.spare, 1));
  r.sweepKeys.ensure(static_cast<size_t>(worlds) * static_cast<size_t>(r.bodySort));
}

// Room past the state's n bodies for every world's spare ones, the first n rows kept.
void makeSpareRoom(DeviceState& d, ResidentState& r) {
  const size_t n = static_cast<size_t>(d.n), room = n + static_cast<size_t>(d.worlds) * static_cast<size_t>(r.spare);
  d.id.ensureKeeping(room, n), d.kind.ensureKeeping(room, n), d.vertexCount.ensureKeeping(room, n), d.dof.ensureKeeping(room, n);
  d.world.ensureKeeping(room, n), d.isLarge.ensureKeeping(room, n), d.local.ensureKeeping(room * kMaxVertices, n * kMaxVertices);
  for (GraphArray<Real>* a : {&d.x, &d.y, &d.angle, &d.vx, &d.vy, &d.omega, &d.area, &d.thickness, &d.mass, &d.invMass, &d.invInertia,
                              &d.gyration2, &d.gyrationX2, &d.gyrationY2, &d.principalAngle, &d.radius})
    a->ensureKeeping(room, n);
  // The per-step views are written by every step's prepare: no rows to keep.
  d.worldVertices.ensure(room * kMaxVertices);
  d.boxes.ensure(room), d.pairBodies.ensure(room), d.soloBodies.ensure(room), d.changes.ensure(room), d.motionBodies.ensure(room);
  r.gone.ensure(room);
  GEM_CUDA_CHECK(cudaMemset(r.gone.get(), 0, room));
  if (d.worlds == 1) {
    // The frames' contact force by id: room for the ids the launch may give, the new ones 0.
    const size_t ids = static_cast<size_t>(r.nextIds.at(0)) + static_cast<size_t>(r.spare), kept = d.contactImpulseOfId.capacity();
    if (d.contactImpulseOfId.ensureKeeping(ids, kept))
      GEM_CUDA_CHECK(cudaMemset(d.contactImpulseOfId.get() + kept, 0, (d.contactImpulseOfId.capacity() - kept) * sizeof(Real)));
  }
}

// The Real rows of World, in the order makeDense reads the device's arrays.
std::vector<Real> World::*const kRealRows[] = {&World::x,          &World::y,          &World::angle,          &World::vx,
                                               &World::vy,         &World::omega,      &World::area,           &World::thickness,
                                               &World::mass,       &World::invMass,    &World::invInertia,     &World::gyration2,
                                               &World::gyrationX2, &World::gyrationY2, &World::principalAngle, &World::radius};

// Rows [first, first + count) of a device array into the host vector's end.
template <class T, class Array>
void appendDeviceRows(std::vector<T>& to, const Array& from, size_t first, size_t count) {
  const size_t at = to.size();
  to.resize(at + count);
  if (count) GEM_CUDA_CHECK(cudaMemcpy(to.data() + at, from.get() + first, count * sizeof(T), cudaMemcpyDeviceToHost));
}

// After a launch whose kernel broke floes or re-sorted: the state made dense again, as the
// device-wide driver's edits and re-sort leave it. First the edit: the bodies that left compacted
// out, the others in their order, the new ones after them in the order they were made, world by
// world (editDeviceBodies), what changed in result.edits for the host's mirrors. Then, after a
// re-sort, the rows permuted to the members' order, world after world (permuteDeviceState, as
// reorderAlongCurve), the order in result.order.
void makeDense(DeviceState& d, ResidentState& r, const ResidentControl& control, DeviceBatchResult& result) {
  const int worlds = d.worlds, n = d.n;
  const size_t first = static_cast<size_t>(n), room = static_cast<size_t>(worlds) * static_cast<size_t>(r.spare);
  // The members name slots of the state as the launch left it: read before the edit moves them.
  std::vector<int> members, count(static_cast<size_t>(worlds));
  if (control.resorted) {
    members.resize(static_cast<size_t>(r.memberBeginHost.back()));
    r.members.download(members.data(), members.size());
    r.memberCount.download(count.data(), count.size());
  }
  std::vector<int> denseSlot(first + room, -1);  // each slot's after the edit (-1: gone)
  for (int k = 0; k < n; ++k) denseSlot[static_cast<size_t>(k)] = k;
  if (control.floesBroken > 0) {
    std::vector<int> used(static_cast<size_t>(worlds));
    r.spareUsed.download(used.data(), used.size());
    // The spare slots in use: the first mostUsed x worlds (a world's t-th is t x worlds + w).
    const int mostUsed = *std::max_element(used.begin(), used.end());
    const size_t usedRows = static_cast<size_t>(mostUsed) * static_cast<size_t>(worlds);
    std::vector<std::int64_t> nextIds(static_cast<size_t>(worlds));
    r.nextId.download(nextIds.data(), nextIds.size());
    std::vector<unsigned char> gone(first + usedRows);
    r.gone.download(gone.data(), gone.size());
    std::vector<std::int64_t> ids;
    appendDeviceRows(ids, d.id, 0, first);
    DeviceBodyEdits& edits = result.edits;
    std::vector<int> removedSlots;
    int kept = 0;
    for (int k = 0; k < n; ++k) {
      if (gone[static_cast<size_t>(k)]) {
        removedSlots.push_back(k), edits.removedIds.push_back(ids[static_cast<size_t>(k)]);
        denseSlot[static_cast<size_t>(k)] = -1;
      } else {
        denseSlot[static_cast<size_t>(k)] = kept++;
      }
    }
    // The new ones that stay: their rows as the kernel made them, and their kinematics now.
    World spareRows;
    appendDeviceRows(spareRows.id, d.id, first, usedRows), appendDeviceRows(spareRows.kind, d.kind, first, usedRows);
    appendDeviceRows(spareRows.vertexCount, d.vertexCount, first, usedRows);
    appendDeviceRows(spareRows.localVertices, d.local, first * kMaxVertices, usedRows * kMaxVertices);
    const GraphArray<Real>* arrays[] = {&d.x,          &d.y,          &d.angle,          &d.vx,      &d.vy,         &d.omega,
                                        &d.area,       &d.thickness,  &d.mass,           &d.invMass, &d.invInertia, &d.gyration2,
                                        &d.gyrationX2, &d.gyrationY2, &d.principalAngle, &d.radius};
    for (size_t a = 0; a < std::size(kRealRows); ++a) appendDeviceRows(spareRows.*kRealRows[a], *arrays[a], first, usedRows);
    World& added = edits.added;
    for (int w = 0; w < worlds; ++w)
      for (int t = 0; t < used[static_cast<size_t>(w)]; ++t) {
        const size_t k = static_cast<size_t>(t) * static_cast<size_t>(worlds) + static_cast<size_t>(w);
        if (gone[first + k]) {  // made and broken again within the launch
          edits.removedIds.push_back(spareRows.id[k]);
          continue;
        }
        denseSlot[first + k] = kept + added.size();
        added.id.push_back(spareRows.id[k]), added.kind.push_back(spareRows.kind[k]), added.vertexCount.push_back(spareRows.vertexCount[k]);
        added.localVertices.insert(added.localVertices.end(),
                                   spareRows.localVertices.begin() + static_cast<std::ptrdiff_t>(k * kMaxVertices),
                                   spareRows.localVertices.begin() + static_cast<std::ptrdiff_t>((k + 1) * kMaxVertices));
        for (auto real : kRealRows) (added.*real).push_back((spareRows.*real)[k]);
        edits.addedWorlds.push_back(w);
      }
    // The ids the dense state has room for: the world's own next id alone, or every world's stride.
    added.nextId = worlds == 1 ? nextIds[0] : static_cast<std::int64_t>(worlds) * d.idStride;
    editDeviceBodies(d, removedSlots, added, 0, worlds == 1 ? std::vector<int>{} : edits.addedWorlds,
                     std::vector<int>(static_cast<size_t>(worlds), 3));
    edits.nextIds = nextIds;
    r.nextIds = nextIds;
  }
  if (control.resorted) {
    // The members' order, world after world, in the slots the edit left.
    std::vector<int>& order = result.order;
    for (int w = 0; w < worlds; ++w)
      for (int i = 0; i < count[static_cast<size_t>(w)]; ++i)
        order.push_back(denseSlot[static_cast<size_t>(members[static_cast<size_t>(r.memberBeginHost[static_cast<size_t>(w)] + i)])]);
    if (order.size() != static_cast<size_t>(d.n) || std::find(order.begin(), order.end(), -1) != order.end())
      throw std::logic_error("runResident: the worlds' members after the launch are not the state's bodies");
    result.worldBefore = d.worldHost;
    GraphArray<int>& onDevice = d.resortSlotsSorted;
    onDevice.upload(order.data(), order.size());
    awaitHostCopies();  // the order: read by the permutation's kernels
    permuteDeviceState(d, onDevice.get(), order);
  }
  r.membersBuilt = false;
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

void DeviceStep::useResident(const ResidentProgram& program, const std::vector<unsigned char>& params, int paramsStride, bool resort) {
  DeviceState& d = *m_state;
  d.resident.reset(new ResidentState);
  ResidentState& r = *d.resident;
  r.resort = resort;
  r.program = program;
  r.paramsStride = paramsStride;
  r.params.upload(params.data(), std::max<size_t>(params.size(), 1));
  if (const char* start = std::getenv("GEM_CUDA_CAPACITY")) r.startCapacity = std::max(1, std::atoi(start));
  // GEM_RESIDENT_SPARE=N: room for N new bodies a world and launch (0: breaks end the launch).
  r.spare = kSpareBodies;
  if (const char* spare = std::getenv("GEM_RESIDENT_SPARE")) r.spare = std::max(0, std::atoi(spare));
  if (program.breakingOffset < 0) r.spare = 0;
}

bool DeviceStep::resident() const { return m_state->resident != nullptr; }

void DeviceStep::setNextIds(const std::vector<std::int64_t>& nextIds) {
  if (m_state->resident) m_state->resident->nextIds = nextIds;
}

long DeviceStep::residentLaunches() const { return m_state->resident ? m_state->resident->launches : 0; }
long DeviceStep::residentResortLaunches() const { return m_state->resident ? m_state->resident->resortLaunches : 0; }

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

  // GEM_RESIDENT_CLIP=thread: the contact geometry a thread a pair, as before the warp's clipping
  // (a switch for the side-by-side figures in docs/performance.md; the results are the same).
  static const bool clipByThread = [] {
    const char* v = std::getenv("GEM_RESIDENT_CLIP");
    return v && std::strcmp(v, "thread") == 0;
  }();
  long next = firstStep;
  int remaining = steps;
  while (remaining > 0) {
    const int batch = std::min(remaining, d.ringSize);
    const bool breaking = r.spare > 0;
    if (breaking) {
      if (r.nextIds.size() != static_cast<size_t>(d.worlds))
        throw std::logic_error("runResident: each world's next id is needed (setNextIds)");
      if (!r.membersBuilt || r.worldOfMembers != d.worldHost) buildMembers(d, r);
      makeSpareRoom(d, r);
      r.nextId.upload(r.nextIds.data(), r.nextIds.size());
      r.spareUsed.ensure(static_cast<size_t>(d.worlds));
      GEM_CUDA_CHECK(cudaMemset(r.spareUsed.get(), 0, sizeof(int) * static_cast<size_t>(d.worlds)));
    }
    if (r.resort) r.placeScratch.ensure(static_cast<size_t>(d.worlds) * static_cast<size_t>(r.bodySort));
    // The largest world, its spare bodies included, sets the launch's shared memory.
    const std::size_t shared = residentSharedBytes(r.mostBodies + r.spare, r.vertexRoom);
    const int grid = std::max(1, std::min(d.worlds, multiprocessors * std::max(1, residentBlocksPerMultiprocessor(shared))));
    awaitHostCopies();  // members, params, the kept pairs, the spare room: read by the launch below
    GEM_CUDA_CHECK(cudaMemsetAsync(r.control.get(), 0, sizeof(ResidentControl), d.stream));
    GEM_CUDA_CHECK(cudaMemsetAsync(r.recordCount.get(), 0, sizeof(int) * kMaxRecordStreams, d.stream));
    ResidentArgs a{};
    a.prepare = prepareArgsOf(d, d.tableSize, false);
    a.x = d.x.get(), a.y = d.y.get(), a.angle = d.angle.get(), a.vx = d.vx.get(), a.vy = d.vy.get(), a.omega = d.omega.get();
    a.vessel = d.vessel.get();
    a.motion = d.motionBodies.get();
    a.impulseOfId = d.worlds == 1 ? d.contactImpulseOfId.get() : nullptr;
    a.members = r.members.get(), a.memberBegin = r.memberBegin.get(), a.memberCount = r.memberCount.get(), a.worlds = d.worlds;
    a.breaking = ResidentBreaking{
        breaking ? r.program.breakingOffset : -1,
        r.spare,
        d.n,
        r.spareUsed.get(),
        r.nextId.get(),
        r.gone.get(),
        ResidentBodyRows{d.id.get(), d.kind.get(), d.vertexCount.get(), d.dof.get(), d.world.get(), d.local.get(), d.area.get(),
                         d.thickness.get(), d.mass.get(), d.invMass.get(), d.invInertia.get(), d.gyration2.get(), d.gyrationX2.get(),
                         d.gyrationY2.get(), d.principalAngle.get(), d.radius.get(), d.isLarge.get()}};
    a.resort = r.resort, a.placeScratch = r.placeScratch.get();
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
    // The kernel's own topology phase takes its stream's rows; any other topology stream halts.
    a.haltStreams = d.haltStreams;
    if (breaking) {
      const int q = r.program.breakingStream;
      if (q >= 0) a.haltStreams &= ~(1u << q);
    }
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
    if (control.resorted) ++r.resortLaunches;
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
    result.hostTopology = control.haltReason == kHaltBreak;
    // A step overflowed and left every world alone: grow what it passed; it runs again next launch.
    // (Before the early end below, so that the next run does not first overflow at that step again.)
    if (control.haltReason == kHaltOverflow) {
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
    // A launch that changed the worlds' bodies or their order ends the run: the host follows first.
    if (control.floesBroken > 0 || control.resorted) {
      makeDense(d, r, control, result);
      break;
    }
    if (control.haltReason == kHaltBreak) break;
  }
}

}  // namespace gem::cuda
