// A broadphase plugin that keeps none of the contract's ordering: all_pairs's pairs, last first,
// every other one given as (b, a), each twice, and a pair of a body with itself. GEM normalises a
// plugin strategy's pairs (normalizeCandidatePairs), so its runs equal all_pairs's bit for bit.
#include "framework/api/plugin_api.hpp"
#include "framework/api/registry.hpp"

GEM_PLUGIN("scrambled_pairs", "0.1.0")

namespace gem {
namespace {

class ScrambledPairs final : public Broadphase {
 public:
  explicit ScrambledPairs(const BroadphaseSettings&) {}
  std::string name() const override { return "scrambled_pairs"; }
  void invalidate() override {}

  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override {
    pairs.clear();
    const int n = world.size();
    for (int a = n - 1; a >= 0; --a)
      for (int b = n - 1; b > a; --b) {
        const Real dx = world.x[a] - world.x[b], dy = world.y[a] - world.y[b], reach = world.radius[a] + world.radius[b];
        if (dx * dx + dy * dy > reach * reach) continue;
        if (world.kind[a] == BodyKind::Wall && world.kind[b] == BodyKind::Wall) continue;
        const CandidatePair pair = (a + b) % 2 ? CandidatePair{b, a} : CandidatePair{a, b};
        pairs.push_back(pair);
        pairs.push_back(pair);
      }
    if (n > 0) pairs.push_back({0, 0});
  }
};

}  // namespace

GEM_REGISTER_BROADPHASE(ScrambledPairs, "scrambled_pairs", "test plugin: all_pairs's pairs out of order, reversed and repeated");

}  // namespace gem
