// uniform_grid: the uniform grid of thesis 5.5.1 and docs/model.md 9, rebuilt every step as on the
// GPU (where it is the step's own hashed grid, framework/cuda): the same structure on both backends,
// no kept list and so no skin.
//
// Cell size: [broadphase.uniform_grid] cell_size, else twice the largest floe's bounding radius.
// A body whose bounding box (centroid +- R) fits in a cell, 2 R <= cell, is "small": it sits in the
// cell of its box's lower-left corner, and two small bodies whose boxes overlap then sit in the same
// or neighbouring cells. A larger body (a wall, the vessel, any body when the cell is set small)
// stays out of the grid and is tested against every body. Every pair whose bounding boxes overlap
// is proposed, a superset of the pairs whose polygons' boxes overlap, which is what a strategy owes.
//
// Cells are fixed in space and the domain is unbounded: the key range comes from the bodies at each
// step. The key is row-major, key = row * columns + column, so the three cells of a row are three
// consecutive keys and, sorted, one run of bodies: no per-cell arrays (a sparse field kilometres
// wide would make them huge). Each pair is visited once ("half shell"): a body looks at the rest of
// its own cell, the cell to its right and the three cells of the row above. Bodies move little
// between steps, so the previous order is nearly sorted and an insertion sort fixes it in ~O(n).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "broadphase/kept_list/neighbour_list.hpp"
#include "framework/api/errors.hpp"
#include "framework/api/registry.hpp"

namespace gem {
namespace {

class UniformGrid final : public Broadphase {
 public:
  static constexpr const char* kSettings[] = {"cell_size"};  // docs/scenario.md [broadphase.NAME]
  explicit UniformGrid(const BroadphaseSettings& s) : m_cellSize(s.cellSize) {
    if (!(m_cellSize >= 0) || !std::isfinite(m_cellSize))
      throw InputError("broadphase uniform_grid: cell_size must be a finite number >= 0 (0: twice the largest floe's radius)");
  }
  std::string name() const override { return "uniform_grid"; }
  void invalidate() override { m_order.clear(); }
  long rebuilds() const override { return m_builds; }

  void findCandidates(const World& world, std::vector<CandidatePair>& pairs) override {
    ++m_builds;
    pairs.clear();
    const int n = world.size();
    Real cell = m_cellSize > 0 ? m_cellSize : 2 * largestFloeRadius(world);
    if (!(cell > 0)) cell = 1;  // no floes: every body is large, any size will do
    const Real* x = world.x.data();
    const Real* y = world.y.data();
    const Real* radius = world.radius.data();

    // Small and large bodies; the order of the last step is kept while the small ones are the same.
    bool sameBodies = static_cast<int>(m_isLarge.size()) == n;
    m_isLarge.resize(n);
    m_large.clear();
    for (int i = 0; i < n; ++i) {
      const char large = 2 * radius[i] > cell;
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

    // The cell of every small body's lower-left box corner, and the key range.
    m_cx.resize(n);
    m_cy.resize(n);
    std::int64_t minX = 0, minY = 0, maxX = 0;
    for (int k = 0; k < m; ++k) {
      const int i = m_order[k];
      m_cx[i] = static_cast<std::int64_t>(std::floor((x[i] - radius[i]) / cell));
      m_cy[i] = static_cast<std::int64_t>(std::floor((y[i] - radius[i]) / cell));
      if (k == 0) minX = maxX = m_cx[i], minY = m_cy[i];
      minX = std::min(minX, m_cx[i]), maxX = std::max(maxX, m_cx[i]), minY = std::min(minY, m_cy[i]);
    }
    // Two spare columns: "column - 1" or "column + 1" at a row's edge then names an empty cell,
    // not one at the other end of the next row.
    const std::int64_t columns = maxX - minX + 3;
    m_key.resize(n);
    for (int k = 0; k < m; ++k) {
      const int i = m_order[k];
      m_key[i] = (m_cy[i] - minY) * columns + (m_cx[i] - minX + 1);
    }
    sortByKey(m);

    // Sorted copies, so that the sweep reads memory in order.
    m_sx.resize(m), m_sy.resize(m), m_sr.resize(m), m_skey.resize(m), m_sslot.resize(m);
    for (int k = 0; k < m; ++k) {
      const int i = m_order[k];
      m_sx[k] = x[i], m_sy[k] = y[i], m_sr[k] = radius[i];
      m_skey[k] = m_key[i], m_sslot[k] = i;
    }
    auto add = [&](int a, int b) { pairs.push_back(a < b ? CandidatePair{a, b} : CandidatePair{b, a}); };
    auto boxesMeet = [](Real dx, Real dy, Real reach) { return std::fabs(dx) <= reach && std::fabs(dy) <= reach; };

    // The sweep. For body k in cell `key`: run 1 is the rest of its cell and the cell to its right
    // (keys key .. key + 1, positions after k); run 2 is the row above (keys key + columns - 1 ..
    // key + columns + 1). The ends of both runs only move forward as k does.
    int end1 = 0, begin2 = 0, end2 = 0;
    const Real* invMass = world.invMass.data();
    auto test = [&](int k, int q) {
      if (invMass[m_sslot[k]] == 0 && invMass[m_sslot[q]] == 0) return;  // two walls never need a contact
      if (boxesMeet(m_sx[k] - m_sx[q], m_sy[k] - m_sy[q], m_sr[k] + m_sr[q])) add(m_sslot[k], m_sslot[q]);
    };
    for (int k = 0; k < m; ++k) {
      const std::int64_t key = m_skey[k];
      while (end1 < m && m_skey[end1] <= key + 1) ++end1;
      while (begin2 < m && m_skey[begin2] < key + columns - 1) ++begin2;
      while (end2 < m && m_skey[end2] <= key + columns + 1) ++end2;
      for (int q = k + 1; q < end1; ++q) test(k, q);
      for (int q = begin2; q < end2; ++q) test(k, q);
    }
    // Large bodies against every body (each large-large pair once), never two immovable ones.
    for (int l : m_large)
      for (int j = 0; j < n; ++j) {
        if (j == l || (m_isLarge[j] && j < l) || (invMass[l] == 0 && invMass[j] == 0)) continue;
        if (boxesMeet(x[l] - x[j], y[l] - y[j], radius[l] + radius[j])) add(l, j);
      }
    sortPairs(pairs, n);
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

  // Pairs in (a, b) order: a counting sort by a (O(P + n)), then each short row by b.
  void sortPairs(std::vector<CandidatePair>& pairs, int n) {
    m_rowStart.assign(static_cast<size_t>(n) + 1, 0);
    for (const CandidatePair& p : pairs) ++m_rowStart[static_cast<size_t>(p.a) + 1];
    for (int i = 0; i < n; ++i) m_rowStart[static_cast<size_t>(i) + 1] += m_rowStart[static_cast<size_t>(i)];
    m_rowFill.assign(m_rowStart.begin(), m_rowStart.end() - 1);
    m_sorted.resize(pairs.size());
    for (const CandidatePair& p : pairs) m_sorted[static_cast<size_t>(m_rowFill[static_cast<size_t>(p.a)]++)] = p;
    for (int i = 0; i < n; ++i)
      std::sort(m_sorted.begin() + m_rowStart[static_cast<size_t>(i)], m_sorted.begin() + m_rowStart[static_cast<size_t>(i) + 1],
                [](CandidatePair p, CandidatePair q) { return p.b < q.b; });
    pairs.swap(m_sorted);
  }

  Real m_cellSize;
  long m_builds = 0;
  std::vector<int> m_rowStart, m_rowFill;
  std::vector<CandidatePair> m_sorted;
  std::vector<char> m_isLarge;
  std::vector<int> m_large, m_order, m_sslot;
  std::vector<std::int64_t> m_cx, m_cy, m_key, m_skey;
  std::vector<Real> m_sx, m_sy, m_sr;
};

}  // namespace

GEM_REGISTER_BROADPHASE(UniformGrid, "uniform_grid",
                        "uniform grid rebuilt every step, cell of the box's lower-left corner, half-shell search (thesis 5.5.1)");

}  // namespace gem
