// Overlap polygon P ∩ Q of two convex polygons (docs/model.md 3), with the provenance of every vertex
// so that the points where the two boundaries cross (the ends of the line of contact) can be read
// off the result.
//
// Sutherland–Hodgman: P is clipped by the half-plane of each edge of Q in turn. O(n m), but with
// n, m <= 24 and most Q edges leaving P untouched (skipped after one pass of sign tests) it beats
// the O(n + m) O'Rourke walk in practice and has no special cases to get wrong.
#pragma once
#include <cmath>

#include "geometry/sat.hpp"

namespace gem {

// A vertex of the overlap with the tags of the boundary arriving at it and leaving it (counter-
// clockwise): 0 = along P's boundary, 1 = along Q's boundary. inEdge != outEdge marks a point
// where the boundaries cross; 0/0 is a vertex of P inside Q, 1/1 a vertex of Q inside P.
struct ClipVertex {
  Vec2 p;
  signed char inEdge;
  signed char outEdge;
};

// A polygon's length scales for the merge tolerance of clipConvex: its bounding box's largest side
// and its largest |coordinate|.
struct ClipScale {
  Real extent, magnitude;
};

// The scales from the polygon's bounding box (x0, y0) to (x1, y1), for a caller that keeps each
// body's box (the CPU narrowphase's m_boxes, from boundingBox in geometry/polygon.hpp): the values
// clipConvex finds from the vertices themselves. (The two minima differ at most in which of two
// equal zeros they keep, which changes neither scale.)
GEM_HD inline ClipScale clipScaleOfBox(Real x0, Real y0, Real x1, Real y1) {
  using detail::maxR;
  return {maxR(x1 - x0, y1 - y0), maxR(maxR(std::fabs(x0), std::fabs(x1)), maxR(std::fabs(y0), std::fabs(y1)))};
}

// The merge tolerance of clipConvex for polygons of scales p and q: vertices closer than this are
// one vertex. Relative to the smaller body (the overlap's scale) and to the coordinate magnitude
// (the rounding of world coordinates).
GEM_HD inline Real clipToleranceOf(ClipScale p, ClipScale q) {
  return kGeomRelTol * (detail::minR(p.extent, q.extent) + detail::maxR(p.magnitude, q.magnitude));
}

namespace detail {

// Largest bounding-box side and largest |coordinate| of a polygon: the length scales of the
// merge tolerance.
GEM_HD inline void extentAndMagnitude(const Vec2* v, int n, Real* extent, Real* magnitude) {
  Real x0 = v[0].x, x1 = v[0].x, y0 = v[0].y, y1 = v[0].y;
  for (int i = 1; i < n; ++i) {
    x0 = minR(x0, v[i].x), x1 = maxR(x1, v[i].x);
    y0 = minR(y0, v[i].y), y1 = maxR(y1, v[i].y);
  }
  const ClipScale scale = clipScaleOfBox(x0, y0, x1, y1);
  *extent = scale.extent, *magnitude = scale.magnitude;
}

GEM_HD inline bool nearPoint(Vec2 a, Vec2 b, Real tol) { return std::fabs(a.x - b.x) <= tol && std::fabs(a.y - b.y) <= tol; }

// Appends a vertex, merging it into the previous one when they coincide within tol: the merged
// vertex keeps the arriving tag of the first and the leaving tag of the second, so a crossing that
// lands on a vertex is still seen, and a touch without crossing (1 in, 1 out) is not.
GEM_HD inline void emitVertex(ClipVertex* dst, int* k, Vec2 p, signed char in, signed char out, Real tol) {
  if (*k > 0 && nearPoint(dst[*k - 1].p, p, tol)) {
    dst[*k - 1].outEdge = out;
  } else if (*k < kMaxClipVertices) {
    dst[*k] = ClipVertex{p, in, out};
    ++*k;
  }
}

// emitVertex with the last vertex held in registers until the next one is known: the same
// vertices and tags, stored once, field by field. (Updating a stored vertex's one-byte tag and
// reading the vertex back whole soon after stalls the CPU's store forwarding; so does building
// the whole struct from its bytes.)
struct ClipWriter {
  ClipVertex* dst;
  Real tol;
  int k = 0;
  Vec2 lastP{};  // dst[k - 1], not yet stored
  signed char lastIn = 0, lastOut = 0;
  GEM_HD void emit(Vec2 p, signed char in, signed char out) {
    if (k > 0 && nearPoint(lastP, p, tol)) {
      lastOut = out;
    } else if (k < kMaxClipVertices) {
      store();
      lastP = p, lastIn = in, lastOut = out;
      ++k;
    }
  }
  GEM_HD void store() {
    if (k == 0) return;
    dst[k - 1].p = lastP;
    dst[k - 1].inEdge = lastIn;
    dst[k - 1].outEdge = lastOut;
  }
  GEM_HD int finish() {
    store();
    return k;
  }
};

// The merge tolerance of clipConvex for polygons p (n vertices) and q (m): clipToleranceOf their
// scales.
GEM_HD inline Real clipTolerance(const Vec2* p, int n, const Vec2* q, int m) {
  ClipScale scaleP, scaleQ;
  extentAndMagnitude(p, n, &scaleP.extent, &scaleP.magnitude);
  extentAndMagnitude(q, m, &scaleQ.extent, &scaleQ.magnitude);
  return clipToleranceOf(scaleP, scaleQ);
}

// Which side of the clip line through a along e the point x lies on: >= 0 is inside (left of a
// counter-clockwise edge of Q), < 0 outside.
GEM_HD inline Real clipSide(Vec2 a, Vec2 e, Vec2 x) { return cross(e, x - a); }

// Where the segment prev -> cur, with sides sPrev and sCur of opposite signs, crosses the clip
// line. The signs differ, so the denominator is never zero.
GEM_HD inline Vec2 clipCrossing(Vec2 prev, Real sPrev, Vec2 cur, Real sCur) { return prev + (sPrev / (sPrev - sCur)) * (cur - prev); }

// Closes the ring: merges the last vertex into the first while they coincide.
GEM_HD inline int closeRing(ClipVertex* v, int k, Real tol) {
  while (k > 1 && nearPoint(v[k - 1].p, v[0].p, tol)) {
    v[0].inEdge = v[k - 1].inEdge;
    --k;
  }
  return k;
}

}  // namespace detail

// Writes P ∩ Q (counter-clockwise, no two consecutive vertices within the merge tolerance) into
// out, which has room for kMaxClipVertices, and returns its vertex count; 0 when the overlap is
// empty or has collapsed to fewer than 3 vertices (touching at a point or along an edge).
// A point exactly on a clip line counts as inside, so an edge of P lying along an edge of Q stays
// tagged 0 and the crossings are where the other boundary leaves it.
// tol is the merge tolerance, detail::clipTolerance(p, n, q, m) (the overload below), or
// clipToleranceOf the scales of the polygons' bounding boxes where the caller keeps them.
GEM_HD inline int clipConvex(const Vec2* p, int n, const Vec2* q, int m, ClipVertex* out, Real tol) {
  if (n < 3 || m < 3) return 0;

  ClipVertex tmp[kMaxClipVertices];
  ClipVertex* src = out;
  ClipVertex* dst = tmp;
  detail::ClipWriter first{src, tol};
  for (int i = 0; i < n; ++i) first.emit(p[i], 0, 0);
  int k = detail::closeRing(src, first.finish(), tol);

  Real side[kMaxClipVertices];
  for (int j = 0; j < m && k >= 3; ++j) {
    Vec2 a = q[j], e = q[j + 1 == m ? 0 : j + 1] - a;
    // Signed test: cross(e, x - a) >= 0 is inside (left of a counter-clockwise edge). Each
    // vertex's side is computed once and kept for the clipping below; counting instead of
    // branching, as most edges leave the polygon untouched.
    int outside = 0;
    for (int i = 0; i < k; ++i) {
      side[i] = detail::clipSide(a, e, src[i].p);
      outside += side[i] < Real(0);
    }
    if (outside == 0) continue;  // this edge does not cut the polygon: nothing to copy
    if (outside == k) return 0;  // wholly outside this edge: no overlap

    detail::ClipWriter w{dst, tol};
    Vec2 prev = src[k - 1].p;
    Real sPrev = side[k - 1];
    for (int i = 0; i < k; ++i) {
      const Vec2 cur = src[i].p;
      const signed char in = src[i].inEdge;
      const Real sCur = side[i];
      if (sCur >= Real(0)) {
        if (sPrev < Real(0)) w.emit(detail::clipCrossing(prev, sPrev, cur, sCur), 1, in);  // entering Q's half-plane
        w.emit(cur, in, src[i].outEdge);
      } else if (sPrev >= Real(0)) {  // leaving: arrive along the edge, continue along Q
        w.emit(detail::clipCrossing(prev, sPrev, cur, sCur), in, 1);
      }
      prev = cur;
      sPrev = sCur;
    }
    k = detail::closeRing(dst, w.finish(), tol);
    ClipVertex* t = src;
    src = dst;
    dst = t;
  }
  if (k < 3) return 0;
  if (src != out)
    for (int i = 0; i < k; ++i) out[i] = src[i];
  return k;
}

GEM_HD inline int clipConvex(const Vec2* p, int n, const Vec2* q, int m, ClipVertex* out) {
  if (n < 3 || m < 3) return 0;
  return clipConvex(p, n, q, m, out, detail::clipTolerance(p, n, q, m));
}

// Area of a clipped polygon (shoelace about its first vertex, for precision far from the origin).
GEM_HD inline Real clippedArea(const ClipVertex* v, int k) {
  Real twice = 0;
  for (int i = 1; i + 1 < k; ++i) twice += cross(v[i].p - v[0].p, v[i + 1].p - v[0].p);
  return Real(0.5) * twice;
}

}  // namespace gem
