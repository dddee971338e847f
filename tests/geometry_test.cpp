// Small exact cases of the geometry headers (docs/architecture.md "Tests": a square hitting a square first).
// The random cross-checks against CGAL's exact kernel are in tests/cgal/geometry_cgal_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "geometry/clip.hpp"
#include "geometry/contact.hpp"
#include "geometry/packed_host.hpp"
#include "geometry/polygon.hpp"
#include "geometry/sat.hpp"
#include "geometry/split.hpp"
#include "geometry/triangulate.hpp"

using namespace gem;

namespace {

// Tolerances for the engine's Real: exact cases hold to rounding.
constexpr double kTol = sizeof(Real) >= 8 ? 1e-12 : 2e-5;

using Poly = std::vector<Vec2>;

Poly rect(Real x0, Real y0, Real x1, Real y1) { return {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}; }

Poly moved(Poly p, Vec2 by, Real angle = 0, Vec2 about = {0, 0}) {
  for (Vec2& v : p) v = about + rotate(v - about, angle) + by;
  return p;
}

Contact contactOf(const Poly& p, const Poly& q) {
  return computeContact(p.data(), int(p.size()), areaCentroid(p.data(), int(p.size())), q.data(), int(q.size()),
                        areaCentroid(q.data(), int(q.size())));
}

void expectVec(Vec2 a, Vec2 b, double tol = kTol) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
}

Poly regular(int n, Real r, Real phase = 0, Vec2 c = {0, 0}) {
  Poly p;
  for (int i = 0; i < n; ++i) p.push_back(c + rotate(Vec2{r, 0}, phase + 2 * kPi * i / n));
  return p;
}

}  // namespace

// ---- mass properties (docs/model.md 1) ----

TEST(Geometry, UnitSquareMassProperties) {
  Poly s = rect(0, 0, 1, 1);
  MassProperties mp = massProperties(s.data(), 4);
  EXPECT_NEAR(mp.area, 1.0, kTol);
  expectVec(mp.centroid, {0.5, 0.5});
  EXPECT_NEAR(mp.jxx, 1.0 / 12, kTol);  // b h^3 / 12
  EXPECT_NEAR(mp.jyy, 1.0 / 12, kTol);
  EXPECT_NEAR(mp.jxy, 0.0, kTol);
  EXPECT_NEAR(mp.izz, 1.0 / 6, kTol);
}

TEST(Geometry, RectanglePrincipalAngle) {
  // 4 m along x, 2 m along y: J_xx = b h^3 / 12 = 8/3, J_yy = h b^3 / 12 = 32/3.
  Poly r = rect(-2, -1, 2, 1);
  MassProperties mp = massProperties(r.data(), 4);
  EXPECT_NEAR(mp.area, 8.0, kTol);
  EXPECT_NEAR(mp.jxx, 8.0 / 3, kTol);
  EXPECT_NEAR(mp.jyy, 32.0 / 3, kTol);
  // theta_p = 1/2 atan2(-2 J_xy, J_xx - J_yy) = +-pi/2 (the same axis).
  EXPECT_NEAR(std::fabs(mp.principalAngle), kPi / 2, kTol);
  EXPECT_NEAR(mp.ixx, 32.0 / 3, 10 * kTol);
  EXPECT_NEAR(mp.iyy, 8.0 / 3, 10 * kTol);
  // Tall rectangle: already principal, theta_p = 0.
  Poly t = rect(-1, -2, 1, 2);
  MassProperties mt = massProperties(t.data(), 4);
  EXPECT_NEAR(mt.principalAngle, 0.0, kTol);
  EXPECT_NEAR(mt.ixx, 32.0 / 3, 10 * kTol);
}

TEST(Geometry, RotatedRectanglePrincipalAngle) {
  for (Real alpha : {Real(0.3), Real(-1.1), Real(1.4)}) {
    Poly t = moved(rect(-1, -2, 1, 2), {7, -3}, alpha);
    MassProperties mp = massProperties(t.data(), 4);
    EXPECT_NEAR(mp.area, 8.0, 100 * kTol);
    expectVec(mp.centroid, {7, -3}, 100 * kTol);
    EXPECT_NEAR(mp.principalAngle, alpha, 100 * kTol);
    EXPECT_NEAR(mp.ixx, 32.0 / 3, 1000 * kTol);
    EXPECT_NEAR(mp.iyy, 8.0 / 3, 1000 * kTol);
    EXPECT_NEAR(mp.izz, 40.0 / 3, 1000 * kTol);
  }
}

// ---- orientation and convexity ----

TEST(Geometry, ClockwisePolygonIsReversed) {
  Poly s = {{0, 0}, {0, 1}, {1, 1}, {1, 0}};
  EXPECT_LT(signedArea(s.data(), 4), 0);
  EXPECT_FALSE(isStrictlyConvexCCW(s.data(), 4));
  reverseOrder(s.data(), 4);
  EXPECT_NEAR(signedArea(s.data(), 4), 1.0, kTol);
  EXPECT_TRUE(isStrictlyConvexCCW(s.data(), 4));
}

TEST(Geometry, StrictConvexityRejects) {
  Poly square = rect(0, 0, 1, 1);
  EXPECT_TRUE(isStrictlyConvexCCW(square.data(), 4));
  Poly p19 = regular(19, 3);
  EXPECT_TRUE(isStrictlyConvexCCW(p19.data(), 19));
  Poly ell = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  EXPECT_FALSE(isStrictlyConvexCCW(ell.data(), 6));
  Poly bowtie = {{0, 0}, {1, 1}, {1, 0}, {0, 1}};
  EXPECT_FALSE(isStrictlyConvexCCW(bowtie.data(), 4));
  Poly pentagram;
  for (int i = 0; i < 5; ++i) pentagram.push_back(rotate(Vec2{1, 0}, 4 * kPi * i / 5));
  EXPECT_FALSE(isStrictlyConvexCCW(pentagram.data(), 5));
  Poly collinear = {{0, 0}, {0.5, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_FALSE(isStrictlyConvexCCW(collinear.data(), 5));
  Poly duplicate = {{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_FALSE(isStrictlyConvexCCW(duplicate.data(), 5));
  EXPECT_FALSE(isStrictlyConvexCCW(square.data(), 2));
}

TEST(Geometry, InteriorAngle) {
  Poly s = rect(0, 0, 1, 1);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(interiorAngle(s.data(), 4, i), kPi / 2, kTol);
  Poly t = regular(3, 1);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(interiorAngle(t.data(), 3, i), kPi / 3, 10 * kTol);
}

// ---- separating axes and clipping ----

TEST(Geometry, ConvexOverlap) {
  Poly a = rect(0, 0, 1, 1);
  Poly b = rect(0.5, 0.5, 1.5, 1.5);
  EXPECT_TRUE(convexOverlap(a.data(), 4, b.data(), 4));
  EXPECT_TRUE(convexOverlap(b.data(), 4, a.data(), 4));
  Poly edge = rect(1, 0, 2, 1), corner = rect(1, 1, 2, 2), apart = rect(1.01, 0, 2, 1);
  for (const Poly* q : {&edge, &corner, &apart}) {
    EXPECT_FALSE(convexOverlap(a.data(), 4, q->data(), 4));
    EXPECT_FALSE(convexOverlap(q->data(), 4, a.data(), 4));
  }
  // Separated only along a diagonal direction, which is an edge normal of the triangle.
  Poly tri = {{0.6, 1.5}, {1.5, 0.6}, {2, 2}};
  Poly tri2 = {{0.5, 1.4}, {1.4, 0.5}, {2, 2}};
  EXPECT_FALSE(convexOverlap(a.data(), 4, tri.data(), 3));
  EXPECT_TRUE(convexOverlap(a.data(), 4, tri2.data(), 3));
  Poly small = rect(0.2, 0.2, 0.3, 0.3);
  EXPECT_TRUE(convexOverlap(a.data(), 4, small.data(), 4));
}

TEST(Geometry, ClipSquaresTagsCrossings) {
  Poly a = rect(0, 0, 1, 1), b = rect(0.5, 0.5, 1.5, 1.5);
  ClipVertex v[kMaxClipVertices];
  int k = clipConvex(a.data(), 4, b.data(), 4, v);
  ASSERT_EQ(k, 4);
  EXPECT_NEAR(clippedArea(v, k), 0.25, kTol);
  int crossings = 0;
  for (int i = 0; i < k; ++i) {
    if (v[i].inEdge != v[i].outEdge) {
      ++crossings;
      bool known = (std::fabs(v[i].p.x - 1) < kTol && std::fabs(v[i].p.y - 0.5) < kTol) ||
                   (std::fabs(v[i].p.x - 0.5) < kTol && std::fabs(v[i].p.y - 1) < kTol);
      EXPECT_TRUE(known) << v[i].p.x << " " << v[i].p.y;
    } else if (v[i].inEdge == 0) {
      expectVec(v[i].p, {1, 1});  // P's corner inside Q
    } else {
      expectVec(v[i].p, {0.5, 0.5});  // Q's corner inside P
    }
  }
  EXPECT_EQ(crossings, 2);
  Poly far = rect(3, 3, 4, 4);
  EXPECT_EQ(clipConvex(a.data(), 4, far.data(), 4, v), 0);
  Poly edge = rect(1, 0, 2, 1);
  EXPECT_EQ(clipConvex(a.data(), 4, edge.data(), 4, v), 0);
}

// ---- contact (docs/model.md 3) ----

TEST(Geometry, SquareHitsSquare) {
  Poly a = rect(0, 0, 1, 1), b = rect(0.5, 0.5, 1.5, 1.5);
  Contact c = contactOf(a, b);
  ASSERT_TRUE(c.touching);
  EXPECT_FALSE(c.contained);
  EXPECT_NEAR(c.area, 0.25, kTol);
  expectVec(c.cross0, {1, 0.5});
  expectVec(c.cross1, {0.5, 1});
  expectVec(c.point, {0.75, 0.75});
  Real h = std::sqrt(Real(0.5));
  expectVec(c.normal, {h, h});
  EXPECT_NEAR(c.width, h, kTol);
  EXPECT_EQ(c.apexVertexQ, 0);  // (0.5, 0.5)
  EXPECT_EQ(c.apexVertexP, 2);  // (1, 1)

  Contact r = contactOf(b, a);  // the same line, the normal now from b into a
  ASSERT_TRUE(r.touching);
  EXPECT_NEAR(r.area, 0.25, kTol);
  expectVec(r.point, {0.75, 0.75});
  expectVec(r.normal, {-h, -h});
  EXPECT_NEAR(r.width, h, kTol);
  EXPECT_EQ(r.apexVertexQ, 2);
  EXPECT_EQ(r.apexVertexP, 0);
}

TEST(Geometry, SquareHitsSquareFarFromOriginRotated) {
  // The same contact, rotated and 5 km from the origin: rounding must stay at the metre-scale ulp.
  Vec2 off{5000, -3000};
  Real ang = 0.7;
  Poly a = moved(rect(0, 0, 1, 1), off, ang), b = moved(rect(0.5, 0.5, 1.5, 1.5), off, ang);
  Contact c = contactOf(a, b);
  ASSERT_TRUE(c.touching);
  double tol = sizeof(Real) >= 8 ? 1e-9 : 2e-2;
  EXPECT_NEAR(c.area, 0.25, tol);
  expectVec(c.point, off + rotate(Vec2{0.75, 0.75}, ang), tol);
  Real h = std::sqrt(Real(0.5));
  expectVec(c.normal, rotate(Vec2{h, h}, ang), tol);
  EXPECT_NEAR(c.width, h, tol);
}

TEST(Geometry, SideBySideSquaresCollinearEdges) {
  // Edges of P and Q lie along the same lines: the crossings are where Q's edge meets P's.
  Poly a = rect(0, 0, 1, 1), b = rect(0.5, 0, 1.5, 1);
  Contact c = contactOf(a, b);
  ASSERT_TRUE(c.touching);
  EXPECT_FALSE(c.contained);
  EXPECT_NEAR(c.area, 0.5, kTol);
  expectVec(c.normal, {1, 0});
  EXPECT_NEAR(c.width, 1.0, kTol);
  expectVec(c.cross0, {0.5, 0});
  expectVec(c.cross1, {0.5, 1});
  Contact r = contactOf(b, a);
  expectVec(r.normal, {-1, 0});
  EXPECT_NEAR(r.width, 1.0, kTol);
}

TEST(Geometry, TouchingWithoutAreaIsNoContact) {
  Poly a = rect(0, 0, 1, 1);
  Poly edge = rect(1, 0, 2, 1), corner = rect(1, 1, 2, 2), partial = rect(1, 0.5, 2, 1.5);
  for (const Poly* q : {&edge, &corner, &partial}) {
    Contact c = contactOf(a, *q);
    EXPECT_FALSE(c.touching);
    EXPECT_EQ(c.area, 0);
    EXPECT_EQ(c.width, 0);
    EXPECT_EQ(c.apexVertexP, -1);
    EXPECT_EQ(c.apexVertexQ, -1);
    EXPECT_FALSE(contactOf(*q, a).touching);
  }
  // Sharing an edge after a rotation and far from the origin: rounding must not make a contact.
  Vec2 off{2345.6, 789.1};
  for (Real ang : {Real(0.3), Real(1.0), Real(2.5)}) {
    Poly p = moved(rect(0, 0, 1, 1), off, ang), q = moved(rect(1, 0, 2, 1), off, ang);
    EXPECT_FALSE(contactOf(p, q).touching) << ang;
    EXPECT_FALSE(contactOf(q, p).touching) << ang;
  }
}

TEST(Geometry, ContainedSquare) {
  Poly big = rect(0, 0, 10, 10), small = rect(2, 4, 3, 5);
  Contact c = contactOf(big, small);
  ASSERT_TRUE(c.touching);
  EXPECT_TRUE(c.contained);
  EXPECT_NEAR(c.area, 1.0, kTol);
  Vec2 n = normalized(Vec2{2.5, 4.5} - Vec2{5, 5});
  expectVec(c.normal, n);
  expectVec(c.point, {2.5, 4.5});
  // Width of the unit square across n: its extent along the line direction t = perpLeft(n).
  Vec2 t = perpLeft(n);
  EXPECT_NEAR(c.width, std::fabs(t.x) + std::fabs(t.y), kTol);
  expectVec(c.cross0, c.point - 0.5 * c.width * t);
  expectVec(c.cross1, c.point + 0.5 * c.width * t);
  EXPECT_GE(c.apexVertexQ, 0);
  EXPECT_EQ(c.apexVertexP, -1);

  Contact r = contactOf(small, big);
  EXPECT_TRUE(r.contained);
  expectVec(r.normal, -n);
  EXPECT_NEAR(r.width, c.width, kTol);
  EXPECT_EQ(r.apexVertexQ, -1);
  EXPECT_GE(r.apexVertexP, 0);

  // Coinciding centroids: n = +x, w = the overlap's extent along y.
  Poly mid = rect(4, 3, 6, 7);
  Contact m = contactOf(big, mid);
  EXPECT_TRUE(m.contained);
  expectVec(m.normal, {1, 0});
  EXPECT_NEAR(m.width, 4.0, kTol);
  expectVec(m.point, {5, 5});
  // Identical polygons: every edge shared, no crossing.
  Contact same = contactOf(big, big);
  EXPECT_TRUE(same.touching);
  EXPECT_TRUE(same.contained);
  EXPECT_NEAR(same.area, 100.0, 1e3 * kTol);
}

TEST(Geometry, StarOfDavidFarthestCrossings) {
  Poly up = regular(3, 1, kPi / 2), down = regular(3, 1, -kPi / 2);
  ClipVertex v[kMaxClipVertices];
  int k = clipConvex(up.data(), 3, down.data(), 3, v);
  ASSERT_EQ(k, 6);
  int crossings = 0;
  for (int i = 0; i < k; ++i) crossings += v[i].inEdge != v[i].outEdge;
  EXPECT_EQ(crossings, 6);
  Contact c = contactOf(up, down);
  ASSERT_TRUE(c.touching);
  EXPECT_FALSE(c.contained);
  // The hexagon's vertices lie at radius 1/sqrt(3): the farthest pair is an opposite pair.
  EXPECT_NEAR(c.width, 2 / std::sqrt(Real(3)), 10 * kTol);
  expectVec(c.point, {0, 0}, 10 * kTol);
  EXPECT_NEAR(norm(c.cross0), 1 / std::sqrt(Real(3)), 10 * kTol);
  EXPECT_NEAR(c.area, 6 * std::sqrt(Real(3)) / 4 / 3, 10 * kTol);  // hexagon of side 1/sqrt(3)
  EXPECT_NEAR(norm(c.normal), 1.0, kTol);
  EXPECT_NEAR(dot(c.normal, c.cross1 - c.cross0), 0.0, 10 * kTol);
}

TEST(Geometry, NormalPointsFromPIntoQ) {
  // A triangle poking into a box from the left, with its centroid already past the box's: the
  // normal follows the geometry (+x), not the centroids.
  Poly box = rect(0, 0, 10, 10);
  Poly wedge = {{-1, 5}, {9, 0.5}, {9, 9.5}};
  Contact c = contactOf(wedge, box);
  ASSERT_TRUE(c.touching);
  EXPECT_FALSE(c.contained);
  expectVec(c.normal, {1, 0});
  EXPECT_NEAR(c.point.x, 0.0, kTol);
  EXPECT_NEAR(c.point.y, 5.0, kTol);
  Contact r = contactOf(box, wedge);
  expectVec(r.normal, {-1, 0});
}

// ---- ear clipping and triangle overlap (docs/model.md 9) ----

namespace {

Real trianglesArea(const Poly& p, int (*tri)[3], int nt, bool* allCcw) {
  Real sum = 0;
  *allCcw = true;
  for (int t = 0; t < nt; ++t) {
    Vec2 a = p[tri[t][0]], b = p[tri[t][1]], c = p[tri[t][2]];
    Real ar = Real(0.5) * cross(b - a, c - a);
    if (!(ar > 0)) *allCcw = false;
    sum += ar;
  }
  return sum;
}

}  // namespace

TEST(Geometry, EarClipConvexHexagon) {
  Poly h = regular(6, 2, 0.1, {3, 4});
  int tri[kMaxVertices - 2][3];
  int nt = earClip(h.data(), 6, tri);
  ASSERT_EQ(nt, 4);
  bool ccw;
  EXPECT_NEAR(trianglesArea(h, tri, nt, &ccw), signedArea(h.data(), 6), 100 * kTol);
  EXPECT_TRUE(ccw);
}

TEST(Geometry, EarClipNonConvexL) {
  Poly ell = {{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  int tri[kMaxVertices - 2][3];
  int nt = earClip(ell.data(), 6, tri);
  ASSERT_EQ(nt, 4);
  bool ccw;
  EXPECT_NEAR(trianglesArea(ell, tri, nt, &ccw), 3.0, kTol);
  EXPECT_TRUE(ccw);
  // No triangle may cover the notch (1, 1)-(2, 2).
  for (int t = 0; t < nt; ++t) {
    Vec2 c = (1.0 / 3) * (ell[tri[t][0]] + ell[tri[t][1]] + ell[tri[t][2]]);
    EXPECT_FALSE(c.x > 1 && c.y > 1) << t;
  }
  // A comb with three teeth.
  Poly comb = {{0, 0}, {5, 0}, {5, 2}, {4, 2}, {4, 1}, {3, 1}, {3, 2}, {2, 2}, {2, 1}, {1, 1}, {1, 2}, {0, 2}};
  nt = earClip(comb.data(), int(comb.size()), tri);
  ASSERT_EQ(nt, 10);
  EXPECT_NEAR(trianglesArea(comb, tri, nt, &ccw), signedArea(comb.data(), int(comb.size())), kTol);
  EXPECT_TRUE(ccw);
}

TEST(Geometry, TrianglesOverlap) {
  Vec2 a[3] = {{0, 0}, {1, 0}, {0, 1}};
  Vec2 b[3] = {{0.2, 0.2}, {1.2, 0.2}, {0.2, 1.2}};
  EXPECT_TRUE(trianglesOverlap(a, b, 0));
  Vec2 far[3] = {{2, 2}, {3, 2}, {2, 3}};
  EXPECT_FALSE(trianglesOverlap(a, far, 0));
  EXPECT_FALSE(trianglesOverlap(far, a, 0));
  // Separated along the hypotenuse normal only: gap 0.1 * sqrt(2) / 2 ~ 0.0707.
  Vec2 diag[3] = {{0.6, 0.5}, {1.5, 0.5}, {0.6, 1.4}};
  EXPECT_FALSE(trianglesOverlap(a, diag, 0));
  EXPECT_FALSE(trianglesOverlap(a, diag, 0.07));
  EXPECT_TRUE(trianglesOverlap(a, diag, 0.072));
  EXPECT_TRUE(trianglesOverlap(diag, a, 0.072));
  // Touching along an edge or at a vertex counts (conservative).
  Vec2 edge[3] = {{1, 0}, {1, 1}, {0, 1}};
  EXPECT_TRUE(trianglesOverlap(a, edge, 0));
  Vec2 vertex[3] = {{1, 0}, {2, 0}, {2, 1}};
  EXPECT_TRUE(trianglesOverlap(a, vertex, 0));
  // One inside the other.
  Vec2 tiny[3] = {{0.1, 0.1}, {0.2, 0.1}, {0.1, 0.2}};
  EXPECT_TRUE(trianglesOverlap(a, tiny, 0));
  EXPECT_TRUE(trianglesOverlap(tiny, a, 0));
}

// ---- splitting (docs/model.md 6) ----

TEST(Geometry, SplitSquare) {
  Poly s = rect(0, 0, 1, 1);
  Vec2 l[kMaxClipVertices], r[kMaxClipVertices];
  int nl, nr;
  splitByLine(s.data(), 4, {0.3, 0.5}, {0, 1}, l, &nl, r, &nr);  // left of +y is x < 0.3
  ASSERT_EQ(nl, 4);
  ASSERT_EQ(nr, 4);
  EXPECT_NEAR(signedArea(l, nl), 0.3, kTol);
  EXPECT_NEAR(signedArea(r, nr), 0.7, kTol);
  EXPECT_TRUE(isStrictlyConvexCCW(l, nl));
  EXPECT_TRUE(isStrictlyConvexCCW(r, nr));
  EXPECT_LT(areaCentroid(l, nl).x, 0.3);

  // Through two opposite corners: two triangles.
  splitByLine(s.data(), 4, {0, 0}, {1, 1}, l, &nl, r, &nr);
  ASSERT_EQ(nl, 3);
  ASSERT_EQ(nr, 3);
  EXPECT_NEAR(signedArea(l, nl), 0.5, kTol);
  EXPECT_NEAR(signedArea(r, nr), 0.5, kTol);
  EXPECT_TRUE(isStrictlyConvexCCW(l, nl));
  EXPECT_TRUE(isStrictlyConvexCCW(r, nr));

  // A slanted cut through two edges.
  splitByLine(s.data(), 4, {0.5, 0.5}, {1, 0.3}, l, &nl, r, &nr);
  EXPECT_NEAR(signedArea(l, nl) + signedArea(r, nr), 1.0, kTol);
  EXPECT_TRUE(isStrictlyConvexCCW(l, nl));
  EXPECT_TRUE(isStrictlyConvexCCW(r, nr));
}

TEST(Geometry, SplitLineMisses) {
  Poly s = rect(0, 0, 1, 1);
  Vec2 l[kMaxClipVertices], r[kMaxClipVertices];
  int nl, nr;
  splitByLine(s.data(), 4, {2, 0}, {0, 1}, l, &nl, r, &nr);
  EXPECT_EQ(nl, 4);
  EXPECT_EQ(nr, 0);
  EXPECT_NEAR(signedArea(l, nl), 1.0, kTol);
  // Along an edge, or touching a corner only: no second piece.
  splitByLine(s.data(), 4, {1, 0}, {0, 1}, l, &nl, r, &nr);
  EXPECT_EQ(nl, 4);
  EXPECT_EQ(nr, 0);
  splitByLine(s.data(), 4, {1, 0}, {1, 1}, l, &nl, r, &nr);
  EXPECT_EQ(nl, 4);
  EXPECT_EQ(nr, 0);
  splitByLine(s.data(), 4, {0, -1}, {-1, 0}, l, &nl, r, &nr);
  EXPECT_EQ(nl, 0);
  EXPECT_EQ(nr, 4);
}

// ---- the CPU narrowphase's rejection by one cached edge ----

namespace {

// A random convex counter-clockwise polygon: 3 to 12 points at sorted angles on a circle.
Poly randomConvex(std::mt19937& rng, Vec2 centre, Real radius) {
  std::uniform_real_distribution<Real> unit(0, 1);
  const int n = 3 + static_cast<int>(unit(rng) * 10);
  std::vector<Real> angles(n);
  for (Real& a : angles) a = unit(rng) * 2 * kPi;
  std::sort(angles.begin(), angles.end());
  Poly p;
  for (Real a : angles) p.push_back(centre + radius * Vec2{std::cos(a), std::sin(a)});
  return p;
}

// q: p mirrored across one of its edges, picked at random, so that the two share that edge; then
// moved off it along its normal by up to nudge / 2 either way (touching, a sliver, or a hair apart).
Poly mirroredAcrossAnEdge(std::mt19937& rng, const Poly& p, Real nudge) {
  std::uniform_real_distribution<Real> unit(0, 1);
  const size_t i = static_cast<size_t>(unit(rng) * static_cast<Real>(p.size())) % p.size();
  const Vec2 a = p[i], e = p[(i + 1) % p.size()] - a, t = (Real(1) / norm(e)) * e;
  Poly q;
  for (auto it = p.rbegin(); it != p.rend(); ++it) q.push_back(a + 2 * dot(*it - a, t) * t - (*it - a));
  const Real by = (unit(rng) - 0.5) * nudge;
  for (Vec2& v : q) v = v + by * Vec2{t.y, -t.x};
  return q;
}

}  // namespace

// Whatever edge is tried (the cache may hold a stale or wrong one), an edge that separates means
// computeContact says "not touching", and the full search finds an edge exactly when
// convexOverlap finds none. Pairs apart, overlapping, and sharing an edge to within rounding, near
// the origin and a kilometre away.
TEST(Geometry, CachedSeparatingEdgeNeverRejectsATouchingPair) {
  std::mt19937 rng(20261201);
  std::uniform_real_distribution<Real> unit(0, 1);
  int rejected = 0, touching = 0, sharedEdges = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec2 origin = trial % 2 ? Vec2{1000 * unit(rng), -700 * unit(rng)} : Vec2{0, 0};
    const Real r = 0.5 + 5 * unit(rng);
    Poly p = randomConvex(rng, origin, r), q;
    if (trial % 4 == 3) {
      // q shares an edge with p, nudged by a few ulps to a few nanometres.
      q = mirroredAcrossAnEdge(rng, p, trial % 8 == 3 ? 1e-8 : 1e-13);
      ++sharedEdges;
    } else {
      q = randomConvex(rng, origin + 2.5 * r * Vec2{unit(rng) - 0.5, unit(rng) - 0.5}, 0.5 + 5 * unit(rng));
    }
    const int n = static_cast<int>(p.size()), m = static_cast<int>(q.size());
    const bool overlap = convexOverlap(p.data(), n, q.data(), m);
    const SeparatingEdge found = findSeparatingEdge(p.data(), n, q.data(), m);
    ASSERT_EQ(found.side < 0, overlap) << "trial " << trial;
    if (!overlap) {
      ASSERT_TRUE(separatesAlong(found, p.data(), n, q.data(), m)) << "trial " << trial;
    }
    const Contact contact = contactOf(p, q);
    touching += contact.touching;
    for (int side = 0; side < 2; ++side)
      for (int edge = -1; edge <= (side ? m : n); ++edge) {  // out-of-range indices included
        if (!separatesAlong(SeparatingEdge{side, edge}, p.data(), n, q.data(), m)) continue;
        ++rejected;
        ASSERT_FALSE(overlap) << "trial " << trial << " side " << side << " edge " << edge;
        ASSERT_FALSE(contact.touching) << "trial " << trial << " side " << side << " edge " << edge;
      }
  }
  // The cases are mixed: plenty of each kind.
  EXPECT_GT(touching, 3000);
  EXPECT_GT(rejected, 3000);
  EXPECT_GT(sharedEdges, 3000);
}

// The separating-axis test's search for a witness vertex starts where the last edge's search
// stopped (sat.hpp). It must give the answer of the plain search, every edge scanned from vertex
// 0: the same separating edge first, and "no edge" exactly when the plain search finds none.
// Written out here from docs/model.md 3, not from sat.hpp.
namespace {
bool plainEdgeSeparates(const Poly& p, int i, const Poly& q) {
  const Vec2 a = p[static_cast<size_t>(i)], e = p[(static_cast<size_t>(i) + 1) % p.size()] - a;
  const Vec2 outward{e.y, -e.x};
  const Real le = l1Norm(e), tol = kGeomRelTol * le * (le + l1Norm(a));
  for (const Vec2& v : q)
    if (dot(outward, v - a) < -tol) return false;
  return true;
}
SeparatingEdge plainFirstSeparatingEdge(const Poly& p, const Poly& q) {
  for (int i = 0; i < static_cast<int>(p.size()); ++i)
    if (plainEdgeSeparates(p, i, q)) return {0, i};
  for (int i = 0; i < static_cast<int>(q.size()); ++i)
    if (plainEdgeSeparates(q, i, p)) return {1, i};
  return {-1, 0};
}
}  // namespace

TEST(Geometry, WitnessSearchGivesThePlainSearchsAnswer) {
  std::mt19937 rng(20261202);
  std::uniform_real_distribution<Real> unit(0, 1);
  int overlapping = 0, apart = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec2 origin = trial % 2 ? Vec2{1000 * unit(rng), -700 * unit(rng)} : Vec2{0, 0};
    const Real r = 0.5 + 5 * unit(rng);
    const Poly p = randomConvex(rng, origin, r);
    // From deep overlap to well apart, and sharing an edge to within a few nanometres.
    Poly q;
    if (trial % 4 == 3) {
      q = mirroredAcrossAnEdge(rng, p, 1e-8);
    } else {
      q = randomConvex(rng, origin + 3 * r * unit(rng) * Vec2{unit(rng) - 0.5, unit(rng) - 0.5}, 0.5 + 5 * unit(rng));
    }
    const int n = static_cast<int>(p.size()), m = static_cast<int>(q.size());
    const SeparatingEdge plain = plainFirstSeparatingEdge(p, q);
    const SeparatingEdge found = findSeparatingEdge(p.data(), n, q.data(), m);
    ASSERT_EQ(found.side, plain.side) << "trial " << trial;
    if (plain.side >= 0) {
      ASSERT_EQ(found.edge, plain.edge) << "trial " << trial;
    }
    ASSERT_EQ(convexOverlap(p.data(), n, q.data(), m), plain.side < 0) << "trial " << trial;
    ASSERT_EQ(convexOverlap(q.data(), m, p.data(), n), plain.side < 0) << "trial " << trial;
    for (int i = 0; i < n; ++i) ASSERT_EQ(edgeSeparatesAt(p.data(), n, i, q.data(), m), plainEdgeSeparates(p, i, q)) << "trial " << trial;
    (plain.side < 0 ? overlapping : apart) += 1;
  }
  EXPECT_GT(overlapping, 4000);
  EXPECT_GT(apart, 4000);
}

// The CPU narrowphase gives clipConvex its merge tolerance from the bodies' bounding boxes
// (boundingBox) rather than letting it scan the vertices again: the overlap must be the same, bit
// for bit, vertex by vertex and tag by tag. Polygons near the origin, a kilometre away, and with a
// vertex on an axis (a zero coordinate, where the two scans may keep zeros of different signs).
TEST(Geometry, ClipToleranceFromTheBoxesGivesTheSameOverlap) {
  std::mt19937 rng(20261206);
  std::uniform_real_distribution<Real> unit(0, 1);
  int clipped = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec2 origin = trial % 3 == 1 ? Vec2{1000 * unit(rng), -700 * unit(rng)} : Vec2{0, 0};
    const Real r = 0.5 + 5 * unit(rng);
    Poly p = randomConvex(rng, origin, r);
    if (trial % 3 == 2) {  // a rectangle whose left side lies on x = 0, its ends at -0 and +0
      const Real w = r * (0.5 + unit(rng)), h = r * (0.5 + unit(rng));
      p = {{-Real(0), -Real(0)}, {w, Real(0)}, {w, h}, {Real(0), h}};
    }
    const Poly q = randomConvex(rng, origin + 2 * r * Vec2{unit(rng) - 0.5, unit(rng) - 0.5}, 0.5 + 5 * unit(rng));
    const int n = static_cast<int>(p.size()), m = static_cast<int>(q.size());
    const Box boxP = boundingBox(p.data(), n), boxQ = boundingBox(q.data(), m);
    const Real tol =
        clipToleranceOf(clipScaleOfBox(boxP.x0, boxP.y0, boxP.x1, boxP.y1), clipScaleOfBox(boxQ.x0, boxQ.y0, boxQ.x1, boxQ.y1));
    ASSERT_EQ(std::bit_cast<std::uint64_t>(static_cast<double>(tol)),
              std::bit_cast<std::uint64_t>(static_cast<double>(detail::clipTolerance(p.data(), n, q.data(), m))))
        << "trial " << trial;
    ClipVertex plain[kMaxClipVertices], fromBoxes[kMaxClipVertices];
    const int k = clipConvex(p.data(), n, q.data(), m, plain);
    ASSERT_EQ(clipConvex(p.data(), n, q.data(), m, fromBoxes, tol), k) << "trial " << trial;
    for (int i = 0; i < k; ++i) {
      ASSERT_EQ(std::bit_cast<std::uint64_t>(static_cast<double>(fromBoxes[i].p.x)),
                std::bit_cast<std::uint64_t>(static_cast<double>(plain[i].p.x)));
      ASSERT_EQ(std::bit_cast<std::uint64_t>(static_cast<double>(fromBoxes[i].p.y)),
                std::bit_cast<std::uint64_t>(static_cast<double>(plain[i].p.y)));
      ASSERT_EQ(fromBoxes[i].inEdge, plain[i].inEdge);
      ASSERT_EQ(fromBoxes[i].outEdge, plain[i].outEdge);
    }
    clipped += k >= 3;
  }
  EXPECT_GT(clipped, 4000);  // plenty of real overlaps among the pairs
}

// geometry/packed_host.hpp's packed forms against the scalar ones, bit for bit: world vertices and
// their box for random shapes, poses far from the origin, zero and negative-zero coordinates and
// angles from 0 to many turns; boxes that overlap, touch along an edge or a corner (where > and >=
// differ), are apart, or hold a NaN or an infinite bound.
TEST(Geometry, PackedFormsGiveTheScalarFormsBits) {
  std::mt19937 rng(20261208);
  std::uniform_real_distribution<Real> unit(0, 1);
  auto bits = [](Real v) { return std::bit_cast<std::uint64_t>(static_cast<double>(v)); };
  for (int trial = 0; trial < 20000; ++trial) {
    Poly local = randomConvex(rng, Vec2{0, 0}, 0.2 + 20 * unit(rng));
    if (trial % 7 == 0) local[0] = Vec2{-Real(0), Real(0)};
    Vec2 position = trial % 3 == 0 ? Vec2{-Real(0), Real(0)} : Vec2{5000 * (unit(rng) - 0.5), 5000 * (unit(rng) - 0.5)};
    Real angle = trial % 5 == 0 ? Real(0) : trial % 5 == 1 ? -Real(0) : 40 * (unit(rng) - 0.5);
    if (trial % 11 == 0) {  // world vertices at -0 and +0 in one shape: the box keeps the zero the scalar test keeps
      position = Vec2{-Real(0), -Real(0)}, angle = 0;
      local = trial % 2 ? Poly{{-Real(0), 1}, {Real(0), 2}, {-1, Real(0)}, {-Real(0), -Real(0)}}  // the largest x a zero
                        : Poly{{Real(0), 1}, {-Real(0), 2}, {1, -Real(0)}, {Real(0), Real(0)}};   // the smallest x a zero
    }
    const int n = static_cast<int>(local.size());
    Vec2 scalar[kMaxVertices]{}, packed[kMaxVertices]{};
    toWorld(local.data(), n, position, angle, scalar);
    const Box expected = boundingBox(scalar, n);
    const Box box = toWorldWithBox(local.data(), n, position, angle, packed);
    for (int i = 0; i < n; ++i) {
      ASSERT_EQ(bits(packed[i].x), bits(scalar[i].x)) << "trial " << trial << " vertex " << i;
      ASSERT_EQ(bits(packed[i].y), bits(scalar[i].y)) << "trial " << trial << " vertex " << i;
    }
    ASSERT_EQ(bits(box.x0), bits(expected.x0)) << "trial " << trial;
    ASSERT_EQ(bits(box.y0), bits(expected.y0)) << "trial " << trial;
    ASSERT_EQ(bits(box.x1), bits(expected.x1)) << "trial " << trial;
    ASSERT_EQ(bits(box.y1), bits(expected.y1)) << "trial " << trial;
  }
  // Bounds drawn from a few values, so that equal bounds (boxes touching) and zeros of both signs
  // come up often.
  const Real values[] = {-2, -1, -Real(0), Real(0), 1, 2, 0.5, std::nan(""), INFINITY, -INFINITY};
  std::uniform_int_distribution<int> pick(0, static_cast<int>(std::size(values)) - 1);
  int meeting = 0, apart = 0;
  for (int trial = 0; trial < 200000; ++trial) {
    const Box a{values[pick(rng)], values[pick(rng)], values[pick(rng)], values[pick(rng)]};
    const Box b{values[pick(rng)], values[pick(rng)], values[pick(rng)], values[pick(rng)]};
    const bool expected = boxesOverlap(a, b);
    ASSERT_EQ(boxesMeet(a, b), expected) << "trial " << trial;
    (expected ? meeting : apart) += 1;
  }
  EXPECT_GT(meeting, 20000);
  EXPECT_GT(apart, 20000);
}
