// all_pairs: every pair whose bounding circles overlap, |c_a - c_b| <= R_a + R_b, found by testing
// all n (n - 1) / 2 pairs at every call. No kept list, no skin, nothing to go stale: the reference
// the other strategies are checked against, and the thesis's first GPU structure (5.1).
#include "framework/api/registry.hpp"

namespace gem {
namespace {

class AllPairs final : public Broadphase {
 public:
  explicit AllPairs(const BroadphaseSettings&) {}
  std::string name() const override { return "all_pairs"; }
  void invalidate() override {}

  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override {
    pairs.clear();
    const int n = world.size();
    const Real* x = world.x.data();
    const Real* y = world.y.data();
    const Real* radius = world.radius.data();
    for (int a = 0; a < n; ++a) {
      const bool wallA = world.kind[a] == BodyKind::Wall;
      for (int b = a + 1; b < n; ++b) {
        const Real dx = x[a] - x[b], dy = y[a] - y[b], reach = radius[a] + radius[b];
        if (dx * dx + dy * dy > reach * reach) continue;
        // Two walls are both immovable: nothing can happen between them.
        if (wallA && world.kind[b] == BodyKind::Wall) continue;
        pairs.push_back({a, b});
      }
    }
  }
};

}  // namespace

GEM_REGISTER_BROADPHASE(AllPairs, "all_pairs", "every pair whose bounding circles overlap, O(n^2) each step (the reference)");

}  // namespace gem
