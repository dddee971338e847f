// triangulation_mesh: thesis 5.5.2 and docs/model.md 9. Each polygon is ear-clipped once, in its body
// frame, into triangles; two bodies are candidates when any triangle of one overlaps any triangle
// of the other. The pairs worth testing come from a variable_radius list (same skin, same rebuild
// rule); each step, a listed pair whose bounding circles overlap has its triangles placed in the
// world and tested, so what comes out is close to the narrowphase's own answer.
//
// Triangles are cached by body id (ids are never reused and a body keeps its shape while it keeps
// its id), so a floe is clipped once in its life, not at every rebuild; bodies that break are new
// ids and get clipped when they first appear. The cache drops ids that are gone now and then.
//
// Per step: world vertices of a body are computed at most once (lazily, only for bodies in a
// circle-overlapping pair), and a triangle is tested only when its box meets the other body's box.
// The overlap test and its eps are broadphase/triangle_overlap.hpp's (shared with the device part).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "broadphase/triangle_overlap.hpp"
#include "framework/api/registry.hpp"
#include "geometry/triangulate.hpp"

namespace gem {
namespace {

struct TriangleSet {
  int count;
  int tri[kMaxTriangles][3];
};

class TriangulationMesh final : public KeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin"};  // docs/scenario.md [broadphase.NAME]
  explicit TriangulationMesh(const BroadphaseSettings& s) : KeptListBroadphase(checkedSettings(s).skin) {}
  std::string name() const override { return "triangulation_mesh"; }
  // Its triangles are kept by slot, refreshed by a build: renamed bodies rebuild.
  void bodiesRenamed() override { invalidate(); }

 protected:
  void build(const World& world, NeighbourList& list) override {
    const int n = world.size();
    const Real skin = list.skin();
    m_half.resize(n);
    for (int i = 0; i < n; ++i) m_half[i] = world.radius[i] + skin / 2;
    m_pairsWithinReach.build(world, m_half, 0, list);
    refreshTriangles(world);
  }

  void filter(const World& world, std::vector<CandidatePair>& pairs) override {
    pairs.clear();
    if (++m_epoch == 0) {  // the stamp wrapped: forget every stamp once
      std::fill(m_stamp.begin(), m_stamp.end(), 0u);
      m_epoch = 1;
    }
    // The kept list's candidates (bounding circles overlap, direct bodies included), then triangles.
    // Its resting ranges (framework/api/still_bodies.hpp) would not be ranges of this output.
    m_list.filterByCircles(world, m_circles);
    const Real* x = world.x.data();
    const Real* y = world.y.data();
    for (const CandidatePair& p : m_circles) {
      place(world, p.a);
      place(world, p.b);
      const Real eps = triangleTestEps(world.radius[p.a], world.radius[p.b], x[p.a], y[p.a]);
      if (!boxesMeet(m_box[p.a], m_box[p.b], eps)) continue;
      if (trianglesMeet(p.a, p.b, eps)) pairs.push_back({p.a, p.b});
    }
  }

 private:
  // Per-slot triangles (CSR over slots) from the cache by id; clips the bodies seen for the first time.
  void refreshTriangles(const World& world) {
    const int n = world.size();
    m_triStart.resize(n + 1);
    m_vertStart.resize(n + 1);
    m_tri.clear();
    m_triStart[0] = m_vertStart[0] = 0;
    for (int i = 0; i < n; ++i) {
      auto it = m_cache.find(world.id[i]);
      if (it == m_cache.end()) {
        TriangleSet t{};
        t.count = earClip(world.local(i), world.vertexCount[i], t.tri);
        it = m_cache.emplace(world.id[i], t).first;
      }
      const TriangleSet& t = it->second;
      for (int k = 0; k < t.count; ++k) m_tri.insert(m_tri.end(), t.tri[k], t.tri[k] + 3);
      m_triStart[i + 1] = m_triStart[i] + t.count;
      m_vertStart[i + 1] = m_vertStart[i] + world.vertexCount[i];
    }
    // Forget the ids that are gone once the cache holds many of them.
    if (m_cache.size() > static_cast<size_t>(2 * n) + 64) {
      std::unordered_map<std::int64_t, TriangleSet> kept;
      for (int i = 0; i < n; ++i) kept.emplace(world.id[i], m_cache.at(world.id[i]));
      m_cache.swap(kept);
    }
    m_world.resize(static_cast<size_t>(m_vertStart[n]));
    m_box.resize(n);
    m_stamp.assign(n, 0u);
    m_epoch = 0;
  }

  // World vertices and box of body i, once per step.
  void place(const World& world, int i) {
    if (m_stamp[i] == m_epoch) return;
    m_stamp[i] = m_epoch;
    Vec2* v = &m_world[m_vertStart[i]];
    const int n = world.vertexCount[i];
    toWorld(world.local(i), n, world.position(i), world.angle[i], v);
    m_box[i] = boundingBox(v, n);
  }

  // Any triangle of a meets any triangle of b? Only the triangles whose boxes meet the other body's
  // box take part; the first overlapping pair ends the search.
  bool trianglesMeet(int a, int b, Real eps) {
    auto gather = [&](int body, const Box& other, Vec2(*out)[3]) {
      int count = 0;
      const Vec2* v = &m_world[m_vertStart[body]];
      for (int t = m_triStart[body]; t < m_triStart[body + 1]; ++t) {
        const int* k = &m_tri[static_cast<size_t>(t) * 3];
        Vec2 tri[3] = {v[k[0]], v[k[1]], v[k[2]]};
        if (!boxesMeet(boundingBox(tri, 3), other, eps)) continue;
        std::copy(tri, tri + 3, out[count++]);
      }
      return count;
    };
    Vec2 ta[kMaxTriangles][3], tb[kMaxTriangles][3];
    const int na = gather(a, m_box[b], ta);
    if (na == 0) return false;
    const int nb = gather(b, m_box[a], tb);
    for (int i = 0; i < na; ++i)
      for (int j = 0; j < nb; ++j)
        if (trianglesOverlap(ta[i], tb[j], eps)) return true;
    return false;
  }

  std::vector<Real> m_half;
  std::vector<CandidatePair> m_circles;
  PairsWithinReach m_pairsWithinReach;
  std::unordered_map<std::int64_t, TriangleSet> m_cache;
  std::vector<int> m_triStart, m_vertStart, m_tri;  // m_tri: 3 vertex indices per triangle
  std::vector<Vec2> m_world;
  std::vector<Box> m_box;
  std::vector<std::uint32_t> m_stamp;
  std::uint32_t m_epoch = 0;
};

}  // namespace

GEM_REGISTER_BROADPHASE(TriangulationMesh, "triangulation_mesh",
                        "variable_radius list, then any overlapping pair of ear-clipped triangles (thesis 5.5.2)");

}  // namespace gem
