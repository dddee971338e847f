// variable_radius: the thesis's chosen strategy (5.4, Figure 5.8). A pair is listed when
// |c_a - c_b| <= R_a + R_b + skin, R the bounding radius about the centroid; the list is kept over
// steps under the rebuild rule of neighbour_list.hpp and filtered each step by R_a + R_b.
// Built by sweep and prune along x: O(n + pairs) on a nearly sorted order, where the thesis's GPU
// kernel tested every pair (one thread per floe); the list it builds is the same.
#include "broadphase/neighbour_list.hpp"
#include "framework/registry.hpp"

namespace gem {
namespace {

class VariableRadius final : public KeptListBroadphase {
 public:
  explicit VariableRadius(const BroadphaseSettings& s) : KeptListBroadphase(checkedSettings(s).skin) {}
  std::string name() const override { return "variable_radius"; }

 protected:
  void build(const World& world, NeighbourList& list) override {
    const int n = world.size();
    const Real skin = list.skin();
    const Real* radius = world.radius.data();
    m_half.resize(n);
    for (int i = 0; i < n; ++i) m_half[i] = radius[i] + skin / 2;
    sweepAndPrune(world, m_half, m_order, m_lo, list, [&](int i, int j, Real d2) {
      const Real reach = radius[i] + radius[j] + skin;
      return d2 <= reach * reach;
    });
  }

 private:
  std::vector<Real> m_half, m_lo;
  std::vector<int> m_order;
};

}  // namespace

GEM_REGISTER_BROADPHASE(VariableRadius, "variable_radius",
                        "kept list of pairs with |c_a - c_b| <= R_a + R_b + skin (thesis 5.4)");

}  // namespace gem
