// uniform_grid: the sort-based loose grid of thesis 5.5.1 and MODEL.md 9 (after the CUDA "particles"
// sample): each body sits in the one cell of its centroid, bodies are sorted by cell, cell start/end
// come from the sorted order, and each body searches the 3 x 3 cells around its own. The pairs it
// finds are filtered by |c_a - c_b| <= R_a + R_b + skin and kept under the rule of
// neighbour_list.hpp: the list is the same as variable_radius's, only the build differs.
//
// Cell size: settings.cellSize, or the largest floe diameter + skin. Two bodies the list needs are
// then within one cell size of each other, so within the 3 x 3 block, as long as each has
// R + skin / 2 <= cell / 2. A body larger than that (a long wall, the vessel, any body when the cell
// is set small) is "large": it stays out of the grid and is tested against every body, O(n) per
// large body per build. A channel has two walls and one vessel, so this stays cheap.
//
// The domain is unbounded: the grid's bounds come from the small bodies at each build. When the
// bounding box holds far more cells than bodies (a few floes scattered over kilometres) the cells
// are hashed into a table of about 2n buckets instead (the sample's wrapped grid); two cells that
// share a bucket only add candidates that the distance filter drops.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "broadphase/neighbour_list.hpp"
#include "framework/registry.hpp"

namespace gem {
namespace {

class UniformGrid final : public KeptListBroadphase {
 public:
  explicit UniformGrid(const BroadphaseSettings& s) : KeptListBroadphase(checkedSettings(s).skin), m_cellSize(s.cellSize) {}
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

    // Small and large bodies, and the bounds of the small ones.
    m_large.clear();
    m_isLarge.assign(n, 0);
    Real minX = 0, minY = 0, maxX = 0, maxY = 0;
    int small = 0;
    for (int i = 0; i < n; ++i) {
      if (radius[i] + skin / 2 > cell / 2) {
        m_isLarge[i] = 1;
        m_large.push_back(i);
        continue;
      }
      if (small++ == 0) minX = maxX = x[i], minY = maxY = y[i];
      minX = std::min(minX, x[i]), maxX = std::max(maxX, x[i]);
      minY = std::min(minY, y[i]), maxY = std::max(maxY, y[i]);
    }
    const double spanX = std::floor((maxX - minX) / cell) + 1, spanY = std::floor((maxY - minY) / cell) + 1;
    m_dense = spanX * spanY <= std::max(4.0 * small, 4096.0);
    if (m_dense) {
      m_nx = static_cast<std::int64_t>(spanX);
      m_ny = static_cast<std::int64_t>(spanY);
      m_buckets = m_nx * m_ny;
    } else {
      m_buckets = 64;
      while (m_buckets < 2 * static_cast<std::int64_t>(small)) m_buckets *= 2;
    }

    // Hash (cell of the centroid) and counting sort by bucket: a one-digit radix sort, O(n + cells),
    // stable, so each bucket lists its bodies in slot order.
    m_cx.resize(n);
    m_cy.resize(n);
    m_bucketOf.resize(n);
    m_start.assign(static_cast<size_t>(m_buckets) + 1, 0);
    for (int i = 0; i < n; ++i) {
      if (m_isLarge[i]) continue;
      m_cx[i] = static_cast<std::int64_t>(std::floor((x[i] - minX) / cell));
      m_cy[i] = static_cast<std::int64_t>(std::floor((y[i] - minY) / cell));
      m_bucketOf[i] = bucket(m_cx[i], m_cy[i]);
      ++m_start[static_cast<size_t>(m_bucketOf[i]) + 1];
    }
    for (std::int64_t b = 0; b < m_buckets; ++b) m_start[b + 1] += m_start[b];
    m_sorted.resize(small);
    m_fill.assign(m_start.begin(), m_start.end() - 1);
    for (int i = 0; i < n; ++i)
      if (!m_isLarge[i]) m_sorted[m_fill[m_bucketOf[i]]++] = i;

    // Row by row in slot order, each row sorted: the list comes out sorted and needs no sort.
    auto accept = [&](int i, int j) {
      if (world.kind[i] == BodyKind::Wall && world.kind[j] == BodyKind::Wall) return false;
      const Real dx = x[i] - x[j], dy = y[i] - y[j], reach = radius[i] + radius[j] + skin;
      return dx * dx + dy * dy <= reach * reach;
    };
    for (int i = 0; i < n; ++i) {
      m_row.clear();
      if (m_isLarge[i]) {
        for (int j = i + 1; j < n; ++j)
          if (accept(i, j)) m_row.push_back(j);
      } else {
        std::int64_t seen[9];
        int seenCount = 0;
        for (std::int64_t oy = -1; oy <= 1; ++oy)
          for (std::int64_t ox = -1; ox <= 1; ++ox) {
            const std::int64_t cx = m_cx[i] + ox, cy = m_cy[i] + oy;
            if (m_dense && (cx < 0 || cy < 0 || cx >= m_nx || cy >= m_ny)) continue;
            const std::int64_t b = bucket(cx, cy);
            // Hashed cells may share a bucket: search each bucket once.
            if (std::find(seen, seen + seenCount, b) != seen + seenCount) continue;
            seen[seenCount++] = b;
            for (int k = m_start[b]; k < m_start[b + 1]; ++k) {
              const int j = m_sorted[k];
              if (j > i && accept(i, j)) m_row.push_back(j);
            }
          }
        for (int j : m_large)
          if (j > i && accept(i, j)) m_row.push_back(j);
        std::sort(m_row.begin(), m_row.end());
      }
      for (int j : m_row) list.add(i, j);
    }
  }

 private:
  std::int64_t bucket(std::int64_t cx, std::int64_t cy) const {
    if (m_dense) return cy * m_nx + cx;
    std::uint64_t h = static_cast<std::uint64_t>(cx) * 0x9E3779B97F4A7C15ull ^ static_cast<std::uint64_t>(cy) * 0xC2B2AE3D27D4EB4Full;
    h ^= h >> 29;
    return static_cast<std::int64_t>(h & static_cast<std::uint64_t>(m_buckets - 1));
  }

  Real m_cellSize;
  bool m_dense = true;
  std::int64_t m_nx = 0, m_ny = 0, m_buckets = 0;
  std::vector<char> m_isLarge;
  std::vector<int> m_large, m_sorted, m_start, m_fill, m_row;
  std::vector<std::int64_t> m_cx, m_cy, m_bucketOf;
};

}  // namespace

GEM_REGISTER_BROADPHASE(UniformGrid, "uniform_grid",
                        "kept list built on a sort-based loose grid, 3 x 3 cell search (thesis 5.5.1)");

}  // namespace gem
