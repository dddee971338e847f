// The cut of one floe by flexural breaking (docs/model.md 6, thesis A.100 to A.104), written once
// for the host and the device: the CPU's topology phase (flexural_breaking.cpp) and the resident
// CUDA kernel, which breaks floes without leaving the device (framework/cuda/resident_kernel.cuh),
// make the same pieces with the same arithmetic (the device build contracts no a*b+c into an FMA).
//
// The floe is cut by the straight line perpendicular to the contact normal n at the cusp length
// L_cusp into the floe (BreakRequest, computed by ship_impact). Each piece keeps at most
// kMaxFloeVertices vertices, moves rigidly with the parent (v_i = v + omega x (c_i - c),
// omega_i = omega) and leaves as rubble when its area is below min_area.
#pragma once
#include <cmath>

#include "events/break_request.hpp"
#include "geometry/portable_trig.hpp"
#include "geometry/split.hpp"

namespace gem {

// Drops the vertex with the smallest turn until the polygon has at most `limit` vertices: a cut
// adds one vertex, and a floe may have at most kMaxFloeVertices. v holds n vertices; returns the
// new count (the order of the others is kept).
GEM_HD inline int limitVertices(Vec2* v, int n, int limit) {
  while (n > limit) {
    int flattest = 0;
    Real smallest = INFINITY;
    for (int i = 0; i < n; ++i) {
      const Vec2 a = v[(i + n - 1) % n], b = v[i], c = v[(i + 1) % n];
      const Real turn = std::fabs(cross(b - a, c - b));
      if (turn < smallest) smallest = turn, flattest = i;
    }
    for (int i = flattest; i + 1 < n; ++i) v[i] = v[i + 1];
    --n;
  }
  return n;
}

// One piece of a cut floe, in world coordinates.
struct FloePiece {
  Vec2 vertices[kMaxClipVertices];
  int count;
  Real area;      // m^2
  Vec2 velocity;  // m/s, the parent's rigid motion at the piece's centroid
  bool rubble;    // area < min_area: it leaves the simulation
};

// Cuts the floe whose vertices about its centroid are `local` (n of them; at `centroid`, turned by
// `angle`, moving with `velocity` and `omega`) as `request` asks. Its world polygon is turned by
// the portable sine and cosine (geometry/portable_trig.hpp), the same on the host and the device.
// Returns false when the cut misses the floe (it stays whole); else fills both pieces, the left of
// the cut line first, as the host appends them (World::addPiece makes their rows).
GEM_HD inline bool cutFloe(const Vec2* local, int n, Vec2 centroid, Real angle, Vec2 velocity, Real omega, const BreakRequest& request,
                           Real minArea, FloePiece pieces[2]) {
  Vec2 polygon[kMaxVertices];
  toWorldPortable(local, n, centroid, angle, polygon);
  const Vec2 linePoint = request.point + request.cuspLength * request.normal;
  splitByLine(polygon, n, linePoint, perpLeft(request.normal), pieces[0].vertices, &pieces[0].count, pieces[1].vertices, &pieces[1].count);
  if (pieces[0].count < 3 || pieces[1].count < 3) return false;
  for (int k = 0; k < 2; ++k) {
    FloePiece& piece = pieces[k];
    piece.count = limitVertices(piece.vertices, piece.count, kMaxFloeVertices);
    piece.area = signedArea(piece.vertices, piece.count);
    piece.rubble = piece.area < minArea;
    const Vec2 pieceCentroid = areaCentroid(piece.vertices, piece.count);
    piece.velocity = velocity + crossZ(omega, pieceCentroid - centroid);
  }
  return true;
}

}  // namespace gem
