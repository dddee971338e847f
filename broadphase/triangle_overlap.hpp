// The triangle test of triangulation_mesh (thesis 5.5.2), written once for its CPU strategy
// (triangulation_mesh.cpp) and its device part (triangulation_mesh.cu): they must give the very
// same candidates, so the constants and the box test live here only.
//
// The test is conservative within eps = kTriangleEpsRel x (R_a + R_b + |x_a| + |y_a|) (size plus
// distance from the origin), so rounding in placing the triangles can never drop a pair whose
// polygons touch.
#pragma once
#include <cmath>

#include "geometry/polygon.hpp"

namespace gem {

// An ear-clipped convex polygon of kMaxVertices has at most this many triangles.
constexpr int kMaxTriangles = kMaxVertices - 2;

#if defined(GEM_REAL_FLOAT)
constexpr Real kTriangleEpsRel = Real(1e-5);
#else
constexpr Real kTriangleEpsRel = Real(1e-9);
#endif

GEM_HD inline Real triangleTestEps(Real radiusA, Real radiusB, Real xA, Real yA) {
  return kTriangleEpsRel * (radiusA + radiusB + std::fabs(xA) + std::fabs(yA));
}

// Boxes that overlap or come within eps of each other.
GEM_HD inline bool boxesMeet(const Box& p, const Box& q, Real eps) {
  return p.x0 <= q.x1 + eps && q.x0 <= p.x1 + eps && p.y0 <= q.y1 + eps && q.y0 <= p.y1 + eps;
}

}  // namespace gem
