// The power diagram of power_diagram.hpp, one cell at a time (the domain cut by the power
// bisectors of the sites that can reach it), and the cell measures and Laplacian solve on it.
// Compiled without fused multiply-add or vectorizing, as every generator file (CMakeLists.txt;
// why: field_shared.hpp).

#include "framework/field/power_diagram.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace gem::field_detail {

void PowerDiagram::rebuild() {
  m_start.assign(static_cast<size_t>(m_grid.nx) * m_grid.ny + 1, 0);
  for (const P2& p : m_site) ++m_start[static_cast<size_t>(m_grid.cell(p)) + 1];
  std::partial_sum(m_start.begin(), m_start.end(), m_start.begin());
  m_items.resize(m_site.size());
  std::vector<int> fill(m_start.begin(), m_start.end() - 1);
  for (size_t i = 0; i < m_site.size(); ++i)
    m_items[static_cast<size_t>(fill[static_cast<size_t>(m_grid.cell(m_site[i]))]++)] = static_cast<int>(i);
}

void PowerDiagram::setWeights(const std::vector<double>& w) {
  m_w = &w;
  m_wMax = -std::numeric_limits<double>::infinity();
  m_cellMaxW.assign(static_cast<size_t>(m_grid.nx) * m_grid.ny, -std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < m_site.size(); ++i) {
    double& m = m_cellMaxW[static_cast<size_t>(m_grid.cell(m_site[i]))];
    m = std::max(m, w[i]);
    m_wMax = std::max(m_wMax, w[i]);
  }
}

void PowerDiagram::cell(int i, Poly& out) {
  const std::vector<double>& w = *m_w;
  const P2 p = m_site[static_cast<size_t>(i)];
  const double wi = w[static_cast<size_t>(i)];
  Poly& cur = out;
  cur.n = 0;
  cur.push(P2{m_domain.x0, m_domain.y0} - p, -1);
  cur.push(P2{m_domain.x1, m_domain.y0} - p, -1);
  cur.push(P2{m_domain.x1, m_domain.y1} - p, -1);
  cur.push(P2{m_domain.x0, m_domain.y1} - p, -1);
  double r2 = maxDistance2(cur);
  const int gx = m_grid.cx(p.x), gy = m_grid.cy(p.y);
  const int maxRing = std::max(m_grid.nx, m_grid.ny);
  for (int ring = 1; ring <= maxRing; ++ring) {
    m_candidates.clear();
    const double r = std::sqrt(r2);
    for (int y = gy - ring; y <= gy + ring; ++y) {
      if (y < 0 || y >= m_grid.ny) continue;
      const bool edgeRow = y == gy - ring || y == gy + ring;
      const double boxY0 = m_grid.y0 + y * m_grid.h;
      const double ddy = std::max(0.0, std::max(boxY0 - p.y, p.y - boxY0 - m_grid.h));
      for (int x = gx - ring; x <= gx + ring; x += (edgeRow || ring == 1) ? 1 : 2 * ring) {
        if (x < 0 || x >= m_grid.nx) continue;
        const size_t c = static_cast<size_t>(y) * m_grid.nx + x;
        if (m_start[c] == m_start[c + 1]) continue;
        const double boxX0 = m_grid.x0 + x * m_grid.h;
        const double ddx = std::max(0.0, std::max(boxX0 - p.x, p.x - boxX0 - m_grid.h));
        const double dMin = std::sqrt(ddx * ddx + ddy * ddy);
        if (dMin > r && dMin * dMin - 2 * r * dMin >= m_cellMaxW[c] - wi) continue;
        for (int k = m_start[c]; k < m_start[c + 1]; ++k) {
          const int j = m_items[static_cast<size_t>(k)];
          if (j == i) continue;
          const P2 dp = m_site[static_cast<size_t>(j)] - p;
          const double d2 = dot(dp, dp);
          if (std::sqrt(d2) * r > 0.5 * (d2 - w[static_cast<size_t>(j)] + wi)) m_candidates.push_back({d2, j});
        }
      }
    }
    std::sort(m_candidates.begin(), m_candidates.end());
    for (const auto& [d2, j] : m_candidates) {
      const P2 dp = m_site[static_cast<size_t>(j)] - p;
      const double rhs = 0.5 * (d2 - w[static_cast<size_t>(j)] + wi);
      if (std::sqrt(d2 * r2) <= rhs) continue;  // every vertex, hence the cell, is on i's side
      bool cuts = false;
      for (int k = 0; k < cur.n && !cuts; ++k) cuts = dot(dp, cur.v[k]) > rhs;
      if (!cuts) continue;
      clip(cur, dp, rhs, j, m_tmp);
      cur = m_tmp;
      if (cur.n == 0) return;
      r2 = maxDistance2(cur);
    }
    const double reach = std::sqrt(r2) + std::sqrt(std::max(0.0, r2 - wi + m_wMax));
    if (reach <= ring * m_grid.h) return;
  }
}

double PowerDiagram::maxDistance2(const Poly& q) {
  double r2 = 0;
  for (int k = 0; k < q.n; ++k) r2 = std::max(r2, dot(q.v[k], q.v[k]));
  return r2;
}

void measureAll(PowerDiagram& diagram, const std::vector<double>& w, const std::vector<P2>& site, CellSet& out) {
  const size_t n = site.size();
  diagram.setWeights(w);
  out.area.assign(n, 0);
  out.perimeter.assign(n, 0);
  out.centroid.assign(n, P2{0, 0});
  out.start.assign(n + 1, 0);
  out.neighbour.clear();
  out.coupling.clear();
  Poly q;
  for (size_t i = 0; i < n; ++i) {
    diagram.cell(static_cast<int>(i), q);
    if (q.n > 0) out.area[i] = area(q), out.centroid[i] = centroid(q);
    for (int k = 0; k < q.n; ++k) {
      const double l = length(q.v[(k + 1) % q.n] - q.v[k]);
      out.perimeter[i] += l;
      const int j = q.label[k];
      if (j < 0 || !(l > 0)) continue;
      out.neighbour.push_back(j);
      out.coupling.push_back(l / (2 * length(site[static_cast<size_t>(j)] - site[i])));
    }
    out.start[i + 1] = static_cast<int>(out.neighbour.size());
  }
}

// Solves L x = g for the weight step (L x)_i = sum_j c_ij (x_i - x_j): conjugate gradients with
// the diagonal as preconditioner. L is singular (a common shift of all weights changes nothing),
// so g is made mean-free; an inexact solve (residual / 10) is all a damped Newton step needs.
std::vector<double> solveLaplacian(const CellSet& cs, std::vector<double> g) {
  const size_t n = g.size();
  const double mean = std::accumulate(g.begin(), g.end(), 0.0) / static_cast<double>(n);
  for (double& v : g) v -= mean;
  std::vector<double> diag(n, 0), x(n, 0), r = g, z(n), p(n), lp(n);
  for (size_t i = 0; i < n; ++i)
    for (int k = cs.start[i]; k < cs.start[i + 1]; ++k) diag[i] += cs.coupling[static_cast<size_t>(k)];
  auto precondition = [&](const std::vector<double>& in, std::vector<double>& out) {
    for (size_t i = 0; i < n; ++i) out[i] = diag[i] > 0 ? in[i] / diag[i] : 0;
  };
  auto dotN = [&](const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0;
    for (size_t i = 0; i < n; ++i) s += a[i] * b[i];
    return s;
  };
  precondition(r, z);
  p = z;
  double rz = dotN(r, z);
  const double stop = 1e-2 * dotN(g, g);
  for (int it = 0; it < 200 && dotN(r, r) > stop; ++it) {
    for (size_t i = 0; i < n; ++i) {
      double s = 0;
      for (int k = cs.start[i]; k < cs.start[i + 1]; ++k)
        s += cs.coupling[static_cast<size_t>(k)] * (p[i] - p[static_cast<size_t>(cs.neighbour[static_cast<size_t>(k)])]);
      lp[i] = s;
    }
    const double pLp = dotN(p, lp);
    if (!(pLp > 0)) break;
    const double alpha = rz / pLp;
    for (size_t i = 0; i < n; ++i) x[i] += alpha * p[i], r[i] -= alpha * lp[i];
    precondition(r, z);
    const double rzNext = dotN(r, z);
    for (size_t i = 0; i < n; ++i) p[i] = z[i] + (rzNext / rz) * p[i];
    rz = rzNext;
  }
  return x;
}

}  // namespace gem::field_detail
