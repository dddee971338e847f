// Internal to framework/cuda: the resident driver's kernel (resident.cuh says what it is), a template
// over the table of events it holds; resident_events.cu instantiates it with the built-in events.
//
// The table is Events (pair, solo and motion evaluators) and Breaking (the topology event, with
// its cut: events/flexural_cut.hpp through resident_events.cu, the one file that names events).
//
// One block steps one world at a time; a block of a launch of many worlds takes worlds blockIdx.x,
// blockIdx.x + gridDim.x, ... Per step and world:
//   1. prepare every body (body_phases.cuh), and key it by its box's left edge;
//   2. its pairs: a sort and sweep along x over the world's bodies, then the prefilter (mayTouch):
//      exactly the pairs the device-wide driver's narrowphase tests, sorted by (a, b) places among
//      the world's members (its slots' order but after a re-sort in the launch: resortWorld);
//   3. narrowphase (contactOfPair), compaction in order, onset against the previous step's pairs;
//   4. the pair events, contact by contact, each contact's events in the declared order; the solo
//      events, body by body;
//   -- a grid barrier: every world knows whether any overflowed a buffer or asked for a break --
//   5. gather in the CPU's order, the motion events, write-back; this step's pairs kept for onset;
//   6. the topology phase, when the kernel holds the scenario's (flexural_breaking: breakFloes):
//      the floes cut, their pieces added into the world's spare slots, so that a break does not
//      end the launch (the host makes the state dense again after it: resident.cu);
//   -- a grid barrier: the step is over everywhere --
// A step that overflowed leaves every world's state alone (phase 5 is where the state is written),
// so the host can grow the buffer and run it again, bit-identically.
#pragma once
#include <cooperative_groups.h>

#include <cstring>

#include "framework/cuda/resident.cuh"
#include "framework/cuda/warp_contact.cuh"
#include "framework/step/phases.hpp"

namespace gem::cuda::resident {

// ---- the table of events ---------------------------------------------------------------------

template <class E>
struct Pair {
  using Event = E;
  static constexpr ResidentPhase phase = kResidentPair;
};
template <class E>
struct Solo {
  using Event = E;
  static constexpr ResidentPhase phase = kResidentSolo;
};
template <class E>
struct Motion {
  using Event = E;
  static constexpr ResidentPhase phase = kResidentMotion;
};

// The events a kernel holds, in a fixed order: an event's kind is its place here.
template <class... Entries>
struct EventSet {
  static constexpr int size = sizeof...(Entries);
  // Calls visitor(entry) for the entry at `kind` (a switch the compiler builds from the fold).
  template <class Visitor>
  __device__ static void visit(int kind, const Visitor& visitor) {
    int i = 0;
    (void)((i++ == kind ? (visitor(Entries{}), true) : false) || ...);
  }
};

// An event's Params from the world's row of parameters: a copy, as the other drivers pass them.
template <class Params>
__device__ inline Params paramsAt(const unsigned char* row, int offset) {
  Params p;
  memcpy(&p, row + offset, sizeof p);
  return p;
}

struct PairCall {
  const unsigned char* row;
  int offset;
  const PairBody& a;
  const PairBody& b;
  const PairContact& contact;
  PairSlot& slot;
  const StepContext& ctx;
  const RecordSink& sink;
  template <class E>
  __device__ void operator()(Pair<E>) const {
    E::apply(paramsAt<typename E::Params>(row, offset), a, b, contact, slot, ctx, sink);
  }
  template <class Other>
  __device__ void operator()(Other) const {}
};

struct SoloCall {
  const unsigned char* row;
  int offset;
  const SoloBody& body;
  VelocityChange& change;
  const StepContext& ctx;
  template <class E>
  __device__ void operator()(Solo<E>) const {
    E::apply(paramsAt<typename E::Params>(row, offset), body, change, ctx);
  }
  template <class Other>
  __device__ void operator()(Other) const {}
};

struct MotionCall {
  const unsigned char* row;
  int offset;
  MotionBody& body;
  const StepContext& ctx;
  template <class E>
  __device__ void operator()(Motion<E>) const {
    E::apply(paramsAt<typename E::Params>(row, offset), body, ctx);
  }
  template <class Other>
  __device__ void operator()(Other) const {}
};

// ---- block tools -----------------------------------------------------------------------------

// Keys sorted in shared memory up to this many, in global memory past it.
constexpr int kSharedSort = 2048;

// The most break requests a world's step may have for the kernel's topology phase (more: the
// launch stops there and the host's topology phase runs that step).
constexpr int kResidentMostBreaks = 32;

// A world's break requests of one step (breakFloes).
struct BreakScratch {
  int count, unique, piecesKept, floesBroken;
  Real rubbleMass;
  int row[kResidentMostBreaks];  // the rows of the request stream, in the CPU's order
  std::int64_t floeId[kResidentMostBreaks];
  int place[kResidentMostBreaks];       // the floe's place in the world (-1: not there)
  int firstPiece[kResidentMostBreaks];  // the request's first new body among the step's
  int cut[kResidentMostBreaks];         // 1: the floe was cut
  Real rubble[kResidentMostBreaks][2];  // the mass each of its pieces took away as rubble, kg
};

struct BlockShared {
  BreakScratch breaks;
  unsigned long long bounds[4];  // the re-sort's box of centroids (resortWorld)
  int scan[33];
  int count;
  long long cycles[kResidentPhases], stamp;  // block 0's time by phase (ResidentControl::phaseCycles)
  long long pairCounts[3];                   // world 0's (ResidentControl::pairCounts)
  union {
    unsigned long long sort[kSharedSort];                 // blockSort's keys
    ClipVertex clip[kResidentBlock / 32][kWarpClipRoom];  // each warp's overlap polygon (phase 3)
  };
};

// The end of phase k in block 0: its cycles since the last mark go to phase k.
__device__ inline void mark(BlockShared& sh, int k) {
  if (blockIdx.x != 0 || threadIdx.x != 0) return;
  const long long now = clock64();
  sh.cycles[k] += now - sh.stamp;
  sh.stamp = now;
}

// data[0..n) replaced by its exclusive prefix sum; returns the total, on every thread.
__device__ inline int blockExclusiveScan(int* data, int n, BlockShared& sh) {
  const int lane = threadIdx.x & 31, warp = threadIdx.x >> 5, warps = blockDim.x >> 5;
  int carry = 0;
  for (int base = 0; base < n; base += blockDim.x) {
    const int i = base + threadIdx.x;
    const int value = i < n ? data[i] : 0;
    int inclusive = value;
    for (int o = 1; o < 32; o <<= 1) {
      const int t = __shfl_up_sync(~0u, inclusive, o);
      if (lane >= o) inclusive += t;
    }
    if (lane == 31) sh.scan[warp] = inclusive;
    __syncthreads();
    if (warp == 0) {
      int total = lane < warps ? sh.scan[lane] : 0;
      for (int o = 1; o < 32; o <<= 1) {
        const int t = __shfl_up_sync(~0u, total, o);
        if (lane >= o) total += t;
      }
      if (lane < warps) sh.scan[lane] = total;
    }
    __syncthreads();
    if (i < n) data[i] = carry + (warp > 0 ? sh.scan[warp - 1] : 0) + inclusive - value;
    carry += sh.scan[warps - 1];
    __syncthreads();
  }
  return carry;
}

__device__ inline void bitonicSort(unsigned long long* keys, int m) {
  for (int k = 2; k <= m; k <<= 1)
    for (int j = k >> 1; j > 0; j >>= 1) {
      for (int i = threadIdx.x; i < m; i += blockDim.x) {
        const int l = i ^ j;
        if (l <= i) continue;
        const unsigned long long x = keys[i], y = keys[l];
        if ((x > y) == ((i & k) == 0)) {
          keys[i] = y;
          keys[l] = x;
        }
      }
      __syncthreads();
    }
}

// Up to this many keys a rank sort (every thread counts the keys below its own: one pass between
// two barriers) takes less time than the bitonic network's log^2 rounds, each ending at a barrier
// (the contacts' sorts). Its work grows as the square: the 824-floe world's sweep (824 keys) took
// 38 us a step by rank, 12 us by the network (docs/performance.md 4.4).
constexpr int kRankSort = 256;

// keys[0..n) sorted ascending through copy (n entries of shared memory); ties keep their order.
__device__ inline void rankSort(unsigned long long* keys, int n, unsigned long long* copy) {
  for (int i = threadIdx.x; i < n; i += blockDim.x) copy[i] = keys[i];
  __syncthreads();
  for (int i = threadIdx.x; i < n; i += blockDim.x) {
    const unsigned long long key = copy[i];
    int rank = 0;
    for (int j = 0; j < n; ++j) {
      const unsigned long long other = copy[j];
      rank += (other < key || (other == key && j < i)) ? 1 : 0;
    }
    keys[rank] = key;
  }
  __syncthreads();
}

// keys[0..n) sorted ascending; keys has room for the next power of two of n (the padding).
__device__ inline void blockSort(unsigned long long* keys, int n, BlockShared& sh) {
  int m = 1;
  while (m < n) m <<= 1;
  if (n <= 1) return;
  if (n <= kRankSort) return rankSort(keys, n, sh.sort);
  if (__isShared(keys)) {  // already in shared memory (the sweep's keys, staged): in place
    for (int i = n + threadIdx.x; i < m; i += blockDim.x) keys[i] = ~0ull;
    __syncthreads();
    bitonicSort(keys, m);
  } else if (m <= kSharedSort) {
    for (int i = threadIdx.x; i < m; i += blockDim.x) sh.sort[i] = i < n ? keys[i] : ~0ull;
    __syncthreads();
    bitonicSort(sh.sort, m);
    for (int i = threadIdx.x; i < n; i += blockDim.x) keys[i] = sh.sort[i];
  } else {
    for (int i = n + threadIdx.x; i < m; i += blockDim.x) keys[i] = ~0ull;
    __syncthreads();
    bitonicSort(keys, m);
  }
  __syncthreads();
}

// pairs[0..count) (keys a << 32 | b, each pair once) sorted ascending, where pairsAt[a] has counted
// the pairs of each place a: a counting sort by a through shared memory, then each pair's rank by b
// among its own place's few. A few barriers where the bitonic network has dozens.
__device__ inline void sortPairsByPlace(unsigned long long* pairs, int count, int* pairsAt, int n, BlockShared& sh) {
  blockExclusiveScan(pairsAt, n + 1, sh);
  unsigned long long* placed = sh.sort;
  for (int k = threadIdx.x; k < count; k += blockDim.x) {
    const unsigned long long key = pairs[k];
    placed[atomicAdd(&pairsAt[key >> 32], 1)] = key;
  }
  __syncthreads();
  // pairsAt[a] is now where place a's pairs end (and a + 1's begin).
  for (int k = threadIdx.x; k < count; k += blockDim.x) {
    const unsigned long long key = placed[k];
    const int a = static_cast<int>(key >> 32);
    const int begin = a > 0 ? pairsAt[a - 1] : 0, end = pairsAt[a];
    int rank = 0;
    for (int j = begin; j < end; ++j) rank += placed[j] < key ? 1 : 0;
    pairs[begin + rank] = key;
  }
  __syncthreads();
}

template <class T>
__device__ inline int lowerBoundOf(const T* v, int n, T x) {
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

// A float's bits as an unsigned integer that sorts as the float does.
__device__ inline unsigned orderedBits(float f) {
  const unsigned u = __float_as_uint(f);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

// Counters the worlds of a launch share: read past the L1, which other multiprocessors do not see.
__device__ inline int readShared(const int* p) { return *static_cast<const volatile int*>(p); }

// ---- one world's step --------------------------------------------------------------------------

struct WorldScratch {
  int begin, n;
  const int* members;  // the world's slots (a.members + begin)
  unsigned long long *sweep, *pairs, *ids, *bs, *previous;
  Contact* candidates;
  int *flag, *touching, *survivors;
  int *contactA, *contactB;
  // Contact c's first body by its place among the world's members (the gather's search): the
  // contacts ascend by it, not by contactA's slots once the kernel has re-sorted the members
  // (resortWorld). It lives in flag's room, which is free once the survivors are placed.
  int* placeA;
  PairContact* contacts;
  PairSlot* slots;
};

__device__ inline WorldScratch scratchOf(const ResidentArgs& a, int w) {
  const size_t cap = static_cast<size_t>(a.capacity), sortCap = static_cast<size_t>(a.capacitySort), ww = static_cast<size_t>(w);
  WorldScratch s;
  s.begin = a.memberBegin[w];
  s.n = a.memberCount[w];
  s.members = a.members + s.begin;
  s.sweep = a.sweepKeys + ww * static_cast<size_t>(a.bodySort);
  s.pairs = a.pairKeys + ww * sortCap;
  s.ids = a.idKeys + ww * sortCap;
  s.bs = a.bKeys + ww * sortCap;
  s.previous = a.previous + ww * cap;
  s.candidates = a.candContact + ww * cap;
  s.flag = a.flag + ww * 2 * (cap + 1);
  s.touching = s.flag + (cap + 1);
  s.placeA = s.flag;
  s.survivors = a.survivors + ww * cap;
  s.contactA = a.contactA + ww * cap;
  s.contactB = a.contactB + ww * cap;
  s.contacts = a.contacts + ww * cap;
  s.slots = a.slots + ww * cap;
  return s;
}

// Phases 1 to 4 of world w. Returns its contact count (every thread), or -1 when its candidate
// pairs passed the capacity (the step is then run again with more room).
template <class Events>
__device__ int firstHalf(const ResidentArgs& a, int w, const StepContext& ctx, int parity, BlockShared& sh, unsigned char* dynamic) {
  WorldScratch s = scratchOf(a, w);
  const PrepareArgs& p = a.prepare;
  const int n = s.n;
  // The sweep's keys, boxes and inverse masses by the body's place in the world: in shared memory
  // when the launch has room for them (residentSharedBytes), else in global memory. The world's
  // vertices too, after them, when they fit in the rest: vertices[vertexAt[i] .. vertexAt[i + 1])
  // are those of the body at place i.
  Box* boxes = nullptr;
  Real* invMass = nullptr;
  int *vertexAt = nullptr, *pairsAt = nullptr;
  Vec2* vertices = nullptr;
  if (dynamic) {
    s.sweep = reinterpret_cast<unsigned long long*>(dynamic);
    boxes = reinterpret_cast<Box*>(s.sweep + a.bodySort);
    invMass = reinterpret_cast<Real*>(boxes + a.bodySort);
    vertexAt = reinterpret_cast<int*>(invMass + a.bodySort);
    pairsAt = vertexAt + a.bodySort + 1;
    vertices = reinterpret_cast<Vec2*>(dynamic + residentBodyBytes(a.bodySort));
  }
  // 1. Prepare (body_phases.cuh), and the sweep's keys: the box's left edge rounded down (a float
  // sorts as its double does, ties aside), then the body's place in the world.
  auto sweepKey = [](const Box& box, int i) {
    return (static_cast<unsigned long long>(orderedBits(__double2float_rd(box.x0))) << 32) | static_cast<unsigned>(i);
  };
  if (threadIdx.x == 0) sh.count = 0;
  if (!dynamic) {  // a world too large for shared memory: each body whole on one thread
    for (int i = threadIdx.x; i < n; i += blockDim.x) {
      const int slot = s.members[i];
      prepareBody(p, slot);
      s.sweep[i] = sweepKey(p.boxes[slot], i);
    }
    __syncthreads();
    mark(sh, 0);
  } else {
    // In passes, so that no thread walks a body's vertices one global read after another:
    // (a) each body's vertex count and turn (cosine, sine, position: kept in its box's place until
    // (c)); (b) every vertex of the world turned into the world frame, a vertex a thread, into
    // global memory (the events' views point there) and, when they fit, into shared memory, where
    // the narrowphase's long chains of dependent reads wait a few dozen cycles each instead of an
    // L2 round trip; (c) each body's box and views (finishBody). The arithmetic is toWorld's.
    for (int i = threadIdx.x; i < n; i += blockDim.x) {
      const int slot = s.members[i];
      const Real angle = p.angle[slot];
      vertexAt[i] = p.vertexCount[slot];
      boxes[i] = Box{std::cos(angle), std::sin(angle), p.x[slot], p.y[slot]};
    }
    if (threadIdx.x == 0) vertexAt[n] = 0;
    __syncthreads();
    const int total = blockExclusiveScan(vertexAt, n + 1, sh);
    if (threadIdx.x == 0) atomicMax(&a.control->verticesNeeded, total);
    // The same on every thread (the total is): past the room, the narrowphase reads global memory.
    if (static_cast<std::size_t>(total) * sizeof(Vec2) > a.sharedBytes - residentBodyBytes(a.bodySort)) vertices = nullptr;
    for (int k = threadIdx.x; k < total; k += blockDim.x) {
      const int i = lowerBoundOf(vertexAt, n + 1, k + 1) - 1;  // the body whose vertices k is among
      const Box turn = boxes[i];
      const size_t at = static_cast<size_t>(s.members[i]) * kMaxVertices + static_cast<size_t>(k - vertexAt[i]);
      const Vec2 v = toWorldPoint(p.local[at], Vec2{turn.x1, turn.y1}, turn.x0, turn.y0);
      p.worldVertices[at] = v;
      if (vertices) vertices[k] = v;
    }
    __syncthreads();
    mark(sh, 0);
    for (int i = threadIdx.x; i < n; i += blockDim.x) {
      const int slot = s.members[i];
      const Vec2* v = vertices ? vertices + vertexAt[i] : p.worldVertices + static_cast<size_t>(slot) * kMaxVertices;
      const Box box = boundingBox(v, vertexAt[i + 1] - vertexAt[i]);
      finishBody(p, slot, box);
      boxes[i] = box;
      invMass[i] = p.invMass[slot];
      s.sweep[i] = sweepKey(box, i);
      pairsAt[i] = 0;
    }
    if (threadIdx.x == 0) pairsAt[n] = 0;
    __syncthreads();
  }
  mark(sh, 1);
  blockSort(s.sweep, n, sh);
  mark(sh, 2);

  // 2. Pairs: a warp per body in sweep order; its lanes walk the bodies after it while their left
  // edge (rounded down) is not past its right edge (rounded up): every pair whose boxes overlap
  // along x is met exactly once, from whichever of the two comes first. The prefilter keeps what
  // the narrowphase of every other driver tests.
  const int lane = threadIdx.x & 31, warps = blockDim.x >> 5;
  for (int q = threadIdx.x >> 5; q < n; q += warps) {
    const int ia = static_cast<int>(s.sweep[q] & 0xffffffffu);
    const Box boxA = boxes ? boxes[ia] : p.boxes[s.members[ia]];
    const Real invMassA = boxes ? invMass[ia] : p.invMass[s.members[ia]];
    const unsigned long long limit = static_cast<unsigned long long>(orderedBits(__double2float_ru(boxA.x1)));
    for (int first = q + 1; first < n; first += 32) {
      const int r = first + lane;
      bool inReach = false;
      if (r < n) {
        const unsigned long long key = s.sweep[r];
        inReach = (key >> 32) <= limit;
        if (inReach) {
          const int ib = static_cast<int>(key & 0xffffffffu);
          const bool touch = boxes ? mayTouch(invMassA, invMass[ib], boxA, boxes[ib])
                                   : mayTouch(invMassA, p.invMass[s.members[ib]], boxA, p.boxes[s.members[ib]]);
          if (touch) {
            const int at = atomicAdd(&sh.count, 1);
            const unsigned lo = ia < ib ? ia : ib, hi = ia < ib ? ib : ia;
            if (at < a.capacity) {
              s.pairs[at] = (static_cast<unsigned long long>(lo) << 32) | hi;
              if (pairsAt) atomicAdd(&pairsAt[lo], 1);
            }
          }
        }
      }
      if (__any_sync(~0u, !inReach)) break;
    }
  }
  __syncthreads();
  mark(sh, 3);
  const int pairs = sh.count;
  if (threadIdx.x == 0) {
    atomicAdd(&a.control->candidates[parity], pairs);
    atomicMax(&a.control->candidatesNeeded, pairs);
    if (pairs > a.capacity) atomicOr(&a.control->overflow[parity], 1);
  }
  if (pairs > a.capacity) return -1;
  if (pairsAt && pairs <= kSharedSort)
    sortPairsByPlace(s.pairs, pairs, pairsAt, n, sh);
  else
    blockSort(s.pairs, pairs, sh);
  mark(sh, 4);

  // 3. Narrowphase in two passes: the separating-axis test over every pair, then the contact
  // geometry (clipping) over the pairs that overlap only, so that the few long clipping chains
  // are spread over the block instead of queued behind the many quick rejections. The same
  // functions as the device-wide driver's contactOfPair, in the same order: the same contacts.
  // With the vertices in shared memory the prefilter is not repeated: every pair passed it above.
  for (int k = threadIdx.x; k < pairs; k += blockDim.x) {
    const unsigned long long key = s.pairs[k];
    const int ia = static_cast<int>(key >> 32), ib = static_cast<int>(key & 0xffffffffu);
    const bool overlap = vertices
                             ? convexOverlap(vertices + vertexAt[ia], vertexAt[ia + 1] - vertexAt[ia], vertices + vertexAt[ib],
                                             vertexAt[ib + 1] - vertexAt[ib])
                             : overlapOfPair(s.members[ia], s.members[ib], p.worldVertices, p.vertexCount, p.boxes, p.invMass, p.world);
    s.flag[k] = overlap ? 1 : 0;
  }
  if (threadIdx.x == 0) s.flag[pairs] = 0;
  __syncthreads();
  const int overlapping = blockExclusiveScan(s.flag, pairs + 1, sh);
  for (int k = threadIdx.x; k < pairs; k += blockDim.x)
    if (s.flag[k + 1] != s.flag[k]) s.survivors[s.flag[k]] = k;
  __syncthreads();
  mark(sh, 5);
  if (a.clipByThread) {
    for (int j = threadIdx.x; j < overlapping; j += blockDim.x) {
      const unsigned long long key = s.pairs[s.survivors[j]];
      Contact c{};
      const bool touching = contactOfPair(s.members[key >> 32], s.members[key & 0xffffffffu], p.worldVertices, p.vertexCount, p.x, p.y,
                                          p.boxes, p.invMass, p.world, c);
      s.touching[j] = touching ? 1 : 0;
      if (touching) s.candidates[j] = c;
    }
  } else {
    // Two pairs a warp, a half warp each (warp_contact.cuh): the lanes of one warp clipping
    // different pairs would diverge through every clipping, and one thread's chain of a pair's
    // clipping is the longest latency of the step. The separating-axis test above already passed.
    const int warp = threadIdx.x >> 5;
    auto fetch = [&](int j) {
      const unsigned long long key = s.pairs[s.survivors[j]];
      const int ia = static_cast<int>(key >> 32), ib = static_cast<int>(key & 0xffffffffu);
      const int sa = s.members[ia], sb = s.members[ib];
      return PairPolygons{vertices ? vertices + vertexAt[ia] : p.worldVertices + static_cast<size_t>(sa) * kMaxVertices,
                          p.vertexCount[sa],
                          Vec2{p.x[sa], p.y[sa]},
                          vertices ? vertices + vertexAt[ib] : p.worldVertices + static_cast<size_t>(sb) * kMaxVertices,
                          p.vertexCount[sb],
                          Vec2{p.x[sb], p.y[sb]}};
    };
    auto store = [&](int j, const Contact& c) {
      s.touching[j] = c.touching ? 1 : 0;
      if (c.touching) s.candidates[j] = c;
    };
    for (int j0 = 2 * warp; j0 < overlapping; j0 += 2 * (blockDim.x >> 5)) warpContactsOfTwo(j0, overlapping, fetch, store, sh.clip[warp]);
  }
  if (threadIdx.x == 0) s.touching[overlapping] = 0;
  __syncthreads();
  mark(sh, 6);
  const int contacts = blockExclusiveScan(s.touching, overlapping + 1, sh);
  const int previous = a.previousCount[w];
  for (int j = threadIdx.x; j < overlapping; j += blockDim.x) {
    if (s.touching[j + 1] == s.touching[j]) continue;
    const int c = s.touching[j], k = s.survivors[j];
    const unsigned long long key = s.pairs[k];
    const int sa = s.members[key >> 32], sb = s.members[key & 0xffffffffu];
    // The pair by the case's own ids (PairBody::id), the smaller first: kept for the next step's onset.
    const unsigned long long ida = static_cast<unsigned long long>(p.pairBodies[sa].id),
                             idb = static_cast<unsigned long long>(p.pairBodies[sb].id);
    const unsigned long long idKey = ida < idb ? (ida << 32) | idb : (idb << 32) | ida;
    s.contactA[c] = sa;
    s.placeA[c] = static_cast<int>(key >> 32);
    s.contactB[c] = sb;
    const int seen = lowerBoundOf(s.previous, previous, idKey);
    s.contacts[c] = PairContact{s.candidates[j], seen == previous || s.previous[seen] != idKey};
    s.slots[c] = PairSlot{{0, 0}};
    s.ids[c] = idKey;
    s.bs[c] = ((key & 0xffffffffu) << 32) | static_cast<unsigned>(c);  // b's place in the world, then the contact
  }
  if (threadIdx.x == 0) atomicAdd(&a.control->contacts[parity], contacts);
  if (blockIdx.x == 0 && threadIdx.x == 0 && w == 0)
    sh.pairCounts[0] += pairs, sh.pairCounts[1] += overlapping, sh.pairCounts[2] += contacts;
  __syncthreads();
  mark(sh, 7);

  // 4. The pair events, a contact at a time, each contact's events in order; then the solo events.
  const unsigned char* row = a.params + static_cast<size_t>(w) * static_cast<size_t>(a.paramsStride);
  for (int k = threadIdx.x; k < contacts; k += blockDim.x) {
    const PairBody bodyA = p.pairBodies[s.contactA[k]], bodyB = p.pairBodies[s.contactB[k]];
    const PairContact contact = s.contacts[k];
    PairSlot slot = s.slots[k];
    for (int e = 0; e < a.program.pairCount; ++e)
      Events::visit(a.program.pair[e].kind,
                    PairCall{row, a.program.pair[e].paramsOffset, bodyA, bodyB, contact, slot, ctx, a.sink.at(e, k, w)});
    s.slots[k] = slot;
  }
  for (int i = threadIdx.x; i < n; i += blockDim.x) {
    const int slot = s.members[i];
    const SoloBody body = p.soloBodies[slot];
    VelocityChange change = p.changes[slot];
    for (int e = 0; e < a.program.soloCount; ++e)
      Events::visit(a.program.solo[e].kind, SoloCall{row, a.program.solo[e].paramsOffset, body, change, ctx});
    p.changes[slot] = change;
  }
  __syncthreads();
  mark(sh, 8);
  // Phase 5 reads the b side in contact order, and the next step's onset the pairs by id.
  blockSort(s.bs, contacts, sh);
  blockSort(s.ids, contacts, sh);
  mark(sh, 9);
  return contacts;
}

// Phase 5 of world w: gather, motion, write-back, this step's pairs kept; its record of the step.
template <class Events>
__device__ void secondHalf(const ResidentArgs& a, int w, int contacts, const StepContext& ctx, WorldStepRecord& record) {
  const WorldScratch s = scratchOf(a, w);
  const PrepareArgs& p = a.prepare;
  const int vessel = a.vessel[w];
  if (threadIdx.x == 0) record = WorldStepRecord{contacts, {0, 0}, {0, 0}, {0, 0}, 0};
  __syncthreads();
  const unsigned char* row = a.params + static_cast<size_t>(w) * static_cast<size_t>(a.paramsStride);
  for (int i = threadIdx.x; i < s.n; i += blockDim.x) {
    const int slot = s.members[i];
    const bool isVessel = slot == vessel;
    const int firstB = lowerBoundOf(s.bs, contacts, static_cast<unsigned long long>(i) << 32);
    int endB = firstB;
    while (endB < contacts && (s.bs[endB] >> 32) == static_cast<unsigned long long>(i)) ++endB;
    const int firstA = lowerBoundOf(s.placeA, contacts, i);
    int endA = firstA;
    while (endA < contacts && s.placeA[endA] == i) ++endA;
    Vec2 onBody;
    MotionBody body = gatherBody(
        p.pairBodies[slot], p.changes[slot], [&](int q) { return static_cast<int>(s.bs[firstB + q] & 0xffffffffu); }, endB - firstB, firstA,
        endA, s.contacts, s.slots, isVessel, &record.vesselImpulse, onBody);
    if (a.impulseOfId) a.impulseOfId[p.pairBodies[slot].id] = norm(onBody);
    for (int e = 0; e < a.program.motionCount; ++e)
      Events::visit(a.program.motion[e].kind, MotionCall{row, a.program.motion[e].paramsOffset, body, ctx});
    a.motion[slot] = body;
    writeBackBody(body, slot, a.x, a.y, a.angle, a.vx, a.vy, a.omega, isVessel, record);
  }
  for (int k = threadIdx.x; k < contacts; k += blockDim.x) s.previous[k] = s.ids[k];
  if (threadIdx.x == 0) a.previousCount[w] = contacts;
  __syncthreads();
}

// The topology phase of world w in step s, after its write-back (docs/model.md 6, as
// FlexuralBreaking::apply does it on the host): its requests of the step in the CPU's order (by
// event, then contact), the first for each floe, each floe cut by events/flexural_cut.hpp from its
// moved state, the pieces added into the world's spare slots with World::addPiece's rows
// (bodyMassRow with the portable trigonometry) and new ids, the floe and rubble out of the world's members. A world with more
// requests than its room stops the launch after this step instead (halt), and leaves the step to
// the host. Returns whether it halted so (no re-sort in the kernel then: the host re-sorts after its
// topology phase); the world's record of the step says what it did.
template <class Breaking>
__device__ bool breakFloes(const ResidentArgs& a, int w, int s, int parity, WorldStepRecord& record, BlockShared& sh) {
  const ResidentBreaking& br = a.breaking;
  const PrepareArgs& p = a.prepare;
  const unsigned char* row = a.params + static_cast<size_t>(w) * static_cast<size_t>(a.paramsStride);
  const int q = Breaking::stream(row, br.offset);
  if (q < 0 || q >= kMaxRecordStreams || !a.sink.streams[q].count) return false;
  const RecordBuffer& buffer = a.sink.streams[q];
  // This step's rows: nothing is pushed after the first barrier, and the step before ended its rows.
  const int begin = s > 0 ? a.ring[s - 1].recordEnd[q] : 0;
  const int end = min(readShared(buffer.count), buffer.capacity);
  auto tagOf = [&](int r) {
    RecordTag t;
    memcpy(&t, buffer.rows + static_cast<size_t>(r) * static_cast<size_t>(buffer.stride), sizeof t);
    return t;
  };
  auto requestOf = [&](int r) {
    typename Breaking::Request request;
    memcpy(&request, buffer.rows + static_cast<size_t>(r) * static_cast<size_t>(buffer.stride) + sizeof(RecordTag), sizeof request);
    return request;
  };
  BreakScratch& b = sh.breaks;
  if (threadIdx.x == 0) b.count = 0;
  __syncthreads();
  for (int r = begin + static_cast<int>(threadIdx.x); r < end; r += blockDim.x)
    if (tagOf(r).world == w) {
      const int k = atomicAdd(&b.count, 1);
      if (k < kResidentMostBreaks) b.row[k] = r;
    }
  __syncthreads();
  const int count = b.count;
  if (count == 0) return false;
  const int room = br.spare - br.spareUsed[w];
  if (threadIdx.x == 0) {
    // The CPU's order of the rows (by event, then contact), then the first request of each floe.
    for (int i = 1; i < min(count, kResidentMostBreaks); ++i)
      for (int j = i; j > 0; --j) {
        const RecordTag x = tagOf(b.row[j - 1]), y = tagOf(b.row[j]);
        // Ties by the row itself: the rows came in by atomics, in no fixed order, while the host
        // keeps a stream's push order.
        if (x.event < y.event || (x.event == y.event && (x.contact < y.contact || (x.contact == y.contact && b.row[j - 1] < b.row[j]))))
          break;
        const int t = b.row[j - 1];
        b.row[j - 1] = b.row[j], b.row[j] = t;
      }
    int unique = 0;
    for (int i = 0; i < min(count, kResidentMostBreaks); ++i) {
      const std::int64_t id = requestOf(b.row[i]).floeId;
      bool seen = false;
      for (int j = 0; j < unique; ++j) seen = seen || b.floeId[j] == id;
      if (seen) continue;
      b.row[unique] = b.row[i], b.floeId[unique] = id, b.place[unique] = -1;
      ++unique;
    }
    b.unique = unique;
    // Two pieces a request at most: a world without the room leaves the step to the host.
    if (count > kResidentMostBreaks || 2 * unique > room) {
      b.unique = -1;
      a.control->halt[parity] = 1;
      atomicMax(&a.control->haltReason, kHaltBreak);
    }
  }
  __syncthreads();
  const int unique = b.unique;
  if (unique < 0) return true;
  const std::int64_t idBase = static_cast<std::int64_t>(w) * p.idStride;
  WorldScratch ws = scratchOf(a, w);
  for (int i = threadIdx.x; i < ws.n; i += blockDim.x) {
    const std::int64_t own = p.id[ws.members[i]] - idBase;
    for (int j = 0; j < unique; ++j)
      if (b.floeId[j] == own) b.place[j] = i;
  }
  __syncthreads();
  // Each request's cut on a thread of its own, from the floe's moved state, as the host's.
  typename Breaking::Piece pieces[2];
  bool cut = false;
  const int j = threadIdx.x;
  if (j < unique && b.place[j] >= 0) {
    const int slot = ws.members[b.place[j]];
    cut = Breaking::cut(p.local + static_cast<size_t>(slot) * kMaxVertices, p.vertexCount[slot], Vec2{a.x[slot], a.y[slot]}, a.angle[slot],
                        Vec2{a.vx[slot], a.vy[slot]}, a.omega[slot], requestOf(b.row[j]), Breaking::minArea(row, br.offset), pieces);
  }
  if (j < unique) {
    b.cut[j] = cut ? 1 : 0;
    b.firstPiece[j] = cut ? (pieces[0].rubble ? 0 : 1) + (pieces[1].rubble ? 0 : 1) : 0;
    // The mass each piece takes away as rubble (0 for a piece that stays: adding it changes no sum).
    for (int k = 0; k < 2; ++k)
      b.rubble[j][k] = cut && pieces[k].rubble ? kRhoIce * pieces[k].area * p.thickness[ws.members[b.place[j]]] : Real(0);
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    // In the requests' order, as the host's loop: the new bodies' places, the rubble's mass.
    int kept = 0, broken = 0;
    Real rubble = 0;
    for (int k = 0; k < unique; ++k) {
      const int here = b.firstPiece[k];
      b.firstPiece[k] = kept;
      kept += here;
      broken += b.cut[k];
      if (b.cut[k]) rubble += b.rubble[k][0], rubble += b.rubble[k][1];
    }
    b.piecesKept = kept, b.floesBroken = broken, b.rubbleMass = rubble;
  }
  __syncthreads();
  const int used = br.spareUsed[w];
  if (cut) {
    const int parent = ws.members[b.place[j]];
    const ResidentBodyRows& out = br.rows;
    int k = b.firstPiece[j];
    for (const auto& piece : pieces) {
      if (piece.rubble) continue;
      const int slot = br.spareFirst + (used + k) * a.worlds + w;
      const BodyMassRow m = bodyMassRow<PortableTrig>(piece.vertices, piece.count, p.thickness[parent], false,
                                                      out.local + static_cast<size_t>(slot) * kMaxVertices);
      out.id[slot] = idBase + br.nextId[w] + k;
      out.kind[slot] = BodyKind::Floe;
      out.vertexCount[slot] = piece.count;
      out.dof[slot] = degreesOfFreedom(BodyKind::Floe, 0);
      out.world[slot] = w;
      out.isLarge[slot] = 0;  // only the device-wide driver's grid reads it; the dense state sets it again
      out.area[slot] = m.area, out.thickness[slot] = p.thickness[parent], out.mass[slot] = m.mass, out.invMass[slot] = m.invMass;
      out.invInertia[slot] = m.invInertia, out.gyration2[slot] = m.gyration2, out.gyrationX2[slot] = m.gyrationX2;
      out.gyrationY2[slot] = m.gyrationY2, out.principalAngle[slot] = m.principalAngle, out.radius[slot] = m.radius;
      a.x[slot] = m.centroid.x, a.y[slot] = m.centroid.y, a.angle[slot] = 0;
      a.vx[slot] = piece.velocity.x, a.vy[slot] = piece.velocity.y, a.omega[slot] = a.omega[parent];
      br.gone[slot] = 0;
      ++k;
    }
    br.gone[parent] = 1;
  }
  __syncthreads();
  // The members: the cut floes out (the others keep their order), the new bodies after them, as
  // World::removeBodies and World::addBody leave the host's world.
  // The world's sweep keys in global memory are the scratch (2 x bodySort ints, bodySort >= n + 1;
  // the next step's prepare writes them anew); the pair buffers may be smaller than the world.
  const int n = ws.n;
  int* flag = reinterpret_cast<int*>(ws.sweep);
  int* survivors = flag + n + 1;
  for (int i = threadIdx.x; i < n; i += blockDim.x) flag[i] = br.gone[ws.members[i]] ? 0 : 1;
  if (threadIdx.x == 0) flag[n] = 0;
  __syncthreads();
  const int stay = blockExclusiveScan(flag, n + 1, sh);
  for (int i = threadIdx.x; i < n; i += blockDim.x)
    if (flag[i + 1] != flag[i]) survivors[flag[i]] = ws.members[i];
  __syncthreads();
  int* members = a.members + ws.begin;
  const int added = b.piecesKept;
  for (int i = threadIdx.x; i < stay + added; i += blockDim.x)
    members[i] = i < stay ? survivors[i] : br.spareFirst + (used + i - stay) * a.worlds + w;
  __syncthreads();
  if (threadIdx.x == 0) {
    a.memberCount[w] = stay + added;
    br.spareUsed[w] = used + added;
    br.nextId[w] += added;
    record.topologyOnDevice = 1;
    if (b.floesBroken > 0) atomicAdd(&a.control->floesBroken, b.floesBroken);
    record.floesBroken = b.floesBroken;
    record.rubbleMass = b.rubbleMass;
  }
  __syncthreads();
  return false;
}

// The re-sort of world w after step `step`'s topology phase, as World::curveOrder orders the host's
// bodies (and the device-wide driver's reorderAlongCurve its slots): the box of the world's
// centroids (exact: min and max round nothing), each body's Morton key in it, a stable sort by key
// (ties keep their place). Only the members move: the next step pairs and sums in the new order,
// and the host permutes the state's rows to it after the launch (runResident).
__device__ inline void resortWorld(const ResidentArgs& a, int w, BlockShared& sh) {
  WorldScratch ws = scratchOf(a, w);
  const int n = ws.n;
  if (n < 2) return;
  if (threadIdx.x == 0) sh.bounds[0] = sh.bounds[1] = ~0ull, sh.bounds[2] = sh.bounds[3] = 0ull;
  __syncthreads();
  for (int i = threadIdx.x; i < n; i += blockDim.x) {
    const int slot = ws.members[i];
    const unsigned long long bx = orderedRealBits(a.x[slot]), by = orderedRealBits(a.y[slot]);
    atomicMin(&sh.bounds[0], bx), atomicMin(&sh.bounds[1], by), atomicMax(&sh.bounds[2], bx), atomicMax(&sh.bounds[3], by);
  }
  __syncthreads();
  const Real x0 = fromOrderedRealBits(sh.bounds[0]), y0 = fromOrderedRealBits(sh.bounds[1]);
  const Real scale = curveScale(x0, y0, fromOrderedRealBits(sh.bounds[2]), fromOrderedRealBits(sh.bounds[3]));
  unsigned long long* keys = ws.sweep;  // the world's sweep keys in global memory: bodySort of them
  for (int i = threadIdx.x; i < n; i += blockDim.x) {
    const int slot = ws.members[i];
    keys[i] = (static_cast<unsigned long long>(curveKey(a.x[slot], a.y[slot], x0, y0, scale)) << 32) | static_cast<unsigned>(i);
  }
  __syncthreads();
  blockSort(keys, n, sh);
  int* scratch = a.placeScratch + static_cast<size_t>(w) * static_cast<size_t>(a.bodySort);
  for (int k = threadIdx.x; k < n; k += blockDim.x) scratch[k] = ws.members[keys[k] & 0xffffffffu];
  __syncthreads();
  int* members = a.members + ws.begin;
  for (int k = threadIdx.x; k < n; k += blockDim.x) members[k] = scratch[k];
  if (threadIdx.x == 0) a.control->resorted = 1;
  __syncthreads();
}

// Is any record stream past its capacity (the step is then run again with more room)?
__device__ inline bool recordsOverflowed(const RecordSink& sink) {
  for (int q = 0; q < kMaxRecordStreams; ++q)
    if (sink.streams[q].count && readShared(sink.streams[q].count) > sink.streams[q].capacity) return true;
  return false;
}

template <class Events, class Breaking>
__global__ void __launch_bounds__(kResidentBlock) residentKernel(ResidentArgs a, bool staged) {
  __shared__ BlockShared sh;
  extern __shared__ __align__(16) unsigned char dynamicShared[];
  unsigned char* const dynamic = staged ? dynamicShared : nullptr;
  ResidentControl& control = *a.control;
  if (threadIdx.x == 0) {
    for (long long& c : sh.cycles) c = 0;
    for (long long& c : sh.pairCounts) c = 0;
    sh.stamp = clock64();
  }
  __syncthreads();
  auto gridBarrier = [&] {
    if (gridDim.x > 1)
      cooperative_groups::this_grid().sync();
    else
      __syncthreads();
  };
  const bool leader = blockIdx.x == 0 && threadIdx.x == 0;
  for (int s = 0; s < a.steps; ++s) {
    const int parity = s & 1;
    const long step = a.firstStep + s;
    const StepContext ctx{a.dt, stepTime(step, a.dt), step};
    // The contact counts of this block's worlds, for phase 5 (a block has one world but for
    // ensembles larger than the device; those keep theirs in the world's record slot).
    for (int w = blockIdx.x; w < a.worlds; w += gridDim.x) {
      const int contacts = firstHalf<Events>(a, w, ctx, parity, sh, dynamic);
      if (threadIdx.x == 0) a.worldRing[static_cast<size_t>(s) * a.worlds + w].contacts = contacts;
    }
    gridBarrier();
    mark(sh, 10);
    // Nothing is pushed between the two barriers: every block reads the same counters.
    const bool overflow = readShared(&control.overflow[parity]) != 0 || recordsOverflowed(a.sink);
    if (leader && !overflow) {
      StepRecord r{readShared(&control.candidates[parity]), readShared(&control.contacts[parity]), {}};
      bool topology = false;
      for (int q = 0; q < kMaxRecordStreams; ++q) {
        r.recordEnd[q] = a.sink.streams[q].count ? readShared(a.sink.streams[q].count) : 0;
        topology = topology || (((a.haltStreams >> q) & 1u) && r.recordEnd[q] > control.recordBegin[q]);
        control.recordBegin[q] = r.recordEnd[q];
      }
      a.ring[s] = r;
      control.stepsDone = s + 1;
      // The reason is the most pressing of those given (a world's breakFloes may give one too).
      if (topology) {
        control.halt[parity] = 1;
        atomicMax(&control.haltReason, kHaltBreak);
      } else if (s + 1 == a.steps) {
        atomicMax(&control.haltReason, kHaltDone);
      }
    }
    if (!overflow) {
      // Does a topology stream the kernel leaves to the host have rows this step (the leader halts
      // then)? Every block reads the same counters, as for the overflow.
      bool hostTopology = false;
      for (int q = 0; q < kMaxRecordStreams; ++q)
        if (((a.haltStreams >> q) & 1u) && a.sink.streams[q].count)
          hostTopology = hostTopology || readShared(a.sink.streams[q].count) > (s > 0 ? a.ring[s - 1].recordEnd[q] : 0);
      __syncthreads();
      for (int w = blockIdx.x; w < a.worlds; w += gridDim.x) {
        WorldStepRecord& record = a.worldRing[static_cast<size_t>(s) * a.worlds + w];
        const int contacts = record.contacts;
        __syncthreads();
        secondHalf<Events>(a, w, contacts, ctx, record);
        const bool halted = a.breaking.offset >= 0 && breakFloes<Breaking>(a, w, s, parity, record, sh);
        // A step whose topology the host takes (a halt) re-sorts on the host after it, every world.
        if (a.resort && isResortStep(step + 1) && !hostTopology && !halted) resortWorld(a, w, sh);
      }
    }
    mark(sh, 11);
    if (leader) {
      // The next step's counters start at zero (this step's parity is read until the barrier).
      control.candidates[parity ^ 1] = control.contacts[parity ^ 1] = control.overflow[parity ^ 1] = control.halt[parity ^ 1] = 0;
    }
    gridBarrier();
    mark(sh, 12);
    if (overflow) {
      if (leader) {
        // The overflowed step's rows are dropped: the counters go back to its start.
        for (int q = 0; q < kMaxRecordStreams; ++q)
          if (a.sink.streams[q].count) *a.sink.streams[q].count = control.recordBegin[q];
        atomicMax(&control.haltReason, kHaltOverflow);
      }
      break;
    }
    if (readShared(&control.halt[parity])) break;
    mark(sh, 13);
  }
  if (blockIdx.x == 0 && threadIdx.x == 0)
    for (int k = 0; k < kResidentPhases; ++k) control.phaseCycles[k] += sh.cycles[k];
  if (blockIdx.x == 0 && threadIdx.x == 0)
    for (int k = 0; k < 3; ++k) control.pairCounts[k] = sh.pairCounts[k];
}

}  // namespace gem::cuda::resident
