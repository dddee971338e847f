// Over 500 lines on purpose: one file, so that CGAL (slow to compile) is compiled once, in one binary.
// Property tests of the geometry headers against CGAL's exact kernel (docs/architecture.md "Tests"): random
// convex polygons (random points -> convex hull, 3 to 19 vertices, 0.5 to 20 m), the second placed
// near the first so that most pairs overlap. Every check runs in both argument orders. The inputs
// are the same Real values on both sides, so every difference is our rounding or our bug.
#include <gtest/gtest.h>

#include <CGAL/Boolean_set_operations_2.h>
#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Gmpq.h>
#include <CGAL/Polygon_2.h>
#include <CGAL/Polygon_with_holes_2.h>
#include <CGAL/convex_hull_2.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <vector>

#include "geometry/clip.hpp"
#include "geometry/contact.hpp"
#include "geometry/polygon.hpp"
#include "geometry/sat.hpp"
#include "geometry/split.hpp"
#include "geometry/triangulate.hpp"

using namespace gem;

namespace {

using K = CGAL::Exact_predicates_exact_constructions_kernel;
using Ki = CGAL::Exact_predicates_inexact_constructions_kernel;
using FT = K::FT;
using Point = K::Point_2;
using Polygon = CGAL::Polygon_2<K>;
using PolygonWithHoles = CGAL::Polygon_with_holes_2<K>;
using Poly = std::vector<Vec2>;

// Tolerances for the engine's Real: kRel relative to the polygons' size, kMag relative to the
// coordinate magnitude (world coordinates far from the origin round at that scale), kUnit for
// identities between unit vectors computed from the same numbers.
constexpr bool kDouble = sizeof(Real) >= 8;
constexpr double kRel = kDouble ? 1e-9 : 1e-4;
constexpr double kMag = kDouble ? 1e-12 : 1e-5;
constexpr double kUnit = kDouble ? 1e-12 : 1e-5;

struct Rng {
  std::mt19937_64 gen;
  explicit Rng(unsigned long long seed) : gen(seed) {}
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(gen); }
  int integer(int a, int b) { return std::uniform_int_distribution<int>(a, b)(gen); }
};

// The nearest double of an exact number. CGAL::to_double of a lazy number only promises 1e-5
// relative precision (the interval's midpoint); force the exact value first.
double toDouble(const FT& x) { return CGAL::to_double(CGAL::exact(x)); }

Point toPoint(Vec2 v) { return Point(double(v.x), double(v.y)); }
Polygon toPolygon(const Poly& p) {
  Polygon out;
  for (Vec2 v : p) out.push_back(toPoint(v));
  return out;
}
double exactArea(const Vec2* v, int k) {
  Polygon out;
  for (int i = 0; i < k; ++i) out.push_back(toPoint(v[i]));
  return toDouble(out.area());
}
Vec2 toVec(const Point& p) { return {Real(toDouble(p.x())), Real(toDouble(p.y()))}; }

// Random convex polygon, 3..19 vertices: points at random angles in an annulus of a random
// ellipse, rounded to Real, then their exact convex hull. Radius = scale.
Poly randomConvex(Rng& rng, Vec2 centre, double scale) {
  for (;;) {
    int k = rng.integer(3, 24);
    double aspect = rng.uniform(0.25, 1), rot = rng.uniform(0, 2 * kPi), inner = rng.uniform(0.5, 1);
    std::vector<Ki::Point_2> pts, hull;
    for (int i = 0; i < k; ++i) {
      double a = rng.uniform(0, 2 * kPi), r = scale * rng.uniform(inner, 1);
      Vec2 v = centre + rotate(Vec2{Real(r * std::cos(a)), Real(aspect * r * std::sin(a))}, Real(rot));
      pts.emplace_back(double(Real(v.x)), double(Real(v.y)));
    }
    CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));  // CCW, no collinear points
    if (hull.size() < 3 || hull.size() > 19) continue;
    Poly p;
    for (auto& h : hull) p.push_back({Real(h.x()), Real(h.y())});
    if (isStrictlyConvexCCW(p.data(), int(p.size())) && signedArea(p.data(), int(p.size())) > 1e-3 * scale * scale) return p;
  }
}

double extentOf(const Poly& p) {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (Vec2 v : p) {
    x0 = std::min(x0, double(v.x)), x1 = std::max(x1, double(v.x));
    y0 = std::min(y0, double(v.y)), y1 = std::max(y1, double(v.y));
  }
  return std::max(x1 - x0, y1 - y0);
}
double magnitudeOf(const Poly& p) {
  double m = 0;
  for (Vec2 v : p) m = std::max({m, std::fabs(double(v.x)), std::fabs(double(v.y))});
  return m;
}

double segmentDistance(Vec2 x, Vec2 a, Vec2 b) {
  Vec2 ab = b - a;
  double t = std::clamp(double(dot(x - a, ab)) / std::max(double(norm2(ab)), 1e-300), 0.0, 1.0);
  return norm(x - (a + Real(t) * ab));
}
double boundaryDistance(Vec2 x, const Poly& p) {
  double d = 1e300;
  for (size_t i = 0; i < p.size(); ++i) d = std::min(d, segmentDistance(x, p[i], p[(i + 1) % p.size()]));
  return d;
}

// Removes near-duplicate and near-collinear vertices (both within tol) so that our polygon and the
// exact one can be compared vertex for vertex.
Poly simplified(Poly p, double tol) {
  bool changed = true;
  while (changed && p.size() > 3) {
    changed = false;
    for (size_t i = 0; i < p.size() && p.size() > 3; ++i) {
      Vec2 a = p[(i + p.size() - 1) % p.size()], b = p[i], c = p[(i + 1) % p.size()];
      if (segmentDistance(b, a, c) <= tol) {
        p.erase(p.begin() + long(i));
        changed = true;
      }
    }
  }
  return p;
}

// Exact area, centroid and second moments about the exact centroid (docs/model.md 1, A.1 to A.8), in
// plain GMP rationals (the lazy kernel number would build a long expression DAG here).
struct ExactMass {
  CGAL::Gmpq area, cx, cy, jxx, jyy, jxy;
};
ExactMass exactMass(const Poly& p) {
  using Q = CGAL::Gmpq;
  ExactMass m{0, 0, 0, 0, 0, 0};
  size_t n = p.size();
  std::vector<Q> x, y;
  for (Vec2 v : p) x.emplace_back(double(v.x)), y.emplace_back(double(v.y));
  for (size_t i = 0; i < n; ++i) {
    size_t j = (i + 1) % n;
    Q ai = x[i] * y[j] - x[j] * y[i];
    m.area += ai;
    m.cx += (x[i] + x[j]) * ai;
    m.cy += (y[i] + y[j]) * ai;
  }
  m.cx /= 3 * m.area;
  m.cy /= 3 * m.area;
  for (size_t i = 0; i < n; ++i) {
    size_t j = (i + 1) % n;
    Q ax = x[i] - m.cx, ay = y[i] - m.cy, bx = x[j] - m.cx, by = y[j] - m.cy;
    Q ai = ax * by - bx * ay;
    m.jxx += (ay * ay + ay * by + by * by) * ai;
    m.jyy += (ax * ax + ax * bx + bx * bx) * ai;
    m.jxy += (ax * by + 2 * ax * ay + 2 * bx * by + bx * ay) * ai;
  }
  m.area /= 2;
  m.jxx /= 12;
  m.jyy /= 12;
  m.jxy /= 24;
  return m;
}

// A random pair: the second polygon near the first (touching distance scaled by u in 0..1.15),
// sometimes small and inside it, sometimes identical or sharing the centroid; some pairs far from
// the origin to exercise world-coordinate rounding.
struct Pair {
  Poly p, q;
};
Pair randomPair(Rng& rng) {
  Vec2 origin{0, 0};
  if (rng.integer(0, 3) == 0) origin = {Real(rng.uniform(-2000, 2000)), Real(rng.uniform(-2000, 2000))};
  double sp = rng.uniform(0.5, 20), sq = rng.uniform(0.5, 20);
  Pair pr;
  pr.p = randomConvex(rng, origin, sp);
  int kind = rng.integer(0, 19);
  if (kind == 0) {
    pr.q = pr.p;  // identical
  } else if (kind == 1) {
    pr.q = randomConvex(rng, areaCentroid(pr.p.data(), int(pr.p.size())), rng.uniform(0.5, 20));  // ~shared centroid
  } else if (kind <= 3) {
    pr.q = randomConvex(rng, origin + Vec2{Real(rng.uniform(-0.2, 0.2) * sp), Real(rng.uniform(-0.2, 0.2) * sp)},
                        sp * rng.uniform(0.05, 0.3));  // small, likely inside
  } else {
    double a = rng.uniform(0, 2 * kPi), d = (sp + sq) * rng.uniform(0, 1.15);
    pr.q = randomConvex(rng, origin + Vec2{Real(d * std::cos(a)), Real(d * std::sin(a))}, sq);
  }
  return pr;
}

// Exact points where the boundaries of p and q properly cross: edges whose endpoints lie strictly
// on opposite sides of each other (exact predicates), intersected in exact arithmetic. Shared
// vertices and collinear overlaps are not crossings.
std::vector<Vec2> exactCrossings(const Poly& p, const Poly& q) {
  std::vector<Vec2> out;
  for (size_t i = 0; i < p.size(); ++i) {
    Point a = toPoint(p[i]), b = toPoint(p[(i + 1) % p.size()]);
    for (size_t j = 0; j < q.size(); ++j) {
      Point c = toPoint(q[j]), d = toPoint(q[(j + 1) % q.size()]);
      if (CGAL::orientation(a, b, c) * CGAL::orientation(a, b, d) >= 0) continue;
      if (CGAL::orientation(c, d, a) * CGAL::orientation(c, d, b) >= 0) continue;
      K::Vector_2 ab = b - a, cd = d - c;
      FT t = CGAL::determinant(c - a, cd) / CGAL::determinant(ab, cd);
      out.push_back(toVec(a + t * ab));
    }
  }
  return out;
}

struct Stats {
  int pairs = 0, overlapping = 0, contained = 0, twoCrossings = 0, manyCrossings = 0, borderline = 0;
};

// One order (p, q) of a pair against the exact intersection.
void checkOrder(const Poly& p, const Poly& q, const Polygon& exact, double exactArea, double areaTol, double tol) {
  int n = int(p.size()), m = int(q.size());
  double minArea = std::min(signedArea(p.data(), n), signedArea(q.data(), m));
  bool borderline = exactArea > 0 && exactArea < kRel * minArea + tol * std::max(extentOf(p), extentOf(q));
  ClipVertex v[kMaxClipVertices];
  int k = clipConvex(p.data(), n, q.data(), m, v);
  double area = k ? clippedArea(v, k) : 0;
  EXPECT_NEAR(area, exactArea, areaTol);
  if (!borderline) {
    EXPECT_EQ(convexOverlap(p.data(), n, q.data(), m), exactArea > 0);
  }
  if (exactArea > 0 && !borderline) {
    ASSERT_GE(k, 3);
    Poly ours, theirs;
    for (int i = 0; i < k; ++i) ours.push_back(v[i].p);
    for (auto it = exact.vertices_begin(); it != exact.vertices_end(); ++it) theirs.push_back(toVec(*it));
    // Our vertices lie on the exact boundary; the result is convex and counter-clockwise.
    for (Vec2 x : ours) EXPECT_LE(boundaryDistance(x, theirs), tol);
    for (int i = 0; i < k; ++i) {
      Vec2 a = v[(i + k - 1) % k].p, b = v[i].p, c = v[(i + 1) % k].p;
      EXPECT_GE(cross(b - a, c - b), -tol * norm(c - a));
    }
    // The same vertex set once near-duplicates and near-collinear vertices are merged.
    double coarse = 1e4 * tol;
    Poly so = simplified(ours, coarse), st2 = simplified(theirs, coarse);
    EXPECT_EQ(so.size(), st2.size());
    for (Vec2 x : st2) {
      double d = 1e300;
      for (Vec2 y : so) d = std::min(d, double(norm(x - y)));
      EXPECT_LE(d, coarse);
    }
  }
}

void checkContact(const Poly& p, const Poly& q, double exactArea, bool borderline, double tol, Stats& st) {
  int n = int(p.size()), m = int(q.size());
  Vec2 cp = areaCentroid(p.data(), n), cq = areaCentroid(q.data(), m);
  Contact c = computeContact(p.data(), n, cp, q.data(), m, cq);
  Contact r = computeContact(q.data(), m, cq, p.data(), n, cp);
  if (borderline) return;
  ASSERT_EQ(c.touching, exactArea > 0);
  ASSERT_EQ(r.touching, exactArea > 0);
  if (!c.touching) {
    EXPECT_EQ(c.apexVertexP, -1);
    EXPECT_EQ(c.apexVertexQ, -1);
    return;
  }
  ++st.overlapping;
  for (const Contact* x : {&c, &r}) {
    EXPECT_NEAR(norm(x->normal), 1.0, kUnit);
    EXPECT_NEAR(x->width, norm(x->cross1 - x->cross0), tol);
    Vec2 nn = normalized(x->cross1 - x->cross0);
    if (x->width > 1e3 * tol) {  // n = perpRight(cross1 - cross0) / w
      EXPECT_NEAR(x->normal.x, nn.y, kUnit + tol / x->width);
      EXPECT_NEAR(x->normal.y, -nn.x, kUnit + tol / x->width);
    }
    EXPECT_LE(norm(x->point - Real(0.5) * (x->cross0 + x->cross1)), tol);
  }
  std::vector<Vec2> ex = exactCrossings(p, q);
  double far = 0;
  for (size_t i = 0; i < ex.size(); ++i)
    for (size_t j = i + 1; j < ex.size(); ++j) far = std::max(far, double(norm(ex[i] - ex[j])));
  // Near-degenerate: crossings within rounding of each other or of a vertex, where rounding may
  // legitimately merge them (a corner poking out by less than tol reads as containment).
  bool nearDegenerate = !ex.empty() && far <= 10 * tol;
  for (Vec2 x : ex)
    for (const Poly* poly : {&p, &q})
      for (Vec2 y : *poly) nearDegenerate = nearDegenerate || norm(x - y) <= 10 * tol;
  if (nearDegenerate) {
    ++st.borderline;
    return;
  }
  EXPECT_EQ(c.contained, ex.empty());
  EXPECT_EQ(r.contained, ex.empty());
  // Both orders describe the same contact: same line, opposite normals (the line's direction is
  // known to about tol / w).
  EXPECT_NEAR(c.width, r.width, tol);
  EXPECT_LE(norm(c.point - r.point), tol);
  if (ex.empty() ? norm(cq - cp) > 1e3 * tol : c.width > 1e3 * tol) {
    EXPECT_LE(norm(c.normal + r.normal), kUnit + 4 * tol / (ex.empty() ? double(norm(cq - cp)) : c.width));
  } else if (ex.empty() && norm(cq - cp) == 0) {  // identical polygons: +x in both orders
    EXPECT_LE(norm(c.normal - Vec2{1, 0}), kUnit);
    EXPECT_LE(norm(r.normal - Vec2{1, 0}), kUnit);
  }
  // Apex vertices: the vertex of Q inside P nearest c, and the same for P. Vertices within tol of
  // the other boundary may go either way.
  for (int side = 0; side < 2; ++side) {
    const Poly& a = side ? p : q;  // whose vertex
    const Poly& b = side ? q : p;  // inside which
    int apex = side ? c.apexVertexP : c.apexVertexQ;
    Polygon eb = toPolygon(b);
    double bestDeep = 1e300;
    for (Vec2 x : a) {
      if (eb.bounded_side(toPoint(x)) == CGAL::ON_BOUNDED_SIDE && boundaryDistance(x, b) > tol)
        bestDeep = std::min(bestDeep, double(norm(x - c.point)));
    }
    if (bestDeep < 1e300) {
      ASSERT_GE(apex, 0);
      EXPECT_LE(norm(a[size_t(apex)] - c.point), bestDeep + tol);
    }
    if (apex >= 0) {
      Vec2 x = a[size_t(apex)];
      EXPECT_TRUE(eb.bounded_side(toPoint(x)) == CGAL::ON_BOUNDED_SIDE || boundaryDistance(x, b) <= tol);
    } else {
      EXPECT_EQ(bestDeep, 1e300);
    }
  }
  if (ex.empty()) {
    ++st.contained;
    if (norm(cq - cp) > 1e3 * tol) {
      EXPECT_LE(norm(c.normal - normalized(cq - cp)), kUnit);
    }
    return;
  }
  // Crossing points: the exact pair, or the exact farthest pair for more than two.
  EXPECT_NEAR(c.width, far, tol);
  for (Vec2 x : {c.cross0, c.cross1}) {
    EXPECT_LE(boundaryDistance(x, p), tol);
    EXPECT_LE(boundaryDistance(x, q), tol);
  }
  if (ex.size() == 2) {
    ++st.twoCrossings;
    bool same =
        norm(c.cross0 - ex[0]) <= tol ? norm(c.cross1 - ex[1]) <= tol : norm(c.cross0 - ex[1]) <= tol && norm(c.cross1 - ex[0]) <= tol;
    EXPECT_TRUE(same);
    // n points from P into Q: P's vertices inside Q lie on the +n side of the line, Q's inside P on
    // the -n side (exact inside tests).
    Polygon ep = toPolygon(p), eq = toPolygon(q);
    for (Vec2 x : p) {
      if (eq.bounded_side(toPoint(x)) == CGAL::ON_BOUNDED_SIDE) {
        EXPECT_GE(dot(c.normal, x - c.point), -tol);
      }
    }
    for (Vec2 x : q) {
      if (ep.bounded_side(toPoint(x)) == CGAL::ON_BOUNDED_SIDE) {
        EXPECT_LE(dot(c.normal, x - c.point), tol);
      }
    }
  } else {
    ++st.manyCrossings;
  }
}

void runPairs(unsigned long long seed, int count) {
  Rng rng(seed);
  Stats st;
  for (int it = 0; it < count; ++it) {
    Pair pr = randomPair(rng);
    SCOPED_TRACE(::testing::Message() << "seed " << seed << " pair " << it);
    double scale = std::min(extentOf(pr.p), extentOf(pr.q));
    double tol = kRel * scale + kMag * std::max(magnitudeOf(pr.p), magnitudeOf(pr.q));
    Polygon ep = toPolygon(pr.p), eq = toPolygon(pr.q);
    std::vector<PolygonWithHoles> inter;
    CGAL::intersection(ep, eq, std::back_inserter(inter));
    ASSERT_LE(inter.size(), 1u);
    FT exactAreaFT = inter.empty() ? FT(0) : inter[0].outer_boundary().area();
    double exactArea = toDouble(exactAreaFT);
    double minArea = std::min(signedArea(pr.p.data(), int(pr.p.size())), signedArea(pr.q.data(), int(pr.q.size())));
    double areaTol = kRel * minArea + tol * scale;
    // Borderline: an overlap thinner than the tolerance (either way is right).
    bool borderline = exactArea > 0 && exactArea < kRel * minArea + tol * std::max(extentOf(pr.p), extentOf(pr.q));
    st.borderline += borderline;
    // do_intersect (closed sets) agrees whenever the overlap has area.
    if (exactArea > 0) {
      EXPECT_TRUE(CGAL::do_intersect(ep, eq));
    }
    Polygon exact = inter.empty() ? Polygon() : inter[0].outer_boundary();
    checkOrder(pr.p, pr.q, exact, exactArea, areaTol, tol);
    checkOrder(pr.q, pr.p, exact, exactArea, areaTol, tol);
    checkContact(pr.p, pr.q, exactArea, borderline, tol, st);
    ++st.pairs;
    if (::testing::Test::HasFatalFailure()) return;
  }
  // The generator must exercise every case.
  EXPECT_GT(st.overlapping, count / 2);
  EXPECT_GT(st.contained, count / 50);
  EXPECT_GT(st.twoCrossings, count / 5);
  EXPECT_GT(st.manyCrossings, 0);
  std::printf("pairs %d overlapping %d contained %d two-crossing %d many-crossing %d borderline %d\n", st.pairs, st.overlapping,
              st.contained, st.twoCrossings, st.manyCrossings, st.borderline);
}

}  // namespace

// 4 x 2,500 = 10,000 pairs, each checked in both orders; four tests so that ctest -j runs them side by side.
TEST(GeometryCgal, ClipAndContactSeed1) { runPairs(1, 2500); }
TEST(GeometryCgal, ClipAndContactSeed2) { runPairs(2, 2500); }
TEST(GeometryCgal, ClipAndContactSeed3) { runPairs(3, 2500); }
TEST(GeometryCgal, ClipAndContactSeed4) { runPairs(4, 2500); }

// Degenerate configurations on purpose: vertices on a coarse grid (exact in Real, and every
// cross product of them exact), so that shared edges, collinear edges, vertices on edges, touching
// corners and identical polygons are common. The overlap decision must then be exact.
Poly gridConvex(Rng& rng, int half, Vec2 offset) {
  for (;;) {
    std::vector<Ki::Point_2> pts, hull;
    int k = rng.integer(3, 10);
    for (int i = 0; i < k; ++i) pts.emplace_back(rng.integer(-half, half), rng.integer(-half, half));
    CGAL::convex_hull_2(pts.begin(), pts.end(), std::back_inserter(hull));
    if (hull.size() < 3) continue;
    Poly p;
    for (auto& h : hull) p.push_back(offset + Vec2{Real(h.x()), Real(h.y())});
    return p;
  }
}

TEST(GeometryCgal, DegenerateGridPairs) {
  Rng rng(51);
  Vec2 l[kMaxClipVertices], r[kMaxClipVertices];
  int touching = 0, apart = 0;
  for (int it = 0; it < 6000; ++it) {
    SCOPED_TRACE(::testing::Message() << "pair " << it);
    Poly p = gridConvex(rng, 3, {0, 0});
    Poly q = it % 10 == 0 ? p : gridConvex(rng, 3, {Real(rng.integer(-6, 6)), Real(rng.integer(-6, 6))});
    int n = int(p.size()), m = int(q.size());
    double tol = kDouble ? 1e-12 * 16 : 1e-5 * 16;
    std::vector<PolygonWithHoles> inter;
    CGAL::intersection(toPolygon(p), toPolygon(q), std::back_inserter(inter));
    double exactArea = inter.empty() ? 0 : toDouble(inter[0].outer_boundary().area());
    for (int order = 0; order < 2; ++order) {
      const Poly& a = order ? q : p;
      const Poly& b = order ? p : q;
      int na = order ? m : n, nb = order ? n : m;
      EXPECT_EQ(convexOverlap(a.data(), na, b.data(), nb), exactArea > 0);
      ClipVertex v[kMaxClipVertices];
      int k = clipConvex(a.data(), na, b.data(), nb, v);
      EXPECT_NEAR(k ? clippedArea(v, k) : 0, exactArea, tol);
      Vec2 ca = areaCentroid(a.data(), na), cb = areaCentroid(b.data(), nb);
      Contact c = computeContact(a.data(), na, ca, b.data(), nb, cb);
      ASSERT_EQ(c.touching, exactArea > 0);
      if (!c.touching) continue;
      EXPECT_NEAR(c.area, exactArea, tol);
      EXPECT_NEAR(norm(c.normal), 1.0, kUnit);
      EXPECT_NEAR(c.width, norm(c.cross1 - c.cross0), tol);
      EXPECT_LE(norm(c.point - Real(0.5) * (c.cross0 + c.cross1)), tol);
      if (!c.contained) {
        EXPECT_NEAR(c.normal.x * c.width, c.cross1.y - c.cross0.y, tol);  // n = perpRight(cross1 - cross0) / w
        EXPECT_NEAR(c.normal.y * c.width, c.cross0.x - c.cross1.x, tol);
        for (Vec2 x : {c.cross0, c.cross1}) {
          EXPECT_LE(boundaryDistance(x, a), tol);
          EXPECT_LE(boundaryDistance(x, b), tol);
        }
      }
    }
    (exactArea > 0 ? touching : apart)++;
    // The same pair turned and moved 3 km away: rounding breaks the exact touches, and the
    // tolerance must still call them no contact (and keep every real overlap).
    {
      Real ang = Real(rng.uniform(0, 2 * kPi));
      Vec2 off{Real(rng.uniform(-3000, 3000)), Real(rng.uniform(-3000, 3000))};
      Poly pw = p, qw = q;
      for (Vec2& x : pw) x = off + rotate(x, ang);
      for (Vec2& x : qw) x = off + rotate(x, ang);
      Contact c = computeContact(pw.data(), n, areaCentroid(pw.data(), n), qw.data(), m, areaCentroid(qw.data(), m));
      Contact c2 = computeContact(qw.data(), m, areaCentroid(qw.data(), m), pw.data(), n, areaCentroid(pw.data(), n));
      EXPECT_EQ(c.touching, exactArea > 0);
      EXPECT_EQ(c2.touching, exactArea > 0);
      double worldTol = kMag * 3000 * 50;  // rounding at 3 km times the perimeter
      EXPECT_NEAR(c.area, exactArea, worldTol);
      EXPECT_NEAR(c2.area, exactArea, worldTol);
      EXPECT_EQ(convexOverlap(pw.data(), n, qw.data(), m), exactArea > 0);
      EXPECT_EQ(convexOverlap(qw.data(), m, pw.data(), n), exactArea > 0);
    }
    // Splits along grid lines and diagonals: through vertices and along edges.
    Vec2 at{Real(rng.integer(-3, 3)), Real(rng.integer(-3, 3))};
    Vec2 dir{Real(rng.integer(-2, 2)), Real(rng.integer(-2, 2))};
    if (dir.x == 0 && dir.y == 0) dir = {1, 0};
    int nl, nr;
    splitByLine(p.data(), n, at, dir, l, &nl, r, &nr);
    double area = signedArea(p.data(), n);
    EXPECT_NEAR((nl ? signedArea(l, nl) : 0) + (nr ? signedArea(r, nr) : 0), area, tol);
    for (int side = 0; side < 2; ++side) {
      const Vec2* v = side ? r : l;
      int k = side ? nr : nl;
      if (k) {
        EXPECT_GE(k, 3);
        EXPECT_TRUE(isStrictlyConvexCCW(v, k));
      }
    }
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(touching, 1000);
  EXPECT_GT(apart, 1000);
}

TEST(GeometryCgal, MassProperties) {
  Rng rng(11);
  for (int it = 0; it < 10000; ++it) {
    Vec2 origin{0, 0};
    if (it % 4 == 0) origin = {Real(rng.uniform(-2000, 2000)), Real(rng.uniform(-2000, 2000))};
    double s = rng.uniform(0.5, 20);
    Poly p = randomConvex(rng, origin, s);
    int n = int(p.size());
    SCOPED_TRACE(::testing::Message() << "polygon " << it);
    ExactMass em = exactMass(p);
    double area = CGAL::to_double(em.area), tol = kRel * s + kMag * magnitudeOf(p);
    MassProperties mp = massProperties(p.data(), n);
    // Areas and moments far from the origin lose digits to the coordinate magnitude (about vertex
    // 0 for the centroid, but the area sum is about the origin).
    double areaTol = kRel * area + kMag * magnitudeOf(p) * s;
    EXPECT_NEAR(signedArea(p.data(), n), area, areaTol);
    EXPECT_NEAR(mp.area, area, areaTol);
    EXPECT_NEAR(mp.centroid.x, CGAL::to_double(em.cx), tol);
    EXPECT_NEAR(mp.centroid.y, CGAL::to_double(em.cy), tol);
    double jTol = kRel * area * s * s;
    double jxx = CGAL::to_double(em.jxx), jyy = CGAL::to_double(em.jyy), jxy = CGAL::to_double(em.jxy);
    EXPECT_NEAR(mp.jxx, jxx, jTol);
    EXPECT_NEAR(mp.jyy, jyy, jTol);
    EXPECT_NEAR(mp.jxy, jxy, jTol);
    // Principal moments: the eigenvalues of [[Jxx, Jxy], [Jxy, Jyy]] (invariant sum and product).
    EXPECT_NEAR(mp.ixx + mp.iyy, jxx + jyy, jTol);
    EXPECT_NEAR(mp.ixx * mp.iyy, jxx * jyy - jxy * jxy, jTol * (jxx + jyy));
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(GeometryCgal, EarClip) {
  Rng rng(21);
  int tri[kMaxVertices - 2][3];
  for (int it = 0; it < 10000; ++it) {
    SCOPED_TRACE(::testing::Message() << "polygon " << it);
    Poly p;
    double s = rng.uniform(0.5, 20);
    if (it % 2 == 0) {
      p = randomConvex(rng, {0, 0}, s);
    } else {
      // Random star-shaped (generally non-convex) simple polygon, up to kMaxVertices vertices.
      int n = rng.integer(3, kMaxVertices);
      std::vector<double> ang;
      for (int i = 0; i < n; ++i) ang.push_back(rng.uniform(0, 2 * kPi));
      std::sort(ang.begin(), ang.end());
      for (double a : ang) {
        double r = s * rng.uniform(0.2, 1);
        p.push_back({Real(r * std::cos(a)), Real(r * std::sin(a))});
      }
      Polygon ep = toPolygon(p);
      if (!ep.is_simple() || ep.orientation() != CGAL::COUNTERCLOCKWISE) continue;
    }
    int n = int(p.size());
    Polygon ep = toPolygon(p);
    double exactArea = toDouble(ep.area());
    int nt = earClip(p.data(), n, tri);
    ASSERT_EQ(nt, n - 2);
    FT sum = 0;
    for (int t = 0; t < nt; ++t) {
      Point a = toPoint(p[size_t(tri[t][0])]), b = toPoint(p[size_t(tri[t][1])]), c = toPoint(p[size_t(tri[t][2])]);
      // Exactly counter-clockwise and non-degenerate, and inside the polygon (its centroid is).
      EXPECT_EQ(CGAL::orientation(a, b, c), CGAL::LEFT_TURN);
      sum += K::Triangle_2(a, b, c).area();
      Point g = CGAL::centroid(a, b, c);
      EXPECT_EQ(ep.bounded_side(g), CGAL::ON_BOUNDED_SIDE);
    }
    // Exact sum of the exact triangle areas: the triangles tile the polygon.
    EXPECT_EQ(sum, ep.area());
    EXPECT_NEAR(toDouble(sum), exactArea, kRel * exactArea);
    if (::testing::Test::HasFailure()) return;
  }
}

TEST(GeometryCgal, SplitByLine) {
  Rng rng(31);
  Vec2 l[kMaxClipVertices], r[kMaxClipVertices];
  int cut = 0;
  for (int it = 0; it < 10000; ++it) {
    SCOPED_TRACE(::testing::Message() << "polygon " << it);
    Vec2 origin{0, 0};
    if (it % 4 == 0) origin = {Real(rng.uniform(-2000, 2000)), Real(rng.uniform(-2000, 2000))};
    double s = rng.uniform(0.5, 20);
    Poly p = randomConvex(rng, origin, s);
    int n = int(p.size());
    double area = toDouble(toPolygon(p).area());
    double tol = kRel * s + kMag * magnitudeOf(p);
    // A line through a random point near the polygon (it misses sometimes) or through a vertex.
    Vec2 at =
        it % 10 == 0 ? p[size_t(rng.integer(0, n - 1))] : origin + Vec2{Real(rng.uniform(-1.1, 1.1) * s), Real(rng.uniform(-1.1, 1.1) * s)};
    double a = rng.uniform(0, 2 * kPi);
    Vec2 dir{Real(std::cos(a)), Real(std::sin(a))};
    int nl, nr;
    splitByLine(p.data(), n, at, dir, l, &nl, r, &nr);
    double al = nl ? exactArea(l, nl) : 0, ar = nr ? exactArea(r, nr) : 0;  // exact areas of our pieces
    EXPECT_NEAR(al + ar, area, kRel * area + tol * s);
    cut += nl > 0 && nr > 0;
    // Each piece: convex, counter-clockwise, on its side of the line, and its area is the exact
    // area of the polygon clipped by the half-plane (up to slivers below tolerance).
    for (int side = 0; side < 2; ++side) {
      const Vec2* v = side ? r : l;
      int k = side ? nr : nl;
      if (k == 0) continue;
      EXPECT_GT(exactArea(v, k), 0);
      for (int i = 0; i < k; ++i) {
        Vec2 x = v[(i + k - 1) % k], y = v[i], z = v[(i + 1) % k];
        EXPECT_GE(cross(y - x, z - y), -tol * norm(z - x));
        double sd = double(cross(dir, y - at));
        if (side == 0) {
          EXPECT_GE(sd, -tol);
        } else {
          EXPECT_LE(sd, tol);
        }
      }
    }
    // Exact reference: the part of p left of the line.
    FT exactLeft = 0;
    {
      Polygon half;  // a large triangle covering the left half-plane near the polygon
      Vec2 d = 8 * Real(s + magnitudeOf(p)) * dir, nrm = perpLeft(d);
      half.push_back(toPoint(at - d));
      half.push_back(toPoint(at + d));
      half.push_back(toPoint(at + d + nrm));
      half.push_back(toPoint(at - d + nrm));
      std::vector<PolygonWithHoles> inter;
      if (half.orientation() == CGAL::COUNTERCLOCKWISE) {
        CGAL::intersection(toPolygon(p), half, std::back_inserter(inter));
        for (auto& h : inter) exactLeft += h.outer_boundary().area();
        // The rounded line may differ from the exact one by an ulp; both are within tolerance.
        EXPECT_NEAR(al, toDouble(exactLeft), kRel * area + tol * s);
      }
    }
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(cut, 2000);
}

TEST(GeometryCgal, TrianglesOverlap) {
  Rng rng(41);
  int agree = 0;
  for (int it = 0; it < 20000; ++it) {
    SCOPED_TRACE(::testing::Message() << "pair " << it);
    Vec2 t[2][3];
    double s = rng.uniform(0.5, 20);
    for (int k = 0; k < 2; ++k) {
      Vec2 c = k == 0 ? Vec2{0, 0} : Vec2{Real(rng.uniform(-1.6, 1.6) * s), Real(rng.uniform(-1.6, 1.6) * s)};
      for (;;) {
        for (int i = 0; i < 3; ++i) t[k][i] = c + Vec2{Real(rng.uniform(-1, 1) * s), Real(rng.uniform(-1, 1) * s)};
        Real a = cross(t[k][1] - t[k][0], t[k][2] - t[k][0]);
        if (a < 0) std::swap(t[k][1], t[k][2]);
        if (std::fabs(a) > 1e-3 * s * s) break;
      }
    }
    K::Triangle_2 e0(toPoint(t[0][0]), toPoint(t[0][1]), toPoint(t[0][2]));
    K::Triangle_2 e1(toPoint(t[1][0]), toPoint(t[1][1]), toPoint(t[1][2]));
    bool exact = CGAL::do_intersect(e0, e1);
    double dist = std::sqrt(toDouble(CGAL::squared_distance(e0, e1)));
    double tol = kRel * s;
    // eps = 0: the closed triangles, as CGAL, except within rounding of touching.
    if (dist > tol || exact) {
      EXPECT_EQ(trianglesOverlap(t[0], t[1], 0), exact) << dist;
      EXPECT_EQ(trianglesOverlap(t[1], t[0], 0), exact) << dist;
      ++agree;
    }
    // eps > 0: conservative, never misses a pair within eps (the edge-normal gaps bound the
    // distance from below, so pairs a little farther than eps may also pass).
    double eps = rng.uniform(0, 0.5) * s;
    if (dist <= eps - tol) {
      EXPECT_TRUE(trianglesOverlap(t[0], t[1], Real(eps))) << dist << " " << eps;
      EXPECT_TRUE(trianglesOverlap(t[1], t[0], Real(eps))) << dist << " " << eps;
    }
    // A gap along an edge normal beyond eps is a true separation: never claimed farther than it is.
    if (!trianglesOverlap(t[0], t[1], Real(eps))) {
      EXPECT_GT(dist, eps - tol);
    }
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_GT(agree, 19000);
}
