// Convex polygon basics: signed area, centroid, second moments and principal axes (docs/model.md 1,
// thesis A.1 to A.16), convexity, orientation and the body-to-world transform.
// Polygons are plain arrays (pointer + count): no containers, so the same code runs on the GPU.
#pragma once
#include <cmath>

#include "geometry/vec2.hpp"

namespace gem {

// a_i = x_i y_{i+1} - x_{i+1} y_i, the doubled signed area of triangle (0, v_i, v_{i+1}) (A.1).
// Summed about vertex 0 rather than the origin: far from the origin (world coordinates) the terms
// would otherwise cancel and, in float, lose the area to rounding.
GEM_HD inline Real signedArea(const Vec2* v, int n) {
  Real twice = 0;
  for (int i = 1; i + 1 < n; ++i) twice += cross(v[i] - v[0], v[i + 1] - v[0]);
  return Real(0.5) * twice;
}

// Area centroid (A.2, A.3). Computed relative to vertex 0 so that polygons far from the origin
// keep their precision. Returns vertex 0 for a degenerate (zero-area) polygon.
GEM_HD inline Vec2 areaCentroid(const Vec2* v, int n) {
  Vec2 o = v[0];
  Real twiceArea = 0, cx = 0, cy = 0;
  for (int i = 0; i < n; ++i) {
    Vec2 a = v[i] - o, b = v[(i + 1) % n] - o;
    Real ai = cross(a, b);
    twiceArea += ai;
    cx += (a.x + b.x) * ai;
    cy += (a.y + b.y) * ai;
  }
  if (twiceArea == Real(0)) return o;
  return {o.x + cx / (Real(3) * twiceArea), o.y + cy / (Real(3) * twiceArea)};
}

struct MassProperties {
  Real area;            // m^2 (positive)
  Vec2 centroid;        // area centroid, input coordinates
  Real jxx, jyy, jxy;   // area moments about the centroid, axes of the input (A.6 to A.8), m^4
  Real principalAngle;  // theta_p, rad (docs/model.md 1: 1/2 atan2(-2 J_xy, J_xx - J_yy))
  Real ixx, iyy;        // principal area moments (A.11, A.12), m^4
  Real izz;             // polar moment about the centroid, I_xx + I_yy, m^4
};

// The trigonometry of massProperties: libm's (the host's, or CUDA's on the device). The pieces of
// a break take geometry/portable_trig.hpp's PortableTrig instead, the same bits on both.
struct LibmTrig {
  GEM_HD static Real atan2(Real y, Real x) { return std::atan2(y, x); }
  GEM_HD static void sinCos(Real angle, Real* s, Real* c) {
    *c = std::cos(angle);
    *s = std::sin(angle);
  }
};

// Mass properties of a counter-clockwise polygon (A.1 to A.16). J_xx here is the integral of
// y'^2 (bending about x), J_yy of x'^2, J_xy of x'y' over the area.
template <class Trig = LibmTrig>
GEM_HD inline MassProperties massProperties(const Vec2* v, int n) {
  MassProperties p{};
  p.area = signedArea(v, n);
  p.centroid = areaCentroid(v, n);
  for (int i = 0; i < n; ++i) {
    Vec2 a = v[i] - p.centroid, b = v[(i + 1) % n] - p.centroid;
    Real ai = cross(a, b);
    p.jxx += (a.y * a.y + a.y * b.y + b.y * b.y) * ai;
    p.jyy += (a.x * a.x + a.x * b.x + b.x * b.x) * ai;
    p.jxy += (a.x * b.y + Real(2) * a.x * a.y + Real(2) * b.x * b.y + b.x * a.y) * ai;
  }
  p.jxx /= Real(12);
  p.jyy /= Real(12);
  p.jxy /= Real(24);
  p.principalAngle = Real(0.5) * Trig::atan2(Real(-2) * p.jxy, p.jxx - p.jyy);
  // Moments in the frame rotated by theta_p (A.11, A.12): the product of inertia vanishes there.
  Real c, s;
  Trig::sinCos(p.principalAngle, &s, &c);
  p.ixx = p.jxx * c * c + p.jyy * s * s - Real(2) * p.jxy * s * c;
  p.iyy = p.jxx * s * s + p.jyy * c * c + Real(2) * p.jxy * s * c;
  p.izz = p.jxx + p.jyy;
  return p;
}

// Reverses the vertex order in place (clockwise input is reversed, not rejected: docs/model.md 1).
GEM_HD inline void reverseOrder(Vec2* v, int n) {
  for (int i = 0, j = n - 1; i < j; ++i, --j) {
    Vec2 t = v[i];
    v[i] = v[j];
    v[j] = t;
  }
}

// True when the polygon is strictly convex and counter-clockwise: every turn is a left turn
// (cross product above tol times the edge lengths) and the boundary winds exactly once.
GEM_HD inline bool isStrictlyConvexCCW(const Vec2* v, int n, Real relTol = Real(1e-12)) {
  if (n < 3) return false;
  Real winding = 0;
  for (int i = 0; i < n; ++i) {
    Vec2 a = v[(i + n - 1) % n], b = v[i], c = v[(i + 1) % n];
    Vec2 e0 = b - a, e1 = c - b;
    Real l0 = norm(e0), l1 = norm(e1);
    if (!(l0 > Real(0)) || !(l1 > Real(0))) return false;
    if (!(cross(e0, e1) > relTol * l0 * l1)) return false;
    winding += std::atan2(cross(e0, e1), dot(e0, e1));
  }
  // A star-shaped self-intersecting polygon turns left everywhere but winds more than once.
  return std::fabs(winding - Real(2) * kPi) < Real(1e-6);
}

// Interior angle at vertex i of a counter-clockwise convex polygon, rad (the floe's apex angle phi).
GEM_HD inline Real interiorAngle(const Vec2* v, int n, int i) {
  Vec2 toPrev = v[(i + n - 1) % n] - v[i], toNext = v[(i + 1) % n] - v[i];
  return std::atan2(std::fabs(cross(toNext, toPrev)), dot(toNext, toPrev));
}

// World vertices of a body: body-frame vertices (about the centroid) rotated by angle and
// shifted to the centroid position (what A.24 to A.30 do in polar form).
// One vertex of toWorld: c and s are the cosine and sine of the body's angle.
GEM_HD inline Vec2 toWorldPoint(Vec2 local, Vec2 position, Real c, Real s) { return position + rotate(local, c, s); }

GEM_HD inline void toWorld(const Vec2* local, int n, Vec2 position, Real angle, Vec2* world) {
  Real c = std::cos(angle), s = std::sin(angle);
  for (int i = 0; i < n; ++i) world[i] = toWorldPoint(local[i], position, c, s);
}

// World-aligned bounding box: the narrowphase's first, cheapest rejection.
struct Box {
  Real x0, y0, x1, y1;
};

GEM_HD inline Box boundingBox(const Vec2* v, int n) {
  Box box{v[0].x, v[0].y, v[0].x, v[0].y};
  for (int k = 1; k < n; ++k) {
    box.x0 = v[k].x < box.x0 ? v[k].x : box.x0, box.x1 = v[k].x > box.x1 ? v[k].x : box.x1;
    box.y0 = v[k].y < box.y0 ? v[k].y : box.y0, box.y1 = v[k].y > box.y1 ? v[k].y : box.y1;
  }
  return box;
}

GEM_HD inline bool boxesOverlap(const Box& a, const Box& b) { return !(a.x0 > b.x1 || b.x0 > a.x1 || a.y0 > b.y1 || b.y0 > a.y1); }

// Farthest vertex distance from the body origin: the bounding radius of docs/model.md 9.
GEM_HD inline Real boundingRadius(const Vec2* local, int n) {
  Real r2 = 0;
  for (int i = 0; i < n; ++i) r2 = norm2(local[i]) > r2 ? norm2(local[i]) : r2;
  return std::sqrt(r2);
}

}  // namespace gem
