// The resident driver's contact geometry, a warp a pair (framework/cuda/warp_contact.cuh), against
// computeContact a thread a pair on the device and on the CPU: the same contacts bit for bit, on
// polygon pairs chosen to take every path of the clipping (partial overlaps, one polygon inside the
// other, shared edges, vertices that coincide within the merge tolerance, 24-vertex polygons, far
// from the origin).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>

#include "tests/cuda/cuda_test_support.hpp"
#include "tests/cuda/warp_contact_kernels.hpp"

namespace gem::test {
namespace {

// Counter-clockwise convex polygon: n points on an ellipse at sorted random angles.
std::vector<Vec2> ellipse(std::mt19937_64& rng, int n, Vec2 centre, Real rx, Real ry, Real turn) {
  std::uniform_real_distribution<Real> u(0, 2 * M_PI);
  std::vector<Real> angles(n);
  for (Real& a : angles) a = u(rng);
  std::sort(angles.begin(), angles.end());
  std::vector<Vec2> v;
  const Real c = std::cos(turn), s = std::sin(turn);
  for (Real a : angles) {
    const Real x = rx * std::cos(a), y = ry * std::sin(a);
    v.push_back(Vec2{centre.x + c * x - s * y, centre.y + s * x + c * y});
  }
  return v;
}

Vec2 centroidOf(const std::vector<Vec2>& v) {
  Real twice = 0, cx = 0, cy = 0;
  for (size_t i = 0; i < v.size(); ++i) {
    const Vec2 a = v[i] - v[0], b = v[(i + 1) % v.size()] - v[0];
    const Real w = cross(a, b);
    twice += w, cx += (a.x + b.x) * w, cy += (a.y + b.y) * w;
  }
  return Vec2{v[0].x + cx / (3 * twice), v[0].y + cy / (3 * twice)};
}

void add(PolygonPairs& pairs, const std::vector<Vec2>& p, const std::vector<Vec2>& q) {
  for (const auto* poly : {&p, &q}) {
    std::vector<Vec2>& out = poly == &p ? pairs.p : pairs.q;
    const size_t at = out.size();
    out.resize(at + kMaxVertices, Vec2{0, 0});
    std::copy(poly->begin(), poly->end(), out.begin() + static_cast<std::ptrdiff_t>(at));
  }
  pairs.np.push_back(static_cast<int>(p.size()));
  pairs.nq.push_back(static_cast<int>(q.size()));
  pairs.cp.push_back(centroidOf(p));
  pairs.cq.push_back(centroidOf(q));
}

bool sameBits(Real a, Real b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool sameBits(Vec2 a, Vec2 b) { return sameBits(a.x, b.x) && sameBits(a.y, b.y); }

bool sameContact(const Contact& a, const Contact& b) {
  return a.touching == b.touching && a.contained == b.contained && a.apexVertexP == b.apexVertexP && a.apexVertexQ == b.apexVertexQ &&
         sameBits(a.area, b.area) && sameBits(a.point, b.point) && sameBits(a.normal, b.normal) && sameBits(a.width, b.width) &&
         sameBits(a.cross0, b.cross0) && sameBits(a.cross1, b.cross1);
}

PolygonPairs hardPairs() {
  std::mt19937_64 rng(20261202);
  std::uniform_real_distribution<Real> u(0, 1);
  std::uniform_int_distribution<int> vertices(3, kMaxVertices);
  PolygonPairs pairs;
  for (int i = 0; i < 6000; ++i) {
    const int kind = i % 6;
    // Far from the origin for a third of them: the merge tolerance grows with the coordinates.
    const Real far = i % 3 == 0 ? Real(1e5) * (1 + 9 * u(rng)) : 0;
    const Vec2 o{far, -far / 2};
    const Real r = Real(0.5) + 20 * u(rng);
    std::vector<Vec2> p = ellipse(rng, vertices(rng), o, r, r * (Real(0.3) + u(rng)), 2 * M_PI * u(rng));
    std::vector<Vec2> q;
    if (kind == 0) {  // partial overlap, any size ratio
      const Real s = r * (Real(0.1) + 2 * u(rng)), d = r * 1.5 * u(rng), a = 2 * M_PI * u(rng);
      q = ellipse(rng, vertices(rng), Vec2{o.x + d * std::cos(a), o.y + d * std::sin(a)}, s, s * (Real(0.3) + u(rng)), 2 * M_PI * u(rng));
    } else if (kind == 1) {  // one inside the other
      q = ellipse(rng, vertices(rng), o, r * Real(0.2), r * Real(0.1), u(rng));
      if ((i / 6) % 2) std::swap(p, q);
    } else if (kind == 2) {  // p moved and turned by a hair: vertices coincide within the tolerance
      const Real eps = (i % 4 ? Real(1e-13) : Real(1e-9)) * (r + far), turn = (u(rng) - Real(0.5)) * Real(1e-13);
      for (const Vec2& v : p)
        q.push_back(Vec2{o.x + std::cos(turn) * (v.x - o.x) - std::sin(turn) * (v.y - o.y) + eps * u(rng),
                         o.y + std::sin(turn) * (v.x - o.x) + std::cos(turn) * (v.y - o.y) + eps * u(rng)});
    } else if (kind == 3) {  // the very same polygon
      q = p;
    } else if (kind == 4) {  // sharing an edge, the other body across it, pressed in by 0 to 1e-6 r
      const size_t e = static_cast<size_t>(i) % p.size();
      const Vec2 a = p[e], b = p[(e + 1) % p.size()], t = b - a;
      const Real len = norm(t), push = Real(1e-6) * r * u(rng);
      const Vec2 outward{t.y / len, -t.x / len};
      q = {b - push * outward, a - push * outward, a + (r * u(rng) + 1) * outward, b + (r * u(rng) + 1) * outward};
    } else {  // two 24-gons, the longest clipping
      q = ellipse(rng, kMaxVertices, Vec2{o.x + r * (u(rng) - Real(0.5)), o.y + r * (u(rng) - Real(0.5))}, r, r * Real(0.7), u(rng));
      const std::vector<Vec2> big = ellipse(rng, kMaxVertices, o, r, r * Real(0.8), u(rng));
      add(pairs, big, q);
      continue;
    }
    add(pairs, p, q);
  }
  return pairs;
}

TEST(WarpContact, AWarpOrHalfAWarpAPairGivesComputeContactsContactsBitForBit) {
  GEM_SKIP_WITHOUT_CUDA();
  const PolygonPairs pairs = hardPairs();
  std::vector<Contact> byThread, byWarp, byHalfWarp, byCrampedHalfWarp;
  deviceContacts(pairs, byThread, byWarp, byHalfWarp, byCrampedHalfWarp);
  int touching = 0, contained = 0, warpDiffers = 0, halfDiffers = 0, crampedDiffers = 0, cpuDiffers = 0;
  for (int i = 0; i < pairs.size(); ++i) {
    const size_t v = static_cast<size_t>(i) * kMaxVertices;
    const Contact cpu = computeContact(&pairs.p[v], pairs.np[i], pairs.cp[i], &pairs.q[v], pairs.nq[i], pairs.cq[i]);
    touching += cpu.touching, contained += cpu.touching && cpu.contained;
    if (!sameContact(byWarp[i], byThread[i]) && warpDiffers++ < 5)
      ADD_FAILURE() << "pair " << i << ": the warp's contact differs from the thread's (area " << byWarp[i].area << " vs "
                    << byThread[i].area << ")";
    if (!sameContact(byHalfWarp[i], byThread[i]) && halfDiffers++ < 5)
      ADD_FAILURE() << "pair " << i << ": two pairs a warp's contact differs from the thread's (area " << byHalfWarp[i].area << " vs "
                    << byThread[i].area << ")";
    if (!sameContact(byCrampedHalfWarp[i], byThread[i]) && crampedDiffers++ < 5)
      ADD_FAILURE() << "pair " << i << ": with half warps out of room, the contact differs from the thread's";
    if (!sameContact(byThread[i], cpu) && cpuDiffers++ < 5)
      ADD_FAILURE() << "pair " << i << ": the device's contact differs from the CPU's (area " << byThread[i].area << " vs " << cpu.area
                    << ")";
  }
  EXPECT_EQ(warpDiffers, 0);
  EXPECT_EQ(halfDiffers, 0);
  EXPECT_EQ(crampedDiffers, 0);
  EXPECT_EQ(cpuDiffers, 0);
  // The pairs reach the paths they are meant to: many touch, some through containment.
  EXPECT_GT(touching, pairs.size() / 2);
  EXPECT_GT(contained, 100);
}

}  // namespace
}  // namespace gem::test
