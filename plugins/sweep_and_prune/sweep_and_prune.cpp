// sweep_and_prune: a broadphase plugin (docs/plugins.md). Each body's bounding circle gives an
// interval [x - R, x + R] on the x axis; sorting the intervals by their start and sweeping them
// finds every pair whose intervals overlap (Baraff 1992; Cohen et al., I-COLLIDE 1995), and each
// such pair is kept when its bounding circles overlap, |c_a - c_b| <= R_a + R_b: the very pairs of
// all_pairs, found in O(n log n + pairs) instead of O(n^2).
//
// The order of the intervals is kept between steps and re-sorted by insertion, which is linear in
// n when bodies moved little (the coherence SAP is known for). Conservative: a pair whose
// polygons overlap has overlapping bounding circles, so overlapping x intervals. Pairs come out
// sorted by (a, b) with a < b (framework/api/broadphase.hpp).
#include <algorithm>
#include <vector>

#include "framework/api/broadphase.hpp"
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"

GEM_PLUGIN("sweep_and_prune", "1.0.0")

namespace gem {
namespace {

class SweepAndPrune final : public Broadphase {
 public:
  explicit SweepAndPrune(const BroadphaseSettings&) {}
  std::string name() const override { return "sweep_and_prune"; }
  void invalidate() override { m_order.clear(); }
  long rebuilds() const override { return m_rebuilds; }

  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override {
    pairs.clear();
    const int n = world.size();
    const Real* x = world.x.data();
    const Real* y = world.y.data();
    const Real* radius = world.radius.data();
    auto start = [&](int i) { return x[i] - radius[i]; };
    if (static_cast<int>(m_order.size()) != n) {  // first call, or bodies added or removed
      m_order.resize(static_cast<size_t>(n));
      for (int i = 0; i < n; ++i) m_order[static_cast<size_t>(i)] = i;
      ++m_rebuilds;
    }
    // Insertion sort by interval start: near-linear on last step's order.
    for (size_t k = 1; k < m_order.size(); ++k) {
      const int body = m_order[k];
      const Real s = start(body);
      size_t j = k;
      for (; j > 0 && start(m_order[j - 1]) > s; --j) m_order[j] = m_order[j - 1];
      m_order[j] = body;
    }
    for (size_t k = 0; k < m_order.size(); ++k) {
      const int a = m_order[k];
      const Real end = x[a] + radius[a];
      for (size_t l = k + 1; l < m_order.size() && start(m_order[l]) <= end; ++l) {
        const int b = m_order[l];
        const Real dx = x[a] - x[b], dy = y[a] - y[b], reach = radius[a] + radius[b];
        if (dx * dx + dy * dy > reach * reach) continue;
        if (world.kind[a] == BodyKind::Wall && world.kind[b] == BodyKind::Wall) continue;  // both immovable
        pairs.push_back({std::min(a, b), std::max(a, b)});
      }
    }
    std::sort(pairs.begin(), pairs.end(),
              [](const CandidatePair& p, const CandidatePair& q) { return p.a != q.a ? p.a < q.a : p.b < q.b; });
  }

 private:
  std::vector<int> m_order;  // body slots sorted by x - R
  long m_rebuilds = 0;
};

}  // namespace

GEM_REGISTER_BROADPHASE(SweepAndPrune, "sweep_and_prune",
                        "bounding-circle x intervals sorted and swept (insertion sort between steps), then the circle test");

}  // namespace gem
