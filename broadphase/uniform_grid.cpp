// uniform_grid: the sort-based loose grid of thesis 5.5.1 and docs/model.md 9 (after the CUDA "particles"
// sample): each body sits in the one cell of its centroid, bodies are sorted by cell key, and each
// body searches the 3 x 3 cells around its own. The pairs it finds are filtered by
// |c_a - c_b| <= R_a + R_b + skin and kept under the rule of neighbour_list.hpp: the list is the
// same as variable_radius's, only the build differs.
//
// Cell size: settings.cellSize, or the largest floe diameter + skin. Two bodies the list needs are
// then within one cell size of each other, so in neighbouring cells, as long as each has
// R + skin / 2 <= cell / 2. A body larger than that (a long wall, the vessel, any body when the cell
// is set small) is "large": it stays out of the grid and is tested against every body, O(n) per
// large body per build. A channel has two walls and one vessel, so this stays cheap.
//
// Cells are fixed in space (cell (i, j) covers [i c, (i + 1) c) x [j c, (j + 1) c)) and the domain
// is unbounded: the key range comes from the bodies at each build. The key is row-major,
// key = row * columns + column, so the three cells of a row are three consecutive keys and, in the
// sorted order, one contiguous run of bodies. Instead of cell start/end arrays (which a sparse field
// kilometres wide would make huge) the build walks the sorted bodies with monotone pointers to the
// runs it needs. Each pair is visited once ("half shell"): a body looks at the rest of its own cell,
// the cell to its right, and the three cells of the row above.
//
// Sorting: bodies move little between builds, so the previous order is nearly sorted by key and an
// insertion sort fixes it in about O(n); after a topology change it falls back to std::sort.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "framework/api/registry.hpp"

namespace gem {
namespace {

class UniformGrid final : public KeptListBroadphase {
 public:
  static constexpr const char* kSettings[] = {"skin", "cell_size"};  // docs/scenario.md [broadphase.NAME]
  explicit UniformGrid(const BroadphaseSettings& s)
      : KeptListBroadphase(checkedSettings(s).skin), m_cellSize(s.cellSize) {}
  std::string name() const override { return "uniform_grid"; }

 protected:
  void build(const World& world, NeighbourList& list) override {
    const int n = world.size();
    const Real skin = list.skin();
    Real cell = m_cellSize > 0 ? m_cellSize : 2 * largestFloeRadius(world) + skin;
    if (!(cell > 0)) cell = 1;  // no floes and no skin: every body is large, any size will do
    const Real* x = world.x.data();
    const Real* y = world.y.data();
    const Real* radius = world.radius.data();

    // Small and large bodies; the order of the last build is kept if the small ones are the same.
    bool sameBodies = static_cast<int>(m_isLarge.size()) == n;
    m_isLarge.resize(n);
    m_large.clear();
    for (int i = 0; i < n; ++i) {
      const char large = radius[i] + skin / 2 > cell / 2;
      sameBodies = sameBodies && m_isLarge[i] == large;
      m_isLarge[i] = large;
      if (large) m_large.push_back(i);
    }
    const int m = n - static_cast<int>(m_large.size());
    if (!sameBodies || static_cast<int>(m_order.size()) != m) {
      m_order.clear();
      for (int i = 0; i < n; ++i)
        if (!m_isLarge[i]) m_order.push_back(i);
    }

    // Cell of every small body and the key range.
    m_cx.resize(n);
    m_cy.resize(n);
    std::int64_t minX = 0, minY = 0, maxX = 0;
    for (int k = 0; k < m; ++k) {
      const int i = m_order[k];
      m_cx[i] = static_cast<std::int64_t>(std::floor(x[i] / cell));
      m_cy[i] = static_cast<std::int64_t>(std::floor(y[i] / cell));
      if (k == 0) minX = maxX = m_cx[i], minY = m_cy[i];
      minX = std::min(minX, m_cx[i]), maxX = std::max(maxX, m_cx[i]), minY = std::min(minY, m_cy[i]);
    }
    // Two spare columns: the key of "column - 1" or "column + 1" at a row's edge then names an empty
    // cell, not one at the other end of the next row.
    const std::int64_t columns = maxX - minX + 3;
    m_key.resize(n);
    for (int k = 0; k < m; ++k) {
      const int i = m_order[k];
      m_key[i] = (m_cy[i] - minY) * columns + (m_cx[i] - minX + 1);
    }
    sortByKey(m);

    // Sorted copies, so that the sweep reads memory in order.
    m_sx.resize(m), m_sy.resize(m), m_sh.resize(m), m_skey.resize(m), m_sslot.resize(m);
    for (int k = 0; k < m; ++k) {
      const int i = m_order[k];
      m_sx[k] = x[i], m_sy[k] = y[i], m_sh[k] = radius[i] + skin / 2;
      m_skey[k] = m_key[i], m_sslot[k] = i;
    }

    // The sweep. For body k in cell `key`: run 1 is the rest of its cell and the cell to its right
    // (keys key .. key + 1, positions after k); run 2 is the row above (keys key + columns - 1 ..
    // key + columns + 1). The ends of both runs only move forward as k does.
    int end1 = 0, begin2 = 0, end2 = 0;
    auto test = [&](int k, int q) {
      const Real dx = m_sx[k] - m_sx[q], dy = m_sy[k] - m_sy[q], reach = m_sh[k] + m_sh[q];
      if (dx * dx + dy * dy <= reach * reach) list.add(m_sslot[k], m_sslot[q]);
    };
    for (int k = 0; k < m; ++k) {
      const std::int64_t key = m_skey[k];
      while (end1 < m && m_skey[end1] <= key + 1) ++end1;
      while (begin2 < m && m_skey[begin2] < key + columns - 1) ++begin2;
      while (end2 < m && m_skey[end2] <= key + columns + 1) ++end2;
      for (int q = k + 1; q < end1; ++q) test(k, q);
      for (int q = begin2; q < end2; ++q) test(k, q);
    }

    // Large bodies against every body (each large-large pair once). Wall-wall pairs are dropped by
    // NeighbourList::finish for every strategy.
    for (int l : m_large)
      for (int j = 0; j < n; ++j) {
        if (j == l || (m_isLarge[j] && j < l)) continue;
        const Real dx = x[l] - x[j], dy = y[l] - y[j], reach = radius[l] + radius[j] + skin;
        if (dx * dx + dy * dy <= reach * reach) list.add(l, j);
      }
  }

 private:
  // Insertion sort of m_order by key, O(n + inversions); past a work budget (the order is stale
  // after a topology change) std::sort.
  void sortByKey(int m) {
    long moves = 0;
    const long budget = 16L * m + 1024;
    for (int k = 1; k < m && moves <= budget; ++k) {
      const int v = m_order[k];
      const std::int64_t key = m_key[v];
      int p = k - 1;
      while (p >= 0 && m_key[m_order[p]] > key) {
        m_order[p + 1] = m_order[p];
        --p;
        ++moves;
      }
      m_order[p + 1] = v;
    }
    if (moves > budget) std::sort(m_order.begin(), m_order.end(), [&](int a, int b) { return m_key[a] < m_key[b]; });
  }

  Real m_cellSize;
  std::vector<char> m_isLarge;
  std::vector<int> m_large, m_order, m_sslot;
  std::vector<std::int64_t> m_cx, m_cy, m_key, m_skey;
  std::vector<Real> m_sx, m_sy, m_sh;
};

}  // namespace

GEM_REGISTER_BROADPHASE(UniformGrid, "uniform_grid",
                        "kept list built on a sort-based loose grid, 3 x 3 cell search (thesis 5.5.1)");

}  // namespace gem
