#include "broadphase/kept_list/reference_grid.hpp"

#include "framework/api/parallel.hpp"

namespace gem {

Real grid_cells::largeCut(const Real* size, int n, std::vector<Real>& scratch) {
  scratch.assign(size, size + n);
  const auto percentile = scratch.begin() + static_cast<std::ptrdiff_t>((n - 1) * 99 / 100);
  std::nth_element(scratch.begin(), percentile, scratch.end());
  return 2 * *percentile;
}

grid_cells::Layout grid_cells::layOut(Real x0, Real x1, Real y0, Real y1, Real least, int n) {
  const Real scale = std::max({Real(1), std::fabs(x0), std::fabs(x1), std::fabs(y0), std::fabs(y1)});
  Real cell = std::max(least, Real(1e-9) * scale);
  auto cellsAlong = [&](Real span) { return std::min<Real>(std::floor(span / cell) + 1, Real(1 << 30)); };
  const Real most = 4 * static_cast<Real>(n) + 1024;
  while (cellsAlong(x1 - x0) * cellsAlong(y1 - y0) > most) cell *= 2;
  return Layout{cell, static_cast<int>(cellsAlong(x1 - x0)), static_cast<int>(cellsAlong(y1 - y0))};
}

void ReferenceGrid::layOut(const Real* x0, const Real* y0, const Real* radius, int n, Real cellFloor) {
  m_nx = m_ny = 0;
  m_largest = 0;
  m_head.clear();
  if (n <= 0) {
    bin(x0, y0, radius, 0);
    return;
  }
  const Real cut = grid_cells::largeCut(radius, n, m_scratch);
  Real x1 = 0, y1 = 0;
  bool any = false;
  for (int i = 0; i < n; ++i) {
    if (!(radius[i] <= cut) || !std::isfinite(x0[i]) || !std::isfinite(y0[i])) continue;
    m_largest = std::max(m_largest, radius[i]);
    m_x0 = any ? std::min(m_x0, x0[i]) : x0[i], x1 = any ? std::max(x1, x0[i]) : x0[i];
    m_y0 = any ? std::min(m_y0, y0[i]) : y0[i], y1 = any ? std::max(y1, y0[i]) : y0[i];
    any = true;
  }
  if (any) {
    // As wide as a typical search's square (two of the largest radii and the reach beyond them),
    // so that a search meets about 3 x 3 cells. A reference outside these bounds later is clamped
    // into a border cell.
    const grid_cells::Layout cells = grid_cells::layOut(m_x0, x1, m_y0, y1, 2 * m_largest + cellFloor, n);
    m_cell = cells.cell, m_nx = cells.nx, m_ny = cells.ny;
  }
  bin(x0, y0, radius, n);
}

void ReferenceGrid::bin(const Real* x0, const Real* y0, const Real* radius, int n) {
  const size_t bodies = static_cast<size_t>(std::max(n, 0));
  m_head.assign(static_cast<size_t>(m_nx) * static_cast<size_t>(m_ny), -1);
  m_next.resize(bodies), m_prev.resize(bodies), m_in.resize(bodies);
  m_outside.clear();
  // Backwards, so that each chain runs in slot order (the order does not matter to the searches,
  // whose callers sort what they find, but slot order walks memory forwards).
  for (int i = n - 1; i >= 0; --i) {
    if (m_nx > 0 && radius[i] <= m_largest && std::isfinite(x0[i]) && std::isfinite(y0[i])) {
      m_in[static_cast<size_t>(i)] = -1;
      link(i, cellOf(x0[i], y0[i]));
    } else {
      m_in[static_cast<size_t>(i)] = -1, m_next[static_cast<size_t>(i)] = m_prev[static_cast<size_t>(i)] = -1;
      m_outside.push_back(i);
    }
  }
}

void ReferenceGrid::link(int i, int cell) {
  const size_t k = static_cast<size_t>(i);
  int& head = m_head[static_cast<size_t>(cell)];
  m_in[k] = cell, m_prev[k] = -1, m_next[k] = head;
  if (head >= 0) m_prev[static_cast<size_t>(head)] = i;
  head = i;
}

void ReferenceGrid::unlink(int i) {
  const size_t k = static_cast<size_t>(i);
  const int next = m_next[k], prev = m_prev[k];
  if (prev >= 0)
    m_next[static_cast<size_t>(prev)] = next;
  else
    m_head[static_cast<size_t>(m_in[k])] = next;
  if (next >= 0) m_prev[static_cast<size_t>(next)] = prev;
  m_in[k] = -1;
}

void ReferenceGrid::move(int i, Real x0, Real y0) {
  const size_t k = static_cast<size_t>(i);
  if (m_in[k] < 0) return;  // in no cell: visited by every search wherever it is
  if (!std::isfinite(x0) || !std::isfinite(y0)) {
    unlink(i);
    m_next[k] = m_prev[k] = -1;
    m_outside.push_back(i);
    return;
  }
  const int cell = cellOf(x0, y0);
  if (cell == m_in[k]) return;
  unlink(i);
  link(i, cell);
}

void ReferenceGrid::follow(const std::vector<int>& newSlot, const std::vector<char>& isNew, const Real* x0, const Real* y0,
                           const Real* radius) {
  const long oldCount = static_cast<long>(m_in.size());
  const int n = static_cast<int>(isNew.size());
  // A removed body leaves its chain first (a break removes a few), so that no chain names it.
  for (long j = 0; j < oldCount; ++j)
    if (newSlot[static_cast<size_t>(j)] < 0 && m_in[static_cast<size_t>(j)] >= 0) unlink(static_cast<int>(j));
  auto renamed = [&](int j) { return j < 0 ? -1 : newSlot[static_cast<size_t>(j)]; };
  std::vector<int>&next = m_renamed[0], &prev = m_renamed[1], &in = m_renamed[2];
  next.resize(static_cast<size_t>(n)), prev.resize(static_cast<size_t>(n)), in.resize(static_cast<size_t>(n));
  parallelRanges(oldCount, 4096, [&](int, long begin, long end) {
    for (long j = begin; j < end; ++j) {
      const int i = newSlot[static_cast<size_t>(j)];
      if (i < 0) continue;
      const size_t k = static_cast<size_t>(i), from = static_cast<size_t>(j);
      next[k] = renamed(m_next[from]), prev[k] = renamed(m_prev[from]), in[k] = m_in[from];
    }
  });
  parallelRanges(static_cast<long>(m_head.size()), 4096, [&](int, long begin, long end) {
    for (long c = begin; c < end; ++c) m_head[static_cast<size_t>(c)] = renamed(m_head[static_cast<size_t>(c)]);
  });
  m_next.swap(next), m_prev.swap(prev), m_in.swap(in);
  size_t kept = 0;
  for (const int j : m_outside)
    if (const int i = renamed(j); i >= 0) m_outside[kept++] = i;
  m_outside.resize(kept);
  for (int i = 0; i < n; ++i) {
    if (!isNew[static_cast<size_t>(i)]) continue;
    m_next[static_cast<size_t>(i)] = m_prev[static_cast<size_t>(i)] = m_in[static_cast<size_t>(i)] = -1;
    if (m_nx > 0 && radius[i] <= m_largest && std::isfinite(x0[i]) && std::isfinite(y0[i]))
      link(i, cellOf(x0[i], y0[i]));
    else
      m_outside.push_back(i);
  }
}

}  // namespace gem
