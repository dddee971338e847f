// Ear clipping of a polygon into triangles and the triangle-triangle overlap test of the
// triangulation-mesh broadphase (docs/model.md 9, thesis 5.3.1).
#pragma once
#include <cmath>

#include "geometry/vec2.hpp"

namespace gem {

struct Triangle {
  Vec2 a, b, c;
};

namespace detail {

// x inside or on the boundary of the counter-clockwise triangle (a, b, c).
GEM_HD inline bool inClosedTriangle(Vec2 x, Vec2 a, Vec2 b, Vec2 c) {
  return cross(b - a, x - a) >= Real(0) && cross(c - b, x - b) >= Real(0) && cross(a - c, x - c) >= Real(0);
}

}  // namespace detail

// Triangulates the simple counter-clockwise polygon v (convex or not, n <= kMaxVertices) by ear
// clipping: repeatedly cut off a vertex whose corner turns left and whose triangle holds no other
// remaining vertex. Writes n - 2 index triples (counter-clockwise) into tri and returns n - 2
// (0 for n < 3). A convex polygon comes out as a fan from vertex 0. O(n^3) worst case, run once
// per body. Collinear corners are never chosen while a proper ear exists; if rounding leaves no
// proper ear the sharpest remaining corner is cut, so the call always finishes.
GEM_HD inline int earClip(const Vec2* v, int n, int (*tri)[3]) {
  if (n < 3) return 0;
  int idx[kMaxVertices];
  int r = n < kMaxVertices ? n : kMaxVertices;
  for (int i = 0; i < r; ++i) idx[i] = i;
  int t = 0;
  while (r > 3) {
    int ear = -1, fallback = 0;
    Real fallbackTurn = -1;
    for (int i = 0; i < r && ear < 0; ++i) {
      Vec2 a = v[idx[i == 0 ? r - 1 : i - 1]], b = v[idx[i]], c = v[idx[i + 1 == r ? 0 : i + 1]];
      Real turn = cross(b - a, c - b);
      if (turn > fallbackTurn) fallbackTurn = turn, fallback = i;
      if (!(turn > Real(0))) continue;
      bool empty = true;
      for (int j = 0; j < r && empty; ++j) {
        Vec2 x = v[idx[j]];
        bool corner = (x.x == a.x && x.y == a.y) || (x.x == b.x && x.y == b.y) || (x.x == c.x && x.y == c.y);
        if (!corner && detail::inClosedTriangle(x, a, b, c)) empty = false;
      }
      if (empty) ear = i;
    }
    if (ear < 0) ear = fallback;
    tri[t][0] = idx[ear == 0 ? r - 1 : ear - 1];
    tri[t][1] = idx[ear];
    tri[t][2] = idx[ear + 1 == r ? 0 : ear + 1];
    ++t;
    for (int i = ear; i + 1 < r; ++i) idx[i] = idx[i + 1];
    --r;
  }
  tri[t][0] = idx[0];
  tri[t][1] = idx[1];
  tri[t][2] = idx[2];
  return t + 1;
}

// True when the counter-clockwise triangles t0 and t1 (3 vertices each) overlap or come within
// eps (m) of each other: separating-axis test over the six edge normals. Conservative, as a
// broadphase must be: touching counts as overlapping even for eps = 0. No square roots: a gap g
// along an unnormalised normal of length |e| separates when g > 0 and g^2 > eps^2 |e|^2.
GEM_HD inline bool trianglesOverlap(const Vec2* t0, const Vec2* t1, Real eps) {
  const Vec2* s[2] = {t0, t1};
  for (int k = 0; k < 2; ++k) {
    const Vec2* a = s[k];
    const Vec2* b = s[1 - k];
    for (int i = 0; i < 3; ++i) {
      Vec2 e = a[i == 2 ? 0 : i + 1] - a[i];
      Vec2 nrm{e.y, -e.x};  // outward for a counter-clockwise triangle
      Real g0 = dot(nrm, b[0] - a[i]), g1 = dot(nrm, b[1] - a[i]), g2 = dot(nrm, b[2] - a[i]);
      Real g = g0 < g1 ? g0 : g1;
      g = g < g2 ? g : g2;
      if (g > Real(0) && g * g > eps * eps * norm2(e)) return false;
    }
  }
  return true;
}

}  // namespace gem
