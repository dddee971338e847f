// The hexagon field (thesis 6.2.1.1.1): a regular array of equal, slightly rotated hexagons,
// the layout chosen nearest a regular lattice within the concentration tolerance, or among the nx by ny
// arrays of exactly field.count hexagons.
// Compiled without fused multiply-add or vectorizing, as every generator file (CMakeLists.txt;
// why: field_shared.hpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "framework/field/field_generator.hpp"
#include "framework/field/field_polygon.hpp"
#include "framework/field/field_shared.hpp"

namespace gem {
using namespace field_detail;
namespace {

// Distance lower bound between two convex polygons: the widest gap along an edge normal of either
// (exact when the nearest features include an edge, as for neighbouring hexagons).
double separation(const P2* p, int n, const P2* q, int m) {
  double best = -std::numeric_limits<double>::infinity();
  for (int pass = 0; pass < 2; ++pass) {
    const P2* a = pass == 0 ? p : q;
    const P2* b = pass == 0 ? q : p;
    const int na = pass == 0 ? n : m, nb = pass == 0 ? m : n;
    for (int k = 0; k < na; ++k) {
      const P2 e = a[(k + 1) % na] - a[k];
      const P2 out = (1 / length(e)) * P2{e.y, -e.x};  // outward for counter-clockwise a
      double maxA = -std::numeric_limits<double>::infinity(), minB = std::numeric_limits<double>::infinity();
      for (int i = 0; i < na; ++i) maxA = std::max(maxA, dot(out, a[i]));
      for (int i = 0; i < nb; ++i) minB = std::min(minB, dot(out, b[i]));
      best = std::max(best, minB - maxA);
    }
  }
  return best;
}

struct HexLayout {
  int nx, ny;
  double concentrationError, distortion;
};

}  // namespace

std::vector<BodySpec> generateHexagonField(const HexagonFieldSpec& spec) {
  checkDomain(spec.domain);
  checkCommon(spec.concentration, spec.thickness, spec.minGap, true);
  if (!(spec.size > 0 && std::isfinite(spec.size))) fail("field.size: expected a positive size in m, got ", spec.size);
  if (!(spec.rotationJitterDeg >= 0 && spec.rotationJitterDeg <= 30))
    fail("field.rotation_jitter_deg: expected 0 to 30 degrees, got ", spec.rotationJitterDeg);

  const Domain& d = spec.domain;
  const double width = double(d.x1) - d.x0, height = double(d.y1) - d.y0, domainArea = width * height;
  const double hexArea = double(spec.size) * spec.size;
  const double circumradius = std::sqrt(2 * hexArea / (3 * std::sqrt(3.0)));
  const double ideal = spec.concentration * domainArea / hexArea;
  // Rows along x, odd rows shifted by half a cell; hexagons with a vertex up, so that at 100 %
  // cover the lattice is dx = sqrt(3) a, dy = 1.5 a. The nx by ny array is spread over the whole
  // domain (the concentration is N A_hex / A_domain whatever the spacing); the layout chosen is
  // the one nearest a regular lattice among those within half the tolerance of the concentration.
  const double regularAspect = std::sqrt(3.0) / 1.5;
  // Half a row spacing to the edge, unless the vertex on top needs more.
  const double margin = 0.5 * spec.minGap;
  auto rowMargin = [&](int ny) { return std::max(0.5 * height / ny, circumradius + margin); };
  auto rowSpacing = [&](int ny) { return ny > 1 ? (height - 2 * rowMargin(ny)) / (ny - 1) : height; };
  std::vector<HexLayout> layouts;
  if (spec.count < 0) fail("field.count: expected a count >= 0, got ", spec.count);
  if (spec.count > 0 && std::fabs(double(spec.count) * hexArea / domainArea - spec.concentration) > 0.01)
    fail("field.count: ", spec.count, " hexagons of field.size = ", spec.size, " m cover ", double(spec.count) * hexArea / domainArea,
         " of the domain, more than 0.01 from field.concentration = ", spec.concentration);
  for (int ny = 1; height / ny >= circumradius; ++ny) {
    if (spec.count > 0 && spec.count % ny != 0) continue;
    const int around = spec.count > 0 ? spec.count / ny : static_cast<int>(std::round(ideal / ny));
    for (int nx = std::max(1, around - 2); nx <= around + 2; ++nx) {
      if (spec.count > 0 && nx * ny != spec.count) continue;
      const double error = std::fabs(double(nx) * ny * hexArea / domainArea - spec.concentration);
      if (error > 0.01) continue;
      const double dx = width / (nx + (ny > 1 ? 0.5 : 0.0));
      layouts.push_back({nx, ny, error, std::fabs(std::log(dx / rowSpacing(ny) / regularAspect))});
    }
  }
  // Within half the tolerance, the most regular lattice; then the closest concentration.
  std::sort(layouts.begin(), layouts.end(), [](const HexLayout& a, const HexLayout& b) {
    const bool aClose = a.concentrationError <= 0.005, bClose = b.concentrationError <= 0.005;
    if (aClose != bClose) return aClose;
    if (a.distortion != b.distortion) return a.distortion < b.distortion;
    if (a.concentrationError != b.concentrationError) return a.concentrationError < b.concentrationError;
    return a.ny < b.ny;
  });

  for (const HexLayout& layout : layouts) {
    const int nx = layout.nx, ny = layout.ny;
    const double offset = ny > 1 ? 0.5 : 0.0;
    const double dx = width / (nx + offset), dy = rowSpacing(ny);
    const double y0 = ny > 1 ? d.y0 + rowMargin(ny) : 0.5 * (d.y0 + d.y1);
    Random rng(spec.seed);
    std::vector<P2> v(static_cast<size_t>(nx) * ny * 6);
    bool inside = true;
    for (int r = 0; r < ny; ++r)
      for (int i = 0; i < nx; ++i) {
        const P2 centre{d.x0 + dx * (i + 0.5 + offset * (r % 2)), y0 + dy * r};
        const double turn = rng.uniform(-1, 1) * spec.rotationJitterDeg * kPiD / 180;
        P2* hex = &v[(static_cast<size_t>(r) * nx + i) * 6];
        for (int k = 0; k < 6; ++k) {
          const double angle = kPiD / 6 + k * kPiD / 3 + turn;
          hex[k] = centre + circumradius * P2{std::cos(angle), std::sin(angle)};
          inside =
              inside && hex[k].x >= d.x0 + margin && hex[k].x <= d.x1 - margin && hex[k].y >= d.y0 + margin && hex[k].y <= d.y1 - margin;
        }
      }
    if (!inside) continue;
    // Rotated neighbours must still keep the gap: the next in the row, the two touching it in
    // the next row, and the one two rows up.
    auto at = [&](int r, int i) { return &v[(static_cast<size_t>(r) * nx + i) * 6]; };
    auto apart = [&](int r, int i, int r2, int i2) {
      if (r2 >= ny || i2 < 0 || i2 >= nx) return true;
      return separation(at(r, i), 6, at(r2, i2), 6) >= spec.minGap;
    };
    bool separated = true;
    for (int r = 0; r < ny && separated; ++r)
      for (int i = 0; i < nx && separated; ++i) {
        const int left = r % 2 == 0 ? i - 1 : i;  // the lower of the two neighbours in the next row
        separated = apart(r, i, r, i + 1) && apart(r, i, r + 1, left) && apart(r, i, r + 1, left + 1) && apart(r, i, r + 2, i);
      }
    if (!separated) continue;
    std::vector<BodySpec> floes;
    std::vector<P2> centre;
    floes.reserve(static_cast<size_t>(nx) * ny);
    for (size_t h = 0; h < static_cast<size_t>(nx) * ny; ++h) {
      floes.push_back(makeFloe(&v[h * 6], 6, spec.thickness));
      centre.push_back(centroid(&v[h * 6], 6));
    }
    sortAlongX(floes, centre);
    return floes;
  }
  if (spec.count > 0)
    fail("field.count: ", spec.count, " hexagons of field.size = ", spec.size,
         " m fit in no nx by ny array of this domain, at least field.min_gap = ", spec.minGap, " m apart");
  fail("field.concentration: ", spec.concentration, " cannot be reached within 0.01 by hexagons of field.size = ", spec.size,
       " m in this domain, at least field.min_gap = ", spec.minGap, " m apart");
}

}  // namespace gem
