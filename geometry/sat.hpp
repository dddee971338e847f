// Separating-axis overlap test of two convex polygons (docs/model.md 3: "in contact when they overlap
// (separating axis test over the edge normals of both)"), and the geometry tolerance shared by the
// clipping, contact and split headers.
#pragma once
#include <cmath>

#include "geometry/vec2.hpp"

namespace gem {

// Relative tolerance of the geometry predicates: a penetration, sliver or vertex gap smaller than
// this times the local length scale (body size + coordinate magnitude) is treated as zero. It sits
// well above the rounding of the engine's Real (2e-16 for double, 1.2e-7 for float: about 8 ulps
// there) and far below anything physical (double: 1 nm at 1 km from the origin; float: 1 mm).
// Without it, bodies that share an edge touch or overlap at random once rotated into world
// coordinates (tests/cgal: DegenerateGridPairs).
constexpr Real kGeomRelTol = sizeof(Real) >= 8 ? Real(1e-12) : Real(1e-6);

// Cheap length scale of a vector without a square root: |a|_1 lies within sqrt(2) of |a|.
GEM_HD inline Real l1Norm(Vec2 a) { return std::fabs(a.x) + std::fabs(a.y); }

namespace detail {

// Plain min/max: std::fmin/fmax honour NaN rules and are library calls on the host.
GEM_HD inline Real minR(Real a, Real b) { return a < b ? a : b; }
GEM_HD inline Real maxR(Real a, Real b) { return a > b ? a : b; }

// True when edge i of p (from p[i] to p[i + 1]) separates q: every q vertex lies on or outside the
// edge's line (to within the tolerance), so touching along an edge or at a point is separation,
// not overlap. An edge that does not separate needs one witness, a q vertex inside its line; the
// search starts at `witness` and leaves there the one it found. Where it starts changes only how
// soon it stops: each vertex's test is the same arithmetic, so the answer is the same.
GEM_HD inline bool edgeSeparatesFrom(const Vec2* p, int n, int i, const Vec2* q, int m, int& witness) {
  Vec2 a = p[i], e = p[i + 1 == n ? 0 : i + 1] - a;
  // Outward normal of a counter-clockwise edge, unnormalised (length |e|): dot(nrm, x - a) is
  // |e| times the signed distance of x outside the edge.
  Vec2 nrm{e.y, -e.x};
  // Allowed penetration: kGeomRelTol times (edge length + coordinate magnitude), so that the
  // rounding of world coordinates far from the origin cannot fake an overlap of touching bodies.
  Real le = l1Norm(e);
  Real tol = kGeomRelTol * le * (le + l1Norm(a));
  for (int tested = 0; tested < m; ++tested) {
    if (dot(nrm, q[witness] - a) < -tol) return false;
    witness = witness + 1 == m ? 0 : witness + 1;
  }
  return true;
}

// True when some edge of p separates q. Each edge's search for a witness starts at the last
// edge's: the q vertices inside one edge of p are most often inside the next one too, so for
// overlapping polygons most searches stop at their first test.
GEM_HD inline bool edgeSeparates(const Vec2* p, int n, const Vec2* q, int m) {
  int witness = 0;
  for (int i = 0; i < n; ++i)
    if (edgeSeparatesFrom(p, n, i, q, m, witness)) return true;
  return false;
}

}  // namespace detail

// True when the interiors of the counter-clockwise convex polygons p and q overlap. For convex
// polygons the edge normals of both are the only candidate separating axes. Cost O(n m) in the
// worst case, but a non-separating axis usually exits after a vertex or two.
GEM_HD inline bool convexOverlap(const Vec2* p, int n, const Vec2* q, int m) {
  return !detail::edgeSeparates(p, n, q, m) && !detail::edgeSeparates(q, m, p, n);
}

// The CPU narrowphase's rejection of apart pairs, one edge at a time, so that the edge that
// separated a pair last step can be tried first (docs/performance.md 4.1). An edge found here is an
// edge convexOverlap finds too (the same test, detail::edgeSeparatesFrom): the pair does not touch,
// and computeContact would return "not touching".

// A candidate separating axis: the outward normal of edge `edge` of p (side 0) or of q (side 1).
struct SeparatingEdge {
  int side;  // 0: an edge of p, 1: an edge of q, -1: none (the interiors overlap)
  int edge;
};

// True when edge i of p (from p[i] to p[i + 1]) separates q: edgeSeparatesFrom's test of every q
// vertex, the same arithmetic, without its early exit. This is the CPU narrowphase's first try at a
// pair that was apart last step, and there it nearly always separates, so every vertex is tested
// anyway: counting the vertices inside, with no branch and no wrap-around, is cheaper than stopping
// at the first.
GEM_HD inline bool edgeSeparatesAt(const Vec2* p, int n, int i, const Vec2* q, int m) {
  const Vec2 a = p[i], e = p[i + 1 == n ? 0 : i + 1] - a;
  const Vec2 nrm{e.y, -e.x};
  const Real le = l1Norm(e);
  const Real tol = kGeomRelTol * le * (le + l1Norm(a));
  int inside = 0;
  for (int j = 0; j < m; ++j) inside += dot(nrm, q[j] - a) < -tol;
  return inside == 0;
}

// True when `axis` (any side and index; an index out of range is simply not tried) separates p and q.
GEM_HD inline bool separatesAlong(SeparatingEdge axis, const Vec2* p, int n, const Vec2* q, int m) {
  if (axis.side == 0) return axis.edge >= 0 && axis.edge < n && edgeSeparatesAt(p, n, axis.edge, q, m);
  if (axis.side == 1) return axis.edge >= 0 && axis.edge < m && edgeSeparatesAt(q, m, axis.edge, p, n);
  return false;
}

// The first separating edge in convexOverlap's order (p's edges, then q's), or side -1 exactly
// when convexOverlap(p, n, q, m) is true.
GEM_HD inline SeparatingEdge findSeparatingEdge(const Vec2* p, int n, const Vec2* q, int m) {
  int witness = 0;
  for (int i = 0; i < n; ++i)
    if (detail::edgeSeparatesFrom(p, n, i, q, m, witness)) return {0, i};
  witness = 0;
  for (int i = 0; i < m; ++i)
    if (detail::edgeSeparatesFrom(q, m, i, p, n, witness)) return {1, i};
  return {-1, 0};
}

}  // namespace gem
