// The device half of tests/cuda/warp_contact_test.cpp: each polygon pair's contact computed on the
// GPU one thread a pair (computeContact, as the device-wide driver does), one warp a pair
// (convexOverlap, then framework/cuda/warp_contact.cuh's warpContactOfOverlapping), and two pairs a
// warp (warpContactsOfTwo over the overlapping pairs, as the resident driver does; and again with
// half warps too cramped for most pairs, which the whole warp then clips).
#pragma once
#include <vector>

#include "geometry/config.hpp"
#include "geometry/contact.hpp"
#include "geometry/vec2.hpp"

namespace gem::test {

// Pairs (p[i], q[i]), counter-clockwise, world coordinates, kMaxVertices apart.
struct PolygonPairs {
  std::vector<Vec2> p, q;
  std::vector<int> np, nq;
  std::vector<Vec2> cp, cq;  // area centroids
  int size() const { return static_cast<int>(np.size()); }
};

void deviceContacts(const PolygonPairs& pairs, std::vector<Contact>& byThread, std::vector<Contact>& byWarp,
                    std::vector<Contact>& byHalfWarp, std::vector<Contact>& byCrampedHalfWarp);

}  // namespace gem::test
