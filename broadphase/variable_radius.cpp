// variable_radius: the thesis's chosen strategy (5.4, Figure 5.8). A pair is listed when
// |c_a - c_b| <= R_a + R_b + skin, R the bounding radius about the centroid; the list is kept over
// steps under the rebuild rule of neighbour_list.hpp and filtered each step by R_a + R_b.
// Built by PairsWithinReach (neighbour_list.hpp), a sweep along x or a uniform grid, whichever
// tests fewer pairs (the thesis's GPU kernel tested every pair, one thread per floe; the list is
// the same).
#include "broadphase/kept_list/neighbour_list.hpp"
#include "framework/api/registry.hpp"

namespace gem {
namespace {

class VariableRadius final : public KeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin"};  // docs/scenario.md [broadphase.NAME]
  explicit VariableRadius(const BroadphaseSettings& s) : KeptListBroadphase(checkedSettings(s).skin) {}
  std::string name() const override { return "variable_radius"; }

 protected:
  void build(const World& world, NeighbourList& list) override {
    const int n = world.size();
    const Real skin = list.skin();
    m_half.resize(n);
    // |c_a - c_b| <= (R_a + skin / 2) + (R_b + skin / 2).
    for (int i = 0; i < n; ++i) m_half[i] = world.radius[i] + skin / 2;
    m_pairsWithinReach.build(world, m_half, 0, list);
  }

 private:
  std::vector<Real> m_half;
  PairsWithinReach m_pairsWithinReach;
};

}  // namespace

GEM_REGISTER_BROADPHASE(VariableRadius, "variable_radius", "kept list of pairs with |c_a - c_b| <= R_a + R_b + skin (thesis 5.4)");

}  // namespace gem
