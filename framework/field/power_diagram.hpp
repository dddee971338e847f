// The power (Laguerre) diagram of the random field's weighted sites over uniform grids, the cell
// measures and the Laplacian solve of its damped Newton weight iteration. Internal to framework/field/.
#pragma once
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "framework/field/field_polygon.hpp"

namespace gem::field_detail {

// Uniform grid of square cells of side h over the domain.
struct Grid {
  double x0 = 0, y0 = 0, h = 1;
  int nx = 1, ny = 1;
  Grid(const Domain& d, double cell) : x0(d.x0), y0(d.y0), h(cell) {
    nx = std::max(1, static_cast<int>(std::ceil((double(d.x1) - d.x0) / h)));
    ny = std::max(1, static_cast<int>(std::ceil((double(d.y1) - d.y0) / h)));
  }
  int cx(double x) const { return std::clamp(static_cast<int>((x - x0) / h), 0, nx - 1); }
  int cy(double y) const { return std::clamp(static_cast<int>((y - y0) / h), 0, ny - 1); }
  int cell(P2 p) const { return cy(p.y) * nx + cx(p.x); }
};

// The power diagram of weighted sites, clipped to the domain, one cell at a time: the domain
// rectangle cut by the power bisector of every site that can reach it, nearest first.
class PowerDiagram {
 public:
  PowerDiagram(const std::vector<P2>& site, const Domain& d, const Grid& grid) : m_site(site), m_domain(d), m_grid(grid) { rebuild(); }

  // Sites bucketed by grid cell (counting sort: deterministic order within a cell); again after
  // the sites moved.
  void rebuild();

  // The weights for the cells that follow; per grid cell their maximum, so that whole grid cells
  // too far for their heaviest site are skipped.
  void setWeights(const std::vector<double>& w);

  // Cell of site i in coordinates relative to the site. Site j cuts the cell only where its power
  // |x - p_j|^2 - w_j is below |x - p_i|^2 - w_i; with R the cell's largest vertex distance, that
  // needs |p_j - p_i|^2 - 2 R |p_j - p_i| < w_j - w_i, so the rings searched end at
  // R + sqrt(R^2 - w_i + wMax).
  void cell(int i, Poly& out);

 private:
  static double maxDistance2(const Poly& q);

  const std::vector<P2>& m_site;
  Domain m_domain;
  const Grid& m_grid;
  std::vector<int> m_start, m_items;
  const std::vector<double>* m_w = nullptr;
  std::vector<double> m_cellMaxW;
  double m_wMax = 0;
  std::vector<std::pair<double, int>> m_candidates;
  Poly m_tmp;
};

// Every cell's area and perimeter, and its couplings to its neighbours: moving w_i by dw moves
// the bisector with site j by dw / (2 |p_i - p_j|), so d(area_i)/d(w_j) = -l_ij / (2 |p_i - p_j|)
// for an edge of length l_ij, and d(area_i)/d(w_i) is minus their sum: a graph Laplacian.
struct CellSet {
  std::vector<double> area, perimeter;
  std::vector<P2> centroid;  // relative to the site
  std::vector<int> start, neighbour;
  std::vector<double> coupling;
};

void measureAll(PowerDiagram& diagram, const std::vector<double>& w, const std::vector<P2>& site, CellSet& out);

// Solves L x = g for the weight step (L x)_i = sum_j c_ij (x_i - x_j): conjugate gradients with
// the diagonal as preconditioner. L is singular (a common shift of all weights changes nothing),
// so g is made mean-free; an inexact solve (residual / 10) is all a damped Newton step needs.
std::vector<double> solveLaplacian(const CellSet& cs, std::vector<double> g);

}  // namespace gem::field_detail
