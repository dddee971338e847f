// A uniform grid of the kept list's reference positions (neighbour_list.hpp), so that the two
// searches of one body against all the others, the direct pass and relisting, look at the few
// bodies near it instead of every body.
//
// Why a grid of references, not of positions: the list's rule (docs/model.md 9) keeps every body
// that is not direct within half the skin of its reference, so a body found near a reference is
// near the body; and a reference changes only at a build, a rename or a relist, not every step, so
// the grid is kept: a relisted floe moves to the cell of its new reference (each cell is a doubly
// linked chain of slots), and a rename renames the chains. The bodies far larger than most (the
// walls span the field) and a reference at no finite place are in no cell: every search visits
// them.
//
// At 10^5 floes the two searches were a pass over every body for each direct or relisted floe:
// relisting's was the largest item of a one-thread step (docs/performance.md 3.14, 3.15).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "framework/world/world.hpp"

namespace gem {

// What the kept lists' two uniform grids share: the build's (PairsWithinReach::binInGrid) and the
// grid of reference states below.
namespace grid_cells {

// The cell of coordinate v along an axis of `count` cells of width `cell` from `origin`: clamped,
// so that a coordinate outside the grid, or not a number, still lands in a cell. Monotonic in v,
// so a point inside a square is in a cell between the square's corners' cells, whether or not
// either was clamped.
inline int cellAlong(Real v, Real origin, Real cell, int count) {
  const Real c = std::floor((v - origin) / cell);
  if (!(c >= 0)) return 0;
  return c >= static_cast<Real>(count - 1) ? count - 1 : static_cast<int>(c);
}

// Twice the 99th percentile of size[0 .. n): a body larger is in no cell (the walls, the odd
// giant floe), so that it does not widen every cell. n > 0.
Real largeCut(const Real* size, int n, std::vector<Real>& scratch);

// Cells at least `least` wide (and a billionth of the coordinates' scale) over the box [x0, x1] x
// [y0, y1], doubled past 4 n + 1024 cells (a sparse field in a huge box).
struct Layout {
  Real cell;
  int nx, ny;
};
Layout layOut(Real x0, Real x1, Real y0, Real y1, Real least, int n);

}  // namespace grid_cells

class ReferenceGrid {
 public:
  // Lays the cells out for bodies at (x0[i], y0[i]), i < n, and bins them: the bodies whose radius
  // passes twice the 99th percentile of the radii go in no cell. The cells are at least
  // `cellFloor` wider than two of the largest radii in them (the caller's reach beyond the radii).
  void layOut(const Real* x0, const Real* y0, const Real* radius, int n, Real cellFloor);
  // Body i's reference is now (x0, y0): it moves to that cell (one in no cell stays in none).
  void move(int i, Real x0, Real y0);
  // Bodies moved to other slots, keeping their references: old slot j is now newSlot[j] (-1:
  // removed), and a new slot that no old one maps to (isNew, by new slot) holds a new body, binned
  // at (x0[i], y0[i]). The chains are renamed over ranges of slots on the caller's parallel runner
  // (framework/api/parallel.hpp), not binned again: binning is a serial pass of divisions and
  // scattered writes, and at 10^5 floes a break or a re-sort comes every few dozen steps.
  void follow(const std::vector<int>& newSlot, const std::vector<char>& isNew, const Real* x0, const Real* y0, const Real* radius);
  // The largest radius of the bodies in cells: a search for the bodies within r + R_j + extra of a
  // point reaches largestRadius() + r + extra.
  Real largestRadius() const { return m_largest; }
  int outsideCount() const { return static_cast<int>(m_outside.size()); }

  // visit(j) for every body in a cell that meets the square of half-width `reach` around (x, y),
  // then for every body in no cell. Every body whose reference lies in the square is visited, each
  // once; so are some beyond it. A square that is not finite is clamped like any other (its tests
  // then fail by themselves).
  template <class Visit>
  void near(Real x, Real y, Real reach, Visit&& visit) const {
    if (m_nx > 0) {
      const int cx0 = cellAlong(x - reach, m_x0, m_nx), cx1 = cellAlong(x + reach, m_x0, m_nx);
      const int cy0 = cellAlong(y - reach, m_y0, m_ny), cy1 = cellAlong(y + reach, m_y0, m_ny);
      for (int cy = cy0; cy <= cy1; ++cy)
        for (int cx = cx0; cx <= cx1; ++cx)
          for (int j = m_head[static_cast<size_t>(cy * m_nx + cx)]; j >= 0; j = m_next[static_cast<size_t>(j)]) visit(j);
    }
    for (const int j : m_outside) visit(j);
  }

 private:
  int cellAlong(Real v, Real origin, int count) const { return grid_cells::cellAlong(v, origin, m_cell, count); }
  int cellOf(Real x0, Real y0) const { return cellAlong(y0, m_y0, m_ny) * m_nx + cellAlong(x0, m_x0, m_nx); }
  // Bins bodies [0, n) in the cells laid out: one no larger than the largest radius found in them,
  // with a finite reference, goes to its reference's cell.
  void bin(const Real* x0, const Real* y0, const Real* radius, int n);
  void link(int i, int cell);
  void unlink(int i);

  Real m_x0 = 0, m_y0 = 0, m_cell = 1, m_largest = 0;
  int m_nx = 0, m_ny = 0;
  std::vector<int> m_head;                // by cell: its first body, -1 for none
  std::vector<int> m_next, m_prev, m_in;  // by slot: the chain's neighbours (-1: none), its cell (-1: none)
  std::vector<int> m_outside;             // the bodies in no cell, visited by every search
  std::vector<Real> m_scratch;
  std::vector<int> m_renamed[3];  // follow()'s: next, prev and cell by the new slots
};

}  // namespace gem
