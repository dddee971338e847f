// Internal to framework/cuda: the contact of one overlapping pair computed by a group of lanes (a
// warp, or half of one), for the resident driver (docs/performance.md 4.4: one thread's clipping
// chain, with its 2.3 KB local frame, was the longest phase of a resident step).
//
// clipConvex (geometry/clip.hpp) clips P by each edge of Q in turn; for one edge every vertex's side
// and crossing is independent of the others, so the lanes take a vertex each and a prefix sum
// places what each emits. Only the merging of vertices that coincide within the tolerance is
// sequential; it is rare, so the lanes first check whether any emitted vertex lies within the
// tolerance of the one before it, and only then does the group's first lane run clipConvex's own
// merge (detail::emitVertex) over them. The arithmetic is clipConvex's, through the same helpers
// (detail::clipSide, detail::clipCrossing, detail::clipTolerance), and the vertices come out in its
// order, so the overlap polygon is the same bit for bit; contactOfOverlap then runs on one lane.
#pragma once
#include "geometry/contact.hpp"

namespace gem::cuda {

// Room a warp needs to clip any pair: a clip edge can emit up to two vertices per vertex before the
// merge brings them back under kMaxClipVertices.
constexpr int kWarpClipRoom = 2 * kMaxClipVertices;
// A half warp clips a pair of at most this many vertices in all (the overlap of two convex polygons
// has at most n + m), in half that room; a pair that still needs more is clipped again by a warp.
constexpr int kHalfWarpClipVertices = kMaxVertices;

// The lanes that clip one pair: a whole warp (Lanes 32) or half of one (16), with their own mask.
template <int Lanes>
struct ClipGroup {
  static_assert(Lanes == 32 || Lanes == 16, "a warp or half of one");
  unsigned mask;
  int lane;
  __device__ ClipGroup() : mask(Lanes == 32 ? ~0u : 0xffffu << (threadIdx.x & 16)), lane(static_cast<int>(threadIdx.x & (Lanes - 1))) {}

  __device__ bool any(bool p) const { return __any_sync(mask, p); }
  __device__ void sync() const { __syncwarp(mask); }
  __device__ int fromFirst(int value) const { return __shfl_sync(mask, value, 0, Lanes); }
  // Exclusive prefix sum over the group's lanes of value, which is 0, 1 or 2 (a vertex emits that
  // many): two ballots instead of a shuffle per step of a scan. total: the sum over all lanes.
  __device__ int exclusiveSumOfSmall(int value, int& total) const {
    const unsigned ones = __ballot_sync(mask, (value & 1) != 0) & mask, twos = __ballot_sync(mask, (value & 2) != 0) & mask;
    const unsigned below = (1u << (threadIdx.x & 31)) - 1u;
    total = __popc(ones) + 2 * __popc(twos);
    return __popc(ones & below) + 2 * __popc(twos & below);
  }
};

namespace detail {

// Appends what clipConvex's emitVertex calls would append for buf[0..count), merging in place
// (a vertex is only ever written at or before the place it is read from), then closes the ring.
// Every lane of the group calls it; returns the vertex count on every lane.
template <int Lanes>
__device__ inline int groupMergeRun(const ClipGroup<Lanes>& g, ClipVertex* buf, int count, Real tol) {
  bool near = false;
  for (int c = g.lane + 1; c < count; c += Lanes) near = near || gem::detail::nearPoint(buf[c - 1].p, buf[c].p, tol);
  const bool mergeNeeded = g.any(near) || count > kMaxClipVertices;
  int k = count;
  if (g.lane == 0) {
    if (mergeNeeded) {
      k = 0;
      for (int c = 0; c < count; ++c) {
        const ClipVertex v = buf[c];
        gem::detail::emitVertex(buf, &k, v.p, v.inEdge, v.outEdge, tol);
      }
    }
    k = gem::detail::closeRing(buf, k, tol);
  }
  k = g.fromFirst(k);
  g.sync();
  return k;
}

// The vertices one clip vertex emits, in clipConvex's order: how many (0, 1 or 2), written from
// out[0] when out is not null.
__device__ inline int emitted(const ClipVertex& cur, Real sCur, Vec2 prev, Real sPrev, ClipVertex* out) {
  if (sCur >= Real(0)) {
    if (sPrev < Real(0)) {  // entering: the crossing, then the vertex
      if (out) {
        out[0] = ClipVertex{gem::detail::clipCrossing(prev, sPrev, cur.p, sCur), 1, cur.inEdge};
        out[1] = cur;
      }
      return 2;
    }
    if (out) out[0] = cur;
    return 1;
  }
  if (sPrev >= Real(0)) {  // leaving: the crossing only
    if (out) out[0] = ClipVertex{gem::detail::clipCrossing(prev, sPrev, cur.p, sCur), cur.inEdge, 1};
    return 1;
  }
  return 0;
}

}  // namespace detail

// clipConvex(p, n, q, m, buf) by the lanes of a group, each with the same arguments: the overlap
// polygon in buf[0..k) (buf: `room` vertices in memory the group shares), k returned on every lane,
// 0 when there is no overlap, -1 when the polygon outgrew the room or the group (a half warp only:
// clip the pair again with a warp and kWarpClipRoom). The same vertices, bit for bit, as clipConvex.
template <int Lanes>
__device__ inline int groupClipConvex(const ClipGroup<Lanes>& g, const Vec2* p, int n, const Vec2* q, int m, ClipVertex* buf, int room) {
  if (n < 3 || m < 3) return 0;
  if (n > room) return -1;
  const Real tol = gem::detail::clipTolerance(p, n, q, m);
  for (int i = g.lane; i < n; i += Lanes) buf[i] = ClipVertex{p[i], 0, 0};
  g.sync();
  int k = detail::groupMergeRun(g, buf, n, tol);
  for (int j = 0; j < m && k >= 3; ++j) {
    if (k > 2 * Lanes) return -1;  // two vertices a lane (a warp holds kMaxClipVertices)
    const Vec2 a = q[j], e = q[j + 1 == m ? 0 : j + 1] - a;
    // This lane's vertices of the polygon so far, each with the vertex before it.
    ClipVertex cur[2];
    Vec2 prev[2];
    Real sCur[2], sPrev[2];
    int count[2] = {0, 0};
    bool out = false, in = false;
    for (int h = 0; h < 2; ++h) {
      const int i = g.lane + Lanes * h;
      if (i >= k) continue;
      cur[h] = buf[i];
      prev[h] = buf[i == 0 ? k - 1 : i - 1].p;
      sCur[h] = gem::detail::clipSide(a, e, cur[h].p);
      sPrev[h] = gem::detail::clipSide(a, e, prev[h]);
      // clipConvex's test: not outside counts as inside (so a NaN side is inside there too).
      if (sCur[h] < Real(0))
        out = true;
      else
        in = true;
      count[h] = detail::emitted(cur[h], sCur[h], prev[h], sPrev[h], nullptr);
    }
    const bool anyOut = g.any(out), anyIn = g.any(in);
    if (!anyOut) continue;  // this edge does not cut the polygon
    if (!anyIn) return 0;   // wholly outside this edge: no overlap
    int total0 = 0, total1 = 0;
    const int at0 = g.exclusiveSumOfSmall(count[0], total0);
    const int at1 = total0 + g.exclusiveSumOfSmall(count[1], total1);
    if (total0 + total1 > room) return -1;
    g.sync();  // every lane has read the polygon before any overwrites it
    if (count[0]) detail::emitted(cur[0], sCur[0], prev[0], sPrev[0], buf + at0);
    if (count[1]) detail::emitted(cur[1], sCur[1], prev[1], sPrev[1], buf + at1);
    g.sync();
    k = detail::groupMergeRun(g, buf, total0 + total1, tol);
  }
  return k >= 3 ? k : 0;
}

// computeContact(p, n, cp, q, m, cq) for a pair that convexOverlap has already found overlapping,
// by the lanes of a group (buf and room as groupClipConvex's). The result is on the group's first
// lane; `clipped` is false (on every lane) when the polygon outgrew the room (see groupClipConvex).
template <int Lanes>
__device__ inline Contact groupContactOfOverlapping(const ClipGroup<Lanes>& g, const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m,
                                                    Vec2 centroidQ, ClipVertex* buf, int room, bool& clipped) {
  const int k = groupClipConvex(g, p, n, q, m, buf, room);
  clipped = k >= 0;
  Contact c{};
  c.apexVertexP = c.apexVertexQ = -1;
  if (clipped && g.lane == 0) c = contactOfOverlap(buf, k, p, n, centroidP, q, m, centroidQ);
  g.sync();  // buf is read by the first lane until here
  return c;
}

// The same by a whole warp, which always has room (buf: kWarpClipRoom vertices).
__device__ inline Contact warpContactOfOverlapping(const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m, Vec2 centroidQ,
                                                   ClipVertex* buf) {
  bool clipped = true;
  return groupContactOfOverlapping(ClipGroup<32>{}, p, n, centroidP, q, m, centroidQ, buf, kWarpClipRoom, clipped);
}

// One pair's polygons, as a driver hands them to warpContactsOfTwo.
struct PairPolygons {
  const Vec2* p;
  int n;
  Vec2 centroidP;
  const Vec2* q;
  int m;
  Vec2 centroidQ;
};

// The contacts of overlapping pairs j0 and, when j0 + 1 < count, j0 + 1, by one warp (every lane
// calls it with the same arguments): each by a half warp when both are small enough
// (kHalfWarpClipVertices), else, or when a half warp ran out of room, by the whole warp after.
// fetch(j) gives pair j's PairPolygons; store(j, contact) runs on the lane that has the contact.
// buf: kWarpClipRoom vertices of memory the warp shares. HalfRoom: each half's share of it (less
// only in the test that makes the half warps run out of room).
template <int HalfRoom = kWarpClipRoom / 2, class Fetch, class Store>
__device__ inline void warpContactsOfTwo(int j0, int count, const Fetch& fetch, const Store& store, ClipVertex* buf) {
  static_assert(HalfRoom <= kWarpClipRoom / 2, "two halves share the warp's room");
  const bool second = j0 + 1 < count;
  const PairPolygons first = fetch(j0), other = second ? fetch(j0 + 1) : first;
  const bool halves = first.n + first.m <= kHalfWarpClipVertices && (!second || other.n + other.m <= kHalfWarpClipVertices);
  bool redoFirst = !halves, redoOther = !halves && second;
  if (halves) {
    const ClipGroup<16> g;
    const int half = static_cast<int>((threadIdx.x >> 4) & 1);
    bool clipped = true;
    if (half == 0 || second) {
      const PairPolygons& mine = half ? other : first;
      const Contact c = groupContactOfOverlapping(g, mine.p, mine.n, mine.centroidP, mine.q, mine.m, mine.centroidQ, buf + half * HalfRoom,
                                                  HalfRoom, clipped);
      if (clipped && g.lane == 0) store(j0 + half, c);
    }
    const unsigned failed = __ballot_sync(~0u, !clipped);
    redoFirst = (failed & 1u) != 0;
    redoOther = ((failed >> 16) & 1u) != 0;
    __syncwarp();  // both halves are done with buf before the whole warp writes it (racecheck)
  }
  const int lane = static_cast<int>(threadIdx.x & 31);
  if (redoFirst) {
    const Contact c = warpContactOfOverlapping(first.p, first.n, first.centroidP, first.q, first.m, first.centroidQ, buf);
    if (lane == 0) store(j0, c);
  }
  if (redoOther) {
    const Contact c = warpContactOfOverlapping(other.p, other.n, other.centroidP, other.q, other.m, other.centroidQ, buf);
    if (lane == 0) store(j0 + 1, c);
  }
}

}  // namespace gem::cuda
