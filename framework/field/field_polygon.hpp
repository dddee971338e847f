// The generator's small convex polygons (fixed capacity, edges labelled with the site that made
// them) and the cuts that turn a power cell into a floe container. Internal to framework/field/.
#pragma once
#include <stdexcept>

#include "framework/field/field_shared.hpp"

namespace gem::field_detail {

// Small convex polygons: fixed capacity, each edge labelled with the site that made it (-1: the
// domain boundary), so that a power cell knows its neighbours.
constexpr int kPolyCapacity = 64;

struct Poly {
  int n = 0;
  P2 v[kPolyCapacity];
  int label[kPolyCapacity];
  void push(P2 p, int l) {
    if (n == kPolyCapacity) throw std::logic_error("field generator: polygon capacity exceeded");
    v[n] = p;
    label[n++] = l;
  }
};

double area(const Poly& q);
P2 centroid(const P2* v, int n);  // relative to vertex 0, as areaCentroid in geometry/polygon.hpp
P2 centroid(const Poly& q);

// Sutherland-Hodgman against one half-plane dot(a, x) <= b. A vertex carries the label of the
// edge that starts at it; the cut edge gets `label`.
void clip(const Poly& in, P2 a, double b, int label, Poly& out);

// The points of q at least delta from its boundary: q clipped by each edge moved inwards.
void inset(const Poly& q, double delta, Poly& out);

// Removes vertices that would make the polygon fail a strict convexity test after rounding to
// Real: edges shorter than minEdge, corners less than minEdge above the chord of their
// neighbours, and turns with sine below kMinTurnSine. Removing a vertex of a convex polygon cuts a
// corner, so the result stays inside the original.
void cleanup(Poly& q, double minEdge);

// Brings the vertex count into [minSides, maxSides]: above, cut the corner of least area; below,
// chamfer the sharpest corner (new vertices a fifth of the way along its edges). Both keep the
// polygon convex and inside the original. Corners are also cut down towards `preferred` sides as
// long as the area stays above keepArea: a large power cell has many neighbours, and without this
// every large floe would be a near-regular heptagon.
void fitVertexCount(Poly& q, int minSides, int maxSides, int preferred, double keepArea);

// Natural floes are seldom longer than two to three times their width, but a small power cell
// squeezed between large ones can be a sliver. Such a container is cut back across its long
// axis, symmetrically about its centroid, until sqrt(largest / smallest principal second
// moment) (the length / width of a rectangle) is at most maxAspect.
void trimToAspect(Poly& q, double maxAspect);

// Whether every point of pts lies inside (or on) the convex, counter-clockwise outer.
bool containsAll(const Poly& outer, const P2* pts, int n);

}  // namespace gem::field_detail
