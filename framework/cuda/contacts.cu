// Phase 3 of a step, the contacts: the narrowphase over the candidates, their compaction in
// order, onset against the previous step's id pairs, and the commit of this step's pairs.
#include <algorithm>

#include "framework/api/cuda_check.hpp"
#include "framework/cuda/body_phases.cuh"
#include "framework/cuda/device_state.cuh"
#include "framework/cuda/step_phases.cuh"
#include "framework/step/phases.hpp"
#include "geometry/contact.hpp"

namespace gem::cuda {
namespace {

// Over the capacity + 1 entries: candidates past this step's count get flag 0, so the scan of a
// fixed length (captured in the graph) counts exactly this step's contacts.
__global__ void narrowphaseKernel(int capacity, const int* needed, const int* candA, const int* candB, const Vec2* worldVertices,
                                  const int* vertexCount, const Real* x, const Real* y, const Box* boxes, const Real* invMass,
                                  const int* world, Contact* out, int* flag, StepStats* stats) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p > capacity) return;
  const int total = *needed, count = total < capacity ? total : capacity;
  if (p == 0) {
    stats->candidatesNeeded = total;
    stats->candidates = count;
    stats->overflow = total > capacity ? 1 : 0;
  }
  // A step whose candidates passed the capacity is redone with more room, and its candidate list
  // may hold entries no one wrote (a strategy that ran out of its own room, grid rows that did not
  // fit): it tests nothing. (Reading them once read far out of bounds, when the memory had held
  // another run's data.)
  if (p >= count || total > capacity) {
    flag[p] = 0;
    return;
  }
  Contact c{};
  if (!contactOfPair(candA[p], candB[p], worldVertices, vertexCount, x, y, boxes, invMass, world, c)) {
    flag[p] = 0;
    return;
  }
  out[p] = c;
  flag[p] = 1;
}

__device__ inline unsigned long long contactIdKey(std::int64_t ia, std::int64_t ib, int bits) {
  const std::int64_t lo = ia < ib ? ia : ib, hi = ia < ib ? ib : ia;
  return (static_cast<unsigned long long>(lo) << bits) | static_cast<unsigned long long>(hi);
}

__device__ inline bool sortedContains(const unsigned long long* keys, int n, unsigned long long key) {
  int lo = 0, hi = n;
  while (lo < hi) {
    const int mid = (lo + hi) / 2;
    if (keys[mid] < key)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < n && keys[lo] == key;
}

struct CompactArgs {
  int capacity, n, idBits;
  unsigned long long padKey;  // larger than any real key: padding sorts to the end
  const int *candA, *candB;
  const Contact* cand;
  const int *flag, *offset;
  const std::int64_t* id;
  const int* world;
  WorldStepRecord* worldStats;
  const unsigned long long* previous;
  int *contactA, *contactB;
  PairContact* contacts;
  PairSlot* slots;
  unsigned long long* keys;
  int *bKey, *bIndex;
  StepStats* stats;
};

// Compaction in order, onset against the previous step's sorted id pairs. The entries past this
// step's contacts are padded (slot n, the largest key) so the fixed-length sorts keep them last.
__global__ void compactContactsKernel(CompactArgs a) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= a.capacity) return;
  const int contacts = a.offset[a.capacity];
  if (p == 0) a.stats->contacts = contacts;
  if (!a.flag[p]) {
    const int k = contacts + (p - a.offset[p]);  // the non-contacts fill [contacts, capacity) once each
    a.contactA[k] = a.n;
    a.contactB[k] = a.n;
    a.keys[k] = a.padKey;
    a.bKey[k] = a.n;
    a.bIndex[k] = k;
    return;
  }
  const int k = a.offset[p], ia = a.candA[p], ib = a.candB[p];
  const unsigned long long key = contactIdKey(a.id[ia], a.id[ib], a.idBits);
  atomicAdd(&a.worldStats[a.world[ia]].contacts, 1);  // an integer count: the order does not matter
  a.contactA[k] = ia;
  a.contactB[k] = ib;
  a.contacts[k] = PairContact{a.cand[p], !sortedContains(a.previous, a.stats->previousContacts, key)};
  a.slots[k] = PairSlot{{0, 0}};
  a.keys[k] = key;
  a.bKey[k] = ib;
  a.bIndex[k] = k;
}

// This step's sorted id pairs become the next step's "previous" (not when the step overflowed).
// Run at the end of the step, once nothing can overflow any more.
__global__ void commitContactsKernel(int capacity, const unsigned long long* sorted, unsigned long long* previous, StepStats* stats) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= capacity || stats->overflow) return;
  const int contacts = stats->contacts;
  if (k < contacts) previous[k] = sorted[k];
  if (k == 0) stats->previousContacts = contacts;
}

// After ids outgrew the key's field width: re-key the kept pairs (the order is unchanged).
__global__ void rekeyKernel(unsigned long long* keys, const StepStats* stats, int oldBits, int newBits) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= stats->previousContacts) return;
  const unsigned long long key = keys[k], hi = key & ((1ull << oldBits) - 1), lo = key >> oldBits;
  keys[k] = (lo << newBits) | hi;
}

}  // namespace

void enqueueContacts(DeviceState& d, CubCalls& cubCalls, const int* candidatesNeeded) {
  cudaStream_t s = d.stream;
  const int n = d.n, capacity = d.capacity, block = d.block;
  StepStats* stats = d.stats.get();
  // 3. Narrowphase, compaction in order (with padding), onset, the two sorts.
  // computeContact is a long serial chain per pair with a 2.3 KB local-memory frame: while the
  // pairs are few, blocks of one warp spread them over every multiprocessor's L1.
  const int narrowBlock = capacity + 1 < 64 * 1024 ? 32 : block;
  narrowphaseKernel<<<(capacity + narrowBlock) / narrowBlock, narrowBlock, 0, s>>>(
      capacity, candidatesNeeded, d.candA.get(), d.candB.get(), d.worldVertices.get(), d.vertexCount.get(), d.x.get(), d.y.get(),
      d.boxes.get(), d.invMass.get(), d.world.get(), d.candContact.get(), d.flag.get(), stats);
  GEM_CUDA_CHECK_LAUNCH();
  cubCalls.scanFlags(capacity);
  const unsigned long long padKey = d.idBits >= 32 ? ~0ull : (1ull << (2 * d.idBits)) - 1;
  const CompactArgs c{capacity,
                      n,
                      d.idBits,
                      padKey,
                      d.candA.get(),
                      d.candB.get(),
                      d.candContact.get(),
                      d.flag.get(),
                      d.flagOffset.get(),
                      d.id.get(),
                      d.world.get(),
                      d.worldStats.get(),
                      d.previousKeys.get(),
                      d.contactA.get(),
                      d.contactB.get(),
                      d.contacts.get(),
                      d.slots.get(),
                      d.contactKey.get(),
                      d.bKey.get(),
                      d.bIndex.get(),
                      stats};
  compactContactsKernel<<<blocksFor(capacity, block), block, 0, s>>>(c);
  GEM_CUDA_CHECK_LAUNCH();
  cubCalls.sortKeys(capacity, std::min(64, 2 * d.idBits));
  // The b side of every body, in contact order: a stable radix sort of (b, k) by b.
  cubCalls.sortB(capacity, bitsFor(static_cast<unsigned long long>(n)));
}

void enqueueCommitContacts(DeviceState& d) {
  cudaStream_t s = d.stream;
  const int capacity = d.capacity, block = d.block;
  StepStats* stats = d.stats.get();
  commitContactsKernel<<<blocksFor(capacity, block), block, 0, s>>>(capacity, d.sortedKeys.get(), d.previousKeys.get(), stats);
  GEM_CUDA_CHECK_LAUNCH();
}

std::vector<std::pair<std::int64_t, std::int64_t>> DeviceStep::touchingPairs() const {
  const DeviceState& d = *m_state;
  if (d.worlds != 1) throw std::logic_error("DeviceStep::touchingPairs: one world only");
  std::vector<unsigned long long> keys;
  int bits = 32;
  if (d.resident) {
    keys = residentPreviousKeys(d);
  } else {
    keys.resize(static_cast<size_t>(d.h_stats->previousContacts));  // the batch's end copied the stats
    d.previousKeys.download(keys.data(), keys.size());
    bits = d.idBits;
  }
  std::vector<std::pair<std::int64_t, std::int64_t>> pairs;
  pairs.reserve(keys.size());
  for (const unsigned long long key : keys)
    pairs.emplace_back(static_cast<std::int64_t>(key >> bits), static_cast<std::int64_t>(key & ((1ull << bits) - 1)));
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

void DeviceStep::setTouchingPairs(const std::vector<std::pair<std::int64_t, std::int64_t>>& pairs) {
  DeviceState& d = *m_state;
  if (d.worlds != 1) throw std::logic_error("DeviceStep::setTouchingPairs: one world only");
  const int bits = d.resident ? 32 : d.idBits;  // d.idBits: set by the upload
  std::vector<unsigned long long> keys;
  for (const auto& [lo, hi] : pairs) keys.push_back((static_cast<unsigned long long>(lo) << bits) | static_cast<unsigned long long>(hi));
  std::sort(keys.begin(), keys.end());
  if (d.resident) return setResidentPreviousKeys(d, std::move(keys));
  const int count = static_cast<int>(keys.size());
  if (d.previousKeys.ensure(std::max<size_t>(keys.size(), 1))) d.dropGraph();  // the graph reads and writes them
  d.previousKeys.uploadAt(0, keys.data(), keys.size());
  d.h_stats->previousContacts = count;
  GEM_CUDA_CHECK(cudaMemcpy(&d.stats.get()->previousContacts, &count, sizeof count, cudaMemcpyHostToDevice));
}

void rekeyContacts(DeviceState& d, int newBits) {
  rekeyKernel<<<blocksFor(d.capacity), kBlock, 0, d.stream>>>(d.previousKeys.get(), d.stats.get(), d.idBits, newBits);
  GEM_CUDA_CHECK_LAUNCH();
  GEM_CUDA_CHECK(cudaStreamSynchronize(d.stream));
}

}  // namespace gem::cuda
