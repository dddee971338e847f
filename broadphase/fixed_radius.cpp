// fixed_radius: the thesis's first neighbour list (5.4): one radius for the whole field, a pair is
// listed when its centroids are within it. The radius is settings.fixedRadius, or by default
// 2 x the largest floe bounding radius + skin, recomputed at each rebuild (floes only: a long wall
// or the vessel would make it span the field). A pair whose own R_a + R_b + skin is larger (a wall,
// the vessel, or a fixedRadius set too small) is listed by that instead: the interface demands
// that no touching pair is ever missed. Kept and filtered like variable_radius; it differs only in
// listing more pairs, which is the thesis's point of comparison.
#include <algorithm>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "framework/api/registry.hpp"

namespace gem {
namespace {

class FixedRadius final : public KeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin", "fixed_radius"};  // docs/scenario.md [broadphase.NAME]
  explicit FixedRadius(const BroadphaseSettings& s) : KeptListBroadphase(checkedSettings(s).skin), m_fixedRadius(s.fixedRadius) {}
  std::string name() const override { return "fixed_radius"; }

 protected:
  void build(const World& world, NeighbourList& list) override {
    const int n = world.size();
    const Real skin = list.skin();
    const Real fixed = m_fixedRadius > 0 ? m_fixedRadius : 2 * largestFloeRadius(world) + skin;
    // |c_a - c_b| <= max(fixed, (R_a + skin / 2) + (R_b + skin / 2)).
    m_half.resize(n);
    for (int i = 0; i < n; ++i) m_half[i] = world.radius[i] + skin / 2;
    m_pairsWithinReach.build(world, m_half, fixed, list);
  }

 private:
  Real m_fixedRadius;
  std::vector<Real> m_half;
  PairsWithinReach m_pairsWithinReach;
};

}  // namespace

GEM_REGISTER_BROADPHASE(FixedRadius, "fixed_radius",
                        "kept list of pairs within one global radius (default 2 x largest floe radius + skin; thesis 5.4)");

}  // namespace gem
