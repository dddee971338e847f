// Cutting a convex polygon in two along a straight line: the flexural break of docs/model.md 6 cuts
// the floe perpendicular to n at distance L_cusp from the contact point.
#pragma once
#include <cmath>

#include "geometry/clip.hpp"
#include "geometry/sat.hpp"

namespace gem {

namespace detail {

// Appends x unless it repeats the previous point within tol.
GEM_HD inline void pushPoint(Vec2* out, int* k, Vec2 x, Real tol) {
  if (*k > 0 && nearPoint(out[*k - 1], x, tol)) return;
  if (*k < kMaxClipVertices) out[(*k)++] = x;
}

// Drops a repeated closing point and rejects pieces that are not a polygon with area: fewer than
// 3 points, or a sliver thinner than tol (area / extent). Returns the final count.
GEM_HD inline int finishPiece(Vec2* out, int k, Real tol) {
  while (k > 1 && nearPoint(out[k - 1], out[0], tol)) --k;
  if (k < 3) return 0;
  Real twice = 0, extent = 0;
  for (int i = 1; i < k; ++i) {
    if (i + 1 < k) twice += cross(out[i] - out[0], out[i + 1] - out[0]);
    extent = maxR(extent, l1Norm(out[i] - out[0]));
  }
  return Real(0.5) * twice > tol * extent ? k : 0;
}

}  // namespace detail

// Splits convex CCW polygon v by the line through `point` with direction `dir`. left: the part on
// the left of dir (cross(dir, x - point) > 0), right: the other. Either count may be 0 if the line
// misses (or only touches a vertex or an edge). Outputs have room for kMaxClipVertices.
// Both pieces stay counter-clockwise and convex; points on the line go to both, and the two new
// vertices are computed once and shared, so the pieces meet exactly along the cut.
GEM_HD inline void splitByLine(const Vec2* v, int n, Vec2 point, Vec2 dir, Vec2* left, int* nLeft, Vec2* right, int* nRight) {
  *nLeft = *nRight = 0;
  if (n < 3) return;
  Real extent, magnitude;
  detail::extentAndMagnitude(v, n, &extent, &magnitude);
  Real tol = kGeomRelTol * (extent + magnitude);
  int kl = 0, kr = 0;
  Vec2 prev = v[n - 1];
  Real sPrev = cross(dir, prev - point);
  for (int i = 0; i < n; ++i) {
    Vec2 cur = v[i];
    Real sCur = cross(dir, cur - point);
    // A strict sign change along the edge prev -> cur: the cut point belongs to both pieces.
    if ((sPrev > Real(0) && sCur < Real(0)) || (sPrev < Real(0) && sCur > Real(0))) {
      Vec2 x = prev + (sPrev / (sPrev - sCur)) * (cur - prev);
      detail::pushPoint(left, &kl, x, tol);
      detail::pushPoint(right, &kr, x, tol);
    }
    if (sCur >= Real(0)) detail::pushPoint(left, &kl, cur, tol);
    if (sCur <= Real(0)) detail::pushPoint(right, &kr, cur, tol);
    prev = cur;
    sPrev = sCur;
  }
  *nLeft = detail::finishPiece(left, kl, tol);
  *nRight = detail::finishPiece(right, kr, tol);
}

}  // namespace gem
