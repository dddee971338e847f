// The random convex field (generateRandomConvexField of field_generator.hpp): a tessellation,
// not random sequential placement of floes (which jams near 50 % and cannot give the thesis 69 %
// field):
//   1. draw the floe areas a_i from the size distribution (stratified quantiles, so that a field
//      of a few hundred floes already has the requested mean and standard deviation);
//   2. give each floe a share of the domain (its size scaled by a common factor, plus the gap) and
//      seed it as a disk of 0.45 of that share, largest first, by random sequential placement in
//      blocks that each receive their area's worth of shares (0.45 is far below jamming);
//   3. take the power (Laguerre) diagram of the disks, weights r_i^2 (each cell then contains its
//      disk), and move the weights by damped Newton steps until every cell has room for its floe;
//   4. each cell, inset by minGap / 2, cut back to an aspect ratio of at most maxAspect and to
//      minSides..maxSides corners, is the container of its floe: the floe is the container shrunk
//      about its centroid to a_i, then turned and shifted at random as far as it stays inside, so
//      low concentrations do not look like a mosaic. Containers are minGap apart, so floes are too.
// Every step is O(N) over uniform grids (sorting the sizes is O(N log N)): 10^4 floes take
// about 0.1 s, 10^6 floes at 40 % about 10 s on one core. The generator computes in double
// whatever gem::Real is: given the same input values, a float build generates the same field,
// rounded once at the end (and every floe is kept valid after rounding to float).
// Shared helpers: field_shared.hpp; shapes: field_polygon.hpp; step 3: power_diagram.hpp.
// Compiled without fused multiply-add or vectorizing, as every generator file (CMakeLists.txt;
// why: field_shared.hpp).

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "framework/field/field_generator.hpp"
#include "framework/field/field_polygon.hpp"
#include "framework/field/field_shared.hpp"
#include "framework/field/floe_size_distribution.hpp"
#include "framework/field/power_diagram.hpp"

namespace gem {
using namespace field_detail;
namespace {

// A container needs room for its floe after corner cuts (vertex count): its estimated area
// (cell area - perimeter * inset) times this must reach the floe's area.
constexpr double kRoomFraction = 0.92;
constexpr int kMaxNewtonSteps = 30;

// Weighted random choice among k items whose weights change: a Fenwick tree of the weights.
class WeightedChoice {
 public:
  explicit WeightedChoice(const std::vector<double>& weight) : m_tree(weight.size() + 1, 0), m_weight(weight.size(), 0) {
    for (size_t i = 0; i < weight.size(); ++i) set(i, weight[i]);
  }
  void set(size_t i, double w) {
    w = std::max(w, 0.0);
    const double delta = w - m_weight[i];
    m_weight[i] = w;
    for (size_t k = i + 1; k < m_tree.size(); k += k & (~k + 1)) m_tree[k] += delta;
  }
  double total() const {
    double s = 0;
    for (size_t k = m_tree.size() - 1; k > 0; k -= k & (~k + 1)) s += m_tree[k];
    return s;
  }
  // The item where the running sum of weights passes u (0 <= u < total).
  size_t find(double u) const {
    size_t pos = 0, step = 1;
    while (step * 2 < m_tree.size()) step *= 2;
    for (; step > 0; step /= 2)
      if (pos + step < m_tree.size() && m_tree[pos + step] <= u) pos += step, u -= m_tree[pos];
    return std::min(pos, m_weight.size() - 1);
  }

 private:
  std::vector<double> m_tree, m_weight;
};

// Random sequential placement of disks, in the given (descending) order. The domain is cut into
// blocks of about kFloesPerBlock shares, and each disk drawn into a block chosen with probability
// proportional to the room the block has left: every block ends up with its area's worth of
// shares. Without this the random density fluctuations of a large field (a few % over hundreds of
// metres) make the power weights of step 3 grow with the domain, and the diagram slow. A disk that
// finds no place in kAttempts tries is shrunk by 10 % and tried again; at a packing fraction of
// 0.45 that is rare.
std::vector<P2> placeDisks(std::vector<double>& radius, const std::vector<double>& share, const Domain& d, const Grid& grid, Random& rng) {
  constexpr int kAttempts = 64;
  constexpr double kFloesPerBlock = 50;
  const size_t n = radius.size();
  const double width = double(d.x1) - d.x0, height = double(d.y1) - d.y0;
  const double block = std::sqrt(kFloesPerBlock * width * height / static_cast<double>(n));
  // At least four of the largest disks across a block.
  const int bx = std::max(1, std::min(static_cast<int>(std::round(width / block)), static_cast<int>(width / (4 * radius[0]))));
  const int by = std::max(1, std::min(static_cast<int>(std::round(height / block)), static_cast<int>(height / (4 * radius[0]))));
  const double bw = width / bx, bh = height / by;
  std::vector<double> room(static_cast<size_t>(bx) * by, bw * bh);
  WeightedChoice choice(room);

  std::vector<P2> centre(n);
  std::vector<int> head(static_cast<size_t>(grid.nx) * grid.ny, -1), next(n, -1);
  for (size_t i = 0; i < n; ++i) {
    const size_t b = choice.find(rng.uniform() * choice.total());
    room[b] -= share[i];
    choice.set(b, room[b]);
    double blockX = d.x0 + bw * static_cast<double>(b % static_cast<size_t>(bx));
    double blockY = d.y0 + bh * static_cast<double>(b / static_cast<size_t>(bx));
    double blockW = bw, blockH = bh;
    for (int attempt = 0;; ++attempt) {
      if (attempt > 0 && attempt % kAttempts == 0) radius[i] *= 0.9;
      if (attempt == 40 * kAttempts) blockX = d.x0, blockY = d.y0, blockW = width, blockH = height;  // never stuck
      const double r = radius[i];
      // Inside the block, and the disk inside the domain where the domain is wide enough.
      const double ax = std::max(blockX, std::min(d.x0 + r, 0.5 * (d.x0 + d.x1)));
      const double bxx = std::max(ax, std::min(blockX + blockW, std::max(d.x1 - r, 0.5 * (d.x0 + d.x1))));
      const double ay = std::max(blockY, std::min(d.y0 + r, 0.5 * (d.y0 + d.y1)));
      const double byy = std::max(ay, std::min(blockY + blockH, std::max(d.y1 - r, 0.5 * (d.y0 + d.y1))));
      const P2 p{rng.uniform(ax, bxx), rng.uniform(ay, byy)};
      const int gx = grid.cx(p.x), gy = grid.cy(p.y);
      bool free = true;
      for (int y = std::max(0, gy - 1); y <= std::min(grid.ny - 1, gy + 1) && free; ++y)
        for (int x = std::max(0, gx - 1); x <= std::min(grid.nx - 1, gx + 1) && free; ++x)
          for (int j = head[static_cast<size_t>(y) * grid.nx + x]; j >= 0; j = next[j]) {
            const P2 dp = centre[j] - p;
            const double rr = radius[j] + r;
            if (dot(dp, dp) < rr * rr) {
              free = false;
              break;
            }
          }
      if (!free) continue;
      centre[i] = p;
      const size_t c = static_cast<size_t>(grid.cell(p));
      next[i] = head[c];
      head[c] = static_cast<int>(i);
      break;
    }
  }
  return centre;
}

// Floe areas that cover exactly target: a_i scaled by one common factor f, but never above the
// room cap_i of its container. f = 1 unless some container is too small.
std::vector<double> fitAreas(const std::vector<double>& a, const std::vector<double>& cap, double target) {
  auto total = [&](double f) {
    double s = 0;
    for (size_t i = 0; i < a.size(); ++i) s += std::min(f * a[i], cap[i]);
    return s;
  };
  double lo = 1, hi = 1;
  if (total(1) < target) {
    if (std::accumulate(cap.begin(), cap.end(), 0.0) < target * (1 - 1e-9)) return {};
    while (total(hi) < target && hi < 1e9) hi *= 2;  // the caps may fall short by rounding only
    for (int it = 0; it < 100; ++it) {
      const double mid = 0.5 * (lo + hi);
      (total(mid) < target ? lo : hi) = mid;
    }
  }
  std::vector<double> out(a.size());
  for (size_t i = 0; i < a.size(); ++i) out[i] = std::min(hi * a[i], cap[i]);
  return out;
}

// Each floe goes to one group, the groups' areas matching their coverages: random order, each
// floe to a group drawn with probability proportional to what the group still lacks (so every
// group spreads over the whole domain), the last tenth largest first to the neediest group (so
// the error ends near the size of a small floe).
std::vector<int> assignGroups(const std::vector<double>& floeArea, const std::vector<ThicknessGroup>& groups, double domainArea,
                              Random& rng) {
  const size_t n = floeArea.size();
  std::vector<double> lack(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) lack[g] = groups[g].coverage * domainArea;
  std::vector<int> order(n), group(n, 0);
  std::iota(order.begin(), order.end(), 0);
  rng.shuffle(order);
  const size_t randomPart = n - n / 10;
  std::sort(order.begin() + static_cast<std::ptrdiff_t>(randomPart), order.end(), [&](int a, int b) {
    return floeArea[static_cast<size_t>(a)] != floeArea[static_cast<size_t>(b)]
               ? floeArea[static_cast<size_t>(a)] > floeArea[static_cast<size_t>(b)]
               : a < b;
  });
  for (size_t k = 0; k < n; ++k) {
    const size_t i = static_cast<size_t>(order[k]);
    size_t g = 0;
    if (k < randomPart) {
      double sum = 0;
      for (double l : lack) sum += std::max(l, 0.0);
      double pick = rng.uniform() * sum;
      g = groups.size() - 1;
      for (size_t c = 0; c < groups.size(); ++c) {
        if (lack[c] <= 0) continue;
        g = c;
        if ((pick -= lack[c]) < 0) break;
      }
    } else {
      g = static_cast<size_t>(std::max_element(lack.begin(), lack.end()) - lack.begin());
    }
    group[i] = static_cast<int>(g);
    lack[g] -= floeArea[i];
  }
  return group;
}

}  // namespace

std::vector<BodySpec> generateRandomConvexField(const RandomFieldSpec& spec) {
  checkDomain(spec.domain);
  checkCommon(spec.concentration, spec.thickness, spec.minGap, spec.groups.empty());
  if (spec.count < 0) fail("field.count: expected a floe count >= 0 (0: from the size distribution), got ", spec.count);
  if (!(spec.sizeMin > 0 && std::isfinite(spec.sizeMin))) fail("field.size_min: expected a positive size in m, got ", spec.sizeMin);
  if (!(spec.sizeMax >= spec.sizeMin && std::isfinite(spec.sizeMax)))
    fail("field.size_max: expected >= field.size_min = ", spec.sizeMin, " m, got ", spec.sizeMax);
  if (!(spec.sizeMean >= spec.sizeMin && spec.sizeMean <= spec.sizeMax))
    fail("field.size_mean: expected within [field.size_min, field.size_max] = [", spec.sizeMin, ", ", spec.sizeMax, "] m, got ",
         spec.sizeMean);
  if (!(spec.sizeSd >= 0 && std::isfinite(spec.sizeSd))) fail("field.size_sd: expected >= 0 m, got ", spec.sizeSd);
  if (spec.minSides < 3 || spec.minSides > kMaxFloeVertices)
    fail("field.min_sides: expected 3 to ", kMaxFloeVertices, ", got ", spec.minSides);
  if (spec.maxSides < spec.minSides || spec.maxSides > kMaxFloeVertices)
    fail("field.max_sides: expected field.min_sides = ", spec.minSides, " to ", kMaxFloeVertices, ", got ", spec.maxSides);
  if (!(spec.maxAspect >= Real(1.2))) fail("field.max_aspect: expected at least 1.2, got ", spec.maxAspect);
  double coverageSum = 0;
  for (size_t g = 0; g < spec.groups.size(); ++g) {
    if (!(spec.groups[g].coverage > 0)) fail("field.groups[", g, "].coverage: expected > 0, got ", spec.groups[g].coverage);
    if (!(spec.groups[g].thickness > 0 && std::isfinite(spec.groups[g].thickness)))
      fail("field.groups[", g, "].thickness: expected a positive thickness in m, got ", spec.groups[g].thickness);
    coverageSum += spec.groups[g].coverage;
  }
  if (!spec.groups.empty() && std::fabs(coverageSum - spec.concentration) > 1e-6)
    fail("field.groups: the coverages sum to ", coverageSum, " but field.concentration is ", spec.concentration);

  const Domain& d = spec.domain;
  const double domainArea = (double(d.x1) - d.x0) * (double(d.y1) - d.y0);
  const double c = spec.concentration, iceArea = c * domainArea;
  const double lo = spec.sizeMin, hi = spec.sizeMax;

  // 1. Floe areas: stratified quantiles of the fitted distribution, largest first.
  SizeDistribution dist = fitSizeDistribution(spec.sizeMean, spec.sizeSd, lo, hi);
  constexpr double kMaxFloes = 1e8;
  const double floes = spec.count > 0 ? spec.count : std::max(1.0, std::round(iceArea / dist.moment(2)));
  if (floes > kMaxFloes)
    fail("field.concentration: this domain would hold ", floes, " floes, more than the ", kMaxFloes,
         " the generator makes; use a smaller [domain] or larger floes");
  const size_t n = static_cast<size_t>(floes);
  const double nd = floes;
  // Equal bounds fix every floe's area: then the count must give the concentration within 0.01.
  const bool reachable = lo < hi ? iceArea > nd * lo * lo * (1 + 1e-9) && iceArea < nd * hi * hi * (1 - 1e-9)
                                 : std::fabs(nd * lo * lo - iceArea) <= 0.01 * domainArea;
  if (!reachable)
    fail("field.concentration: ", c, " of the domain (", iceArea, " m^2) cannot be covered by ", n,
         " floes of size (sqrt of area) within [field.size_min, field.size_max] = [", lo, ", ", hi, "] m");
  if (spec.count > 0 && dist.sigma > 0) {
    // Shift log-size by a common amount (a common size factor before truncation) until the
    // expected total area is the ice area.
    const double mu0 = dist.mu;
    auto expected = [&](double shift) {
      dist.mu = mu0 + shift;
      return nd * dist.moment(2);
    };
    double a = -1, b = 1;
    while (expected(a) > iceArea && a > -1e3) a *= 2;  // bracketed: iceArea is reachable (above)
    while (expected(b) < iceArea && b < 1e3) b *= 2;
    for (int it = 0; it < 200; ++it) {
      const double mid = 0.5 * (a + b);
      (expected(mid) < iceArea ? a : b) = mid;
    }
    dist.mu = mu0 + 0.5 * (a + b);
  } else if (spec.count > 0) {
    dist.mu = std::log(std::clamp(std::sqrt(iceArea / nd), lo, hi));
  }
  Random rng(spec.seed);
  std::vector<double> target(n);  // a_i, m^2
  for (size_t k = 0; k < n; ++k) {
    const double u = (static_cast<double>(n - 1 - k) + rng.uniform()) / static_cast<double>(n);
    const double s = dist.quantile(u);
    target[k] = s * s;
  }
  const double sampled = std::accumulate(target.begin(), target.end(), 0.0);
  for (double& a : target) a *= iceArea / sampled;  // a fraction of a percent: the exact total

  // 2. Each floe's share of the domain: a cell whose size (sqrt of area) is the floe's times a
  // common factor beta, plus the gap. Insetting a roundish cell of size S by delta leaves about
  // (S - 2 delta)^2 (its perimeter is about 4 S), so the gap is shared fairly between small and
  // large floes. beta solves sum (beta s_i + 2 delta)^2 = A, a quadratic.
  const double insetBy = 0.5 * spec.minGap * (1 + 1e-6) + 1e-9;
  std::vector<double> share(n), radius(n);
  {
    double sumS = 0;
    for (double a : target) sumS += std::sqrt(a);
    const double pad = 2 * insetBy, qa = iceArea, qb = 2 * pad * sumS, qc = pad * pad * nd - domainArea;
    if (!(qc < 0)) fail("field.min_gap: ", spec.minGap, " m between ", n, " floes leaves no room for ice in this domain");
    const double beta = (-qb + std::sqrt(qb * qb - 4 * qa * qc)) / (2 * qa);
    for (size_t i = 0; i < n; ++i) {
      const double size = beta * std::sqrt(target[i]) + pad;
      share[i] = size * size;
    }
  }
  // Seed disks, each a fixed fraction of its share.
  constexpr double kDiskFraction = 0.45;
  for (size_t i = 0; i < n; ++i) radius[i] = std::sqrt(kDiskFraction * share[i] / kPiD);
  // Disks: cells no smaller than the largest diameter, so that every disk overlapping a new one
  // has its centre in the 3 x 3 block around it (and no more than about 4 cells per disk).
  const Grid grid(d, std::max(2 * radius[0], std::sqrt(domainArea / (4 * nd))));
  std::vector<P2> site = placeDisks(radius, share, d, grid, rng);

  // Floes renumbered in grid-cell order (a stable counting sort), so that a cell's neighbours sit
  // near it in memory: at 10^6 floes this halves the time.
  const Grid siteGrid(d, std::sqrt(domainArea / nd));  // about one site per cell: rings grow in small steps
  {
    std::vector<size_t> bucket(static_cast<size_t>(siteGrid.nx) * siteGrid.ny + 1, 0), order(n);
    for (const P2& p : site) ++bucket[static_cast<size_t>(siteGrid.cell(p)) + 1];
    std::partial_sum(bucket.begin(), bucket.end(), bucket.begin());
    for (size_t i = 0; i < n; ++i) order[bucket[static_cast<size_t>(siteGrid.cell(site[i]))]++] = i;
    auto permute = [&](auto& v) {
      auto copy = v;
      for (size_t k = 0; k < n; ++k) v[k] = copy[order[k]];
    };
    permute(site), permute(target), permute(share), permute(radius);
  }

  // 3. Power diagram; its weights by damped Newton steps (Kitagawa, Merigot and Thibert 2019:
  // the cell areas as a function of the weights are the gradient of a concave function, and a
  // step halved until no cell shrinks below half its area or target converges from any start
  // with non-empty cells), until every cell has room for its floe.
  std::vector<double> w(n);
  for (size_t i = 0; i < n; ++i) w[i] = radius[i] * radius[i];
  PowerDiagram diagram(site, d, siteGrid);
  CellSet cells, trial;
  auto misfits = [&](const CellSet& cs) {
    size_t count = 0;
    for (size_t i = 0; i < n; ++i) count += target[i] > kRoomFraction * (cs.area[i] - cs.perimeter[i] * insetBy);
    return count;
  };
  auto residual = [&](const CellSet& cs) {
    double r = 0;
    for (size_t i = 0; i < n; ++i) r += (share[i] - cs.area[i]) * (share[i] - cs.area[i]);
    return std::sqrt(r);
  };
  std::vector<double> gradient(n), direction, wTrial(n);
  measureAll(diagram, w, site, cells);
  // A few misfits in a large field are left to fitAreas (their floes a little smaller).
  for (int iteration = 0; iteration < kMaxNewtonSteps && misfits(cells) > n / 2000; ++iteration) {
    for (size_t i = 0; i < n; ++i) gradient[i] = share[i] - cells.area[i];
    direction = solveLaplacian(cells, gradient);
    const double before = residual(cells);
    bool accepted = false;
    for (double alpha = 1; alpha > 1e-3 && !accepted; alpha *= 0.5) {
      for (size_t i = 0; i < n; ++i) wTrial[i] = w[i] + alpha * direction[i];
      measureAll(diagram, wTrial, site, trial);
      accepted = residual(trial) <= (1 - 0.5 * alpha) * before;
      for (size_t i = 0; i < n && accepted; ++i) accepted = trial.area[i] >= 0.5 * std::min(cells.area[i], share[i]);
    }
    if (!accepted) break;  // cannot happen in exact arithmetic; the containers below cope
    w.swap(wTrial);
    std::swap(cells, trial);
  }

  // 4. Containers, floe areas, floes.
  diagram.setWeights(w);
  std::vector<P2> containerVertex;
  std::vector<int> containerStart(n + 1, 0);
  std::vector<double> room(n);
  Poly cell;
  containerVertex.reserve(n * static_cast<size_t>(spec.maxSides));
  Poly shrunk;
  // Rounding the output to float moves a vertex by up to eps |x|: features 16 times that survive.
  // (float whatever Real is, so that float and double builds generate the same field.)
  const double roundingTol = 16 * std::numeric_limits<float>::epsilon() *
                             std::max({std::fabs(double(d.x0)), std::fabs(double(d.x1)), std::fabs(double(d.y0)), std::fabs(double(d.y1))});
  for (size_t i = 0; i < n; ++i) {
    diagram.cell(static_cast<int>(i), cell);
    inset(cell, insetBy, shrunk);
    // The floe is this container shrunk by at least sqrt(a_i / room): its features are kept
    // above the rounding tolerance after that shrinking.
    const double minFeature = std::max(1e-4 * std::sqrt(target[i]), roundingTol * std::sqrt(std::max(1.0, area(shrunk) / target[i])));
    // Cutting corners can lengthen a polygon and trimming adds corners: twice each settles both.
    // Half the many-sided cells are cut to one corner fewer than allowed, so that the largest
    // floes (the cells with most neighbours) are not all maxSides-gons.
    const int preferred = std::max(spec.minSides, spec.maxSides - static_cast<int>(rng.below(2)));
    for (int pass = 0; pass < 2; ++pass) {
      trimToAspect(shrunk, spec.maxAspect);
      cleanup(shrunk, minFeature);
      fitVertexCount(shrunk, spec.minSides, spec.maxSides, pass == 0 ? preferred : spec.maxSides, target[i] / kRoomFraction);
    }
    room[i] = shrunk.n > 0 ? area(shrunk) : 0;
    for (int k = 0; k < shrunk.n; ++k) containerVertex.push_back(site[i] + shrunk.v[k]);
    containerStart[i + 1] = static_cast<int>(containerVertex.size());
  }
  const std::vector<double> floeArea = fitAreas(target, room, iceArea);
  if (floeArea.empty() || *std::min_element(floeArea.begin(), floeArea.end()) <= 0)
    fail("field.concentration: ", c, " with ", n, " floes at least field.min_gap = ", spec.minGap,
         " m apart could not be reached in this domain; lower it or field.min_gap, or raise field.max_sides");

  std::vector<int> group;
  if (!spec.groups.empty()) group = assignGroups(floeArea, spec.groups, domainArea, rng);

  std::vector<BodySpec> result;
  std::vector<P2> resultCentre;
  result.reserve(n);
  resultCentre.reserve(n);
  Poly container;
  P2 floe[kPolyCapacity], moved[kPolyCapacity];
  for (size_t i = 0; i < n; ++i) {
    container.n = 0;
    for (int k = containerStart[i]; k < containerStart[i + 1]; ++k) container.push(containerVertex[static_cast<size_t>(k)], -1);
    const P2 centre = centroid(container);
    const double scale = std::sqrt(floeArea[i] / room[i]);
    for (int k = 0; k < container.n; ++k) floe[k] = centre + scale * (container.v[k] - centre);
    // Random turn and shift within the container, smaller at each try; kept only if it fits.
    if (scale < 0.98) {
      const double reach = (1 - scale) * std::sqrt(room[i]);
      for (int attempt = 0; attempt < 8; ++attempt) {
        const double amplitude = 1 - attempt / 8.0;
        const double turn = amplitude * rng.uniform(-0.5, 0.5) * kTwoPi;
        const P2 shift{amplitude * reach * rng.uniform(-0.5, 0.5), amplitude * reach * rng.uniform(-0.5, 0.5)};
        const double ct = std::cos(turn), st = std::sin(turn);
        for (int k = 0; k < container.n; ++k) moved[k] = centre + shift + rotated(floe[k] - centre, ct, st);
        if (containsAll(container, moved, container.n)) {
          std::copy(moved, moved + container.n, floe);
          break;
        }
      }
    }
    const Real thickness = group.empty() ? spec.thickness : spec.groups[static_cast<size_t>(group[i])].thickness;
    result.push_back(makeFloe(floe, container.n, thickness));
    resultCentre.push_back(centroid(floe, container.n));
    if (!isStrictlyConvexCCW(result.back().vertices.data(), container.n))
      throw std::logic_error("field generator: a floe is not strictly convex after rounding");
  }
  sortAlongX(result, resultCentre);
  return result;
}

}  // namespace gem
