// The helpers both field generators share (field_shared.hpp): the input checks of the domain and
// the common keys, and the BodySpec output with its ordering along x.
// Compiled without fused multiply-add or vectorizing, as every generator file (CMakeLists.txt;
// why: field_shared.hpp).

#include "framework/field/field_shared.hpp"

#include <algorithm>
#include <numeric>

namespace gem::field_detail {

void checkDomain(const Domain& d) {
  if (!(std::isfinite(d.x0) && std::isfinite(d.x1) && d.x1 > d.x0))
    fail("domain.x: expected [x0, x1] with x0 < x1, got [", d.x0, ", ", d.x1, "]");
  if (!(std::isfinite(d.y0) && std::isfinite(d.y1) && d.y1 > d.y0))
    fail("domain.y: expected [y0, y1] with y0 < y1, got [", d.y0, ", ", d.y1, "]");
}

void checkCommon(Real concentration, Real thickness, Real minGap, bool thicknessUsed) {
  if (!(concentration > 0 && concentration < Real(0.9))) fail("field.concentration: expected a fraction in (0, 0.9), got ", concentration);
  if (thicknessUsed && !(thickness > 0 && std::isfinite(thickness)))
    fail("field.thickness: expected a positive thickness in m, got ", thickness);
  if (!(minGap >= 0 && std::isfinite(minGap))) fail("field.min_gap: expected >= 0 m, got ", minGap);
}

BodySpec makeFloe(const P2* v, int n, Real thickness) {
  BodySpec b;
  b.kind = BodyKind::Floe;
  b.vertices.reserve(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) b.vertices.push_back(Vec2{static_cast<Real>(v[k].x), static_cast<Real>(v[k].y)});
  b.thickness = thickness;
  b.origin = "field";
  return b;
}

// Along x, then y, of the centroids (computed before rounding, so a float build orders alike):
// ids then grow along the vessel's track.
void sortAlongX(std::vector<BodySpec>& floes, const std::vector<P2>& centre) {
  std::vector<size_t> order(floes.size());
  std::iota(order.begin(), order.end(), size_t(0));
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (centre[a].x != centre[b].x) return centre[a].x < centre[b].x;
    if (centre[a].y != centre[b].y) return centre[a].y < centre[b].y;
    return a < b;
  });
  std::vector<BodySpec> sorted;
  sorted.reserve(floes.size());
  for (size_t k : order) sorted.push_back(std::move(floes[k]));
  floes.swap(sorted);
}

}  // namespace gem::field_detail
