// The contact of two convex polygons (docs/model.md 3, thesis 3.2.1 and Figure 3.3): overlap area A_0,
// line of contact between the two boundary crossing points, its midpoint c, length w and the
// normal n from P into Q, with the degenerate cases made definite.
#pragma once
#include <cmath>

#include "geometry/clip.hpp"
#include "geometry/sat.hpp"

namespace gem {

struct Contact {
  bool touching;        // overlap area > 0
  Real area;            // A_0, overlap area, m^2
  Vec2 point;           // c: midpoint of the line of contact
  Vec2 normal;          // unit n, perpendicular to the line of contact, pointing from P into Q
  Real width;           // w: length of the line of contact, m
  Vec2 cross0, cross1;  // the two boundary crossing points; always n = perpRight(cross1 - cross0) / w
  bool contained;       // no usable pair of crossing points (one polygon inside the other)
  int apexVertexQ;      // index into q of the Q vertex inside P (inside the overlap) nearest c; -1 if none
  int apexVertexP;      // same for P's vertices inside Q; -1 if none
};

namespace detail {

// Index of the polygon vertex nearest x (used to name the overlap's corner in the input polygon).
GEM_HD inline int nearestVertex(const Vec2* v, int n, Vec2 x) {
  int best = 0;
  Real bestD2 = norm2(v[0] - x);
  for (int i = 1; i < n; ++i) {
    Real d2 = norm2(v[i] - x);
    if (d2 < bestD2) best = i, bestD2 = d2;
  }
  return best;
}

// Among overlap vertices whose both incident edges carry tag (the corners of that polygon inside
// the other), the input vertex of poly nearest c; -1 if there is none.
GEM_HD inline int apexVertex(const ClipVertex* v, int k, signed char tag, Vec2 c, const Vec2* poly, int n) {
  int best = -1;
  Real bestD2 = 0;
  for (int i = 0; i < k; ++i) {
    if (v[i].inEdge != tag || v[i].outEdge != tag) continue;
    Real d2 = norm2(v[i].p - c);
    if (best < 0 || d2 < bestD2) best = i, bestD2 = d2;
  }
  return best < 0 ? -1 : nearestVertex(poly, n, v[best].p);
}

}  // namespace detail

// Contact of convex counter-clockwise polygons p and q (world coordinates) with area centroids
// centroidP and centroidQ. Not touching (all fields zero, apex indices -1) when the separating-axis
// test finds a gap or the overlap is a sliver thinner than kGeomRelTol times its length scale:
// touching without area is no contact (docs/model.md 3).
//
// Line of contact (docs/model.md 3):
// - 2 crossing points: they are its ends.
// - more than 2 (e.g. two triangles crossing as a star): (choice) the two farthest apart.
// - fewer than 2 (one polygon inside the other, or a lone numerical crossing): n along the
//   centroid-to-centroid direction cQ - cP (+x if the centroids coincide), c = the overlap's
//   centroid, w = the overlap's extent across n; cross0/1 = c -/+ w/2 along the line.
// Normal sign: the overlap's boundary runs, counter-clockwise, from the crossing where it leaves
// Q's boundary for P's (cross0) along P's boundary to the other crossing (cross1), then back along
// Q's. P's part is the face of P that has pushed into Q, so it lies on Q's side of the line: to
// the right of cross0 -> cross1. This is exact from the tags; only when the chosen pair does not
// have one crossing of each kind (possible with more than 2) does the tie-break
// dot(n, cQ - cP) >= 0 decide.
//
// computeContact is the separating-axis test, clipConvex, then contactOfOverlap: a driver that
// finds the overlap polygon another way (the resident CUDA driver clips a pair with a whole warp)
// calls contactOfOverlap on it, so the contact itself is written once.
GEM_HD inline Contact contactOfOverlap(const ClipVertex* v, int k, const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m,
                                       Vec2 centroidQ);

// computeContact's second half, for a caller that has already found no separating edge (the CPU
// narrowphase's findSeparatingEdge): the clipping and the contact, without the test again.
// clipTol is clipConvex's merge tolerance (clip.hpp), when the caller has it from the bodies' boxes.
GEM_HD inline Contact contactOfOverlapping(const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m, Vec2 centroidQ, Real clipTol) {
  ClipVertex v[kMaxClipVertices];
  const int k = clipConvex(p, n, q, m, v, clipTol);
  return contactOfOverlap(v, k, p, n, centroidP, q, m, centroidQ);
}

GEM_HD inline Contact contactOfOverlapping(const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m, Vec2 centroidQ) {
  ClipVertex v[kMaxClipVertices];
  const int k = clipConvex(p, n, q, m, v);
  return contactOfOverlap(v, k, p, n, centroidP, q, m, centroidQ);
}

GEM_HD inline Contact computeContact(const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m, Vec2 centroidQ, Real clipTol) {
  // Most candidate pairs from a broadphase are apart: the separating-axis test rejects them
  // faster than the clipping does.
  if (!convexOverlap(p, n, q, m)) return contactOfOverlap(nullptr, 0, p, n, centroidP, q, m, centroidQ);
  return contactOfOverlapping(p, n, centroidP, q, m, centroidQ, clipTol);
}

GEM_HD inline Contact computeContact(const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m, Vec2 centroidQ) {
  if (!convexOverlap(p, n, q, m)) return contactOfOverlap(nullptr, 0, p, n, centroidP, q, m, centroidQ);
  return contactOfOverlapping(p, n, centroidP, q, m, centroidQ);
}

// The contact of p and q from their overlap polygon v[0..k) as clipConvex writes it (k < 3: none).
GEM_HD inline Contact contactOfOverlap(const ClipVertex* v, int k, const Vec2* p, int n, Vec2 centroidP, const Vec2* q, int m,
                                       Vec2 centroidQ) {
  Contact ct{};
  ct.apexVertexQ = ct.apexVertexP = -1;
  if (k < 3) return ct;

  // Area, centroid and bounding box of the overlap in one pass, about v[0] for precision.
  Vec2 o = v[0].p;
  Real twice = 0, cx = 0, cy = 0, x0 = o.x, x1 = o.x, y0 = o.y, y1 = o.y;
  int nCross = 0, i0 = -1, i1 = -1;
  for (int i = 0; i < k; ++i) {
    Vec2 a = v[i].p - o, b = v[i + 1 == k ? 0 : i + 1].p - o;
    Real ai = cross(a, b);
    twice += ai;
    cx += (a.x + b.x) * ai;
    cy += (a.y + b.y) * ai;
    x0 = detail::minR(x0, v[i].p.x), x1 = detail::maxR(x1, v[i].p.x);
    y0 = detail::minR(y0, v[i].p.y), y1 = detail::maxR(y1, v[i].p.y);
    if (v[i].inEdge != v[i].outEdge) {
      if (nCross == 0) {
        i0 = i;
      } else if (nCross == 1) {
        i1 = i;
      }
      ++nCross;
    }
  }
  Real area = Real(0.5) * twice;
  Real extent = detail::maxR(x1 - x0, y1 - y0);
  Real magnitude = detail::maxR(detail::maxR(std::fabs(x0), std::fabs(x1)), detail::maxR(std::fabs(y0), std::fabs(y1)));
  Real tol = kGeomRelTol * (extent + magnitude);
  // A sliver thinner than tol (area / extent) is a touch, not an overlap.
  if (!(area > tol * extent)) return ct;
  ct.touching = true;
  ct.area = area;

  if (nCross > 2) {  // (choice) the farthest pair; ties keep the first found
    Real best = -1;
    for (int i = 0; i < k; ++i) {
      if (v[i].inEdge == v[i].outEdge) continue;
      for (int j = i + 1; j < k; ++j) {
        if (v[j].inEdge == v[j].outEdge) continue;
        Real d2 = norm2(v[j].p - v[i].p);
        if (d2 > best) best = d2, i0 = i, i1 = j;
      }
    }
  }
  if (nCross >= 2) {
    // cross0 is the crossing that leaves Q's boundary for P's (see above).
    if (v[i0].inEdge == 0 && v[i1].inEdge == 1) {
      int t = i0;
      i0 = i1;
      i1 = t;
    }
    Vec2 d = v[i1].p - v[i0].p;
    Real w = norm(d);
    if (w > tol) {
      Vec2 nrm{d.y / w, -d.x / w};
      if (v[i0].inEdge == v[i1].inEdge && dot(nrm, centroidQ - centroidP) < Real(0)) {
        int t = i0;  // same kind of crossing at both ends: the centroid tie-break
        i0 = i1;
        i1 = t;
        nrm = -nrm;
      }
      ct.cross0 = v[i0].p;
      ct.cross1 = v[i1].p;
      ct.normal = nrm;
      ct.width = w;
      ct.point = Real(0.5) * (ct.cross0 + ct.cross1);
    } else {
      nCross = 0;  // two crossings on top of each other: no line, treat as containment
    }
  }
  if (nCross < 2) {
    ct.contained = true;
    ct.point = {o.x + cx / (Real(3) * twice), o.y + cy / (Real(3) * twice)};
    Vec2 dc = centroidQ - centroidP;
    Real len = norm(dc);
    ct.normal = len > tol ? Vec2{dc.x / len, dc.y / len} : Vec2{Real(1), Real(0)};
    Vec2 t = perpLeft(ct.normal);  // along the line: n = perpRight(t)
    Real lo = 0, hi = 0;
    for (int i = 0; i < k; ++i) {
      Real s = dot(t, v[i].p - ct.point);
      lo = detail::minR(lo, s), hi = detail::maxR(hi, s);
    }
    ct.width = hi - lo;
    ct.cross0 = ct.point - Real(0.5) * ct.width * t;
    ct.cross1 = ct.point + Real(0.5) * ct.width * t;
  }
  ct.apexVertexQ = detail::apexVertex(v, k, 1, ct.point, q, m);
  ct.apexVertexP = detail::apexVertex(v, k, 0, ct.point, p, n);
  return ct;
}

}  // namespace gem
