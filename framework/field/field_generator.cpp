// Pack-ice field generation. The random field is a tessellation, not random sequential placement
// of floes (which jams near 50 % and cannot give the thesis 69 % field):
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
// No fused multiply-add here, so that the same seed gives the same field whatever the target
// flags (-march with FMA otherwise changes the rounding; GCC 12 fuses a*b - c*d pairs through the
// vectorizer even with fp-contract off, hence the second switch).
#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off", "no-tree-vectorize")
#endif

#include "framework/field/field_generator.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>

#include "framework/api/errors.hpp"

namespace gem {
namespace {

// In double, not gem::Real: the field must not depend on the engine's precision.
constexpr double kPiD = 3.14159265358979323846;
constexpr double kTwoPi = 2 * kPiD;

struct P2 {
  double x, y;
};
inline P2 operator+(P2 a, P2 b) { return {a.x + b.x, a.y + b.y}; }
inline P2 operator-(P2 a, P2 b) { return {a.x - b.x, a.y - b.y}; }
inline P2 operator*(double s, P2 a) { return {s * a.x, s * a.y}; }
inline double dot(P2 a, P2 b) { return a.x * b.x + a.y * b.y; }
inline double cross(P2 a, P2 b) { return a.x * b.y - a.y * b.x; }
inline double length(P2 a) { return std::sqrt(dot(a, a)); }
inline P2 rotated(P2 a, double c, double s) { return {c * a.x - s * a.y, s * a.x + c * a.y}; }

// ---------------------------------------------------------------------------------------------
// Random numbers. std::mt19937_64's output is fixed by the standard; the standard distributions
// are not, so the few we need are built here from its raw bits.
class Random {
 public:
  explicit Random(std::uint64_t seed) : m_engine(seed) {}
  double uniform() { return static_cast<double>(m_engine() >> 11) * 0x1.0p-53; }  // [0, 1)
  double uniform(double a, double b) { return a + (b - a) * uniform(); }
  std::uint64_t below(std::uint64_t n) {  // [0, n), unbiased by rejection
    const std::uint64_t limit = std::numeric_limits<std::uint64_t>::max() -
                                std::numeric_limits<std::uint64_t>::max() % n;
    std::uint64_t r;
    do r = m_engine(); while (r >= limit);
    return r % n;
  }
  template <class T>
  void shuffle(std::vector<T>& v) {  // Fisher-Yates
    for (size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[below(i)]);
  }

 private:
  std::mt19937_64 m_engine;
};

// ---------------------------------------------------------------------------------------------
// The size distribution: lognormal in s = sqrt(area), truncated to [lo, hi].
double normalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// Inverse of normalCdf: Acklam's rational approximation, polished by one Halley step (|error|
// about 1e-15).
double normalQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02, -2.759285104469687e+02,
                             1.383577518672690e+02, -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02,
                             6.680131188771972e+01, -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00, 2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00,
                             3.754408661907416e+00};
  p = std::clamp(p, 1e-300, 1 - 1e-16);
  double x;
  if (p < 0.02425 || p > 1 - 0.02425) {
    const double q = std::sqrt(-2 * std::log(p < 0.5 ? p : 1 - p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
        ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
    if (p > 0.5) x = -x;
  } else {
    const double q = p - 0.5, r = q * q;
    x = (((((a[0] * r + a[1]) * r + a[2]) * r + a[3]) * r + a[4]) * r + a[5]) * q /
        (((((b[0] * r + b[1]) * r + b[2]) * r + b[3]) * r + b[4]) * r + 1);
  }
  const double e = normalCdf(x) - p;
  const double u = e * std::sqrt(kTwoPi) * std::exp(0.5 * x * x);
  return x - u / (1 + 0.5 * x * u);
}

// Probability mass of the standard normal between z1 < z2, from the nearer tail so that ranges
// far out in one tail keep their precision.
double normalMass(double z1, double z2) {
  return z1 >= 0 ? normalCdf(-z1) - normalCdf(-z2) : normalCdf(z2) - normalCdf(z1);
}

struct SizeDistribution {
  double mu = 0, sigma = 0, lo = 0, hi = 0;

  // Raw moment E[s^k] of the truncated distribution (closed form for the lognormal).
  double moment(int k) const {
    if (sigma <= 0) return std::pow(std::clamp(std::exp(mu), lo, hi), k);
    const double za = (std::log(lo) - mu) / sigma, zb = (std::log(hi) - mu) / sigma;
    const double mass = normalMass(za, zb);
    if (!(mass > 1e-300)) return std::pow(za > 0 ? lo : hi, k);  // all of it beyond one bound
    return std::exp(k * mu + 0.5 * k * k * sigma * sigma) * normalMass(za - k * sigma, zb - k * sigma) / mass;
  }
  // The size at cumulative probability u of the truncated distribution.
  double quantile(double u) const {
    if (sigma <= 0) return std::clamp(std::exp(mu), lo, hi);
    const double za = (std::log(lo) - mu) / sigma, zb = (std::log(hi) - mu) / sigma;
    double z;
    if (za >= 0) {  // the whole range in the upper tail: work with upper-tail probabilities
      const double qa = normalCdf(-za), qb = normalCdf(-zb);
      if (!(qa - qb > 1e-300)) return lo;
      z = -normalQuantile(qa - u * (qa - qb));
    } else {
      const double pa = normalCdf(za), pb = normalCdf(zb);
      if (!(pb - pa > 1e-300)) return hi;
      z = normalQuantile(pa + u * (pb - pa));
    }
    return std::clamp(std::exp(mu + sigma * z), lo, hi);
  }
  double mean() const { return moment(1); }
  double sd() const { return std::sqrt(std::max(0.0, moment(2) - moment(1) * moment(1))); }
};

// Lognormal parameters whose truncation to [lo, hi] has the requested mean and sd: start from the
// untruncated match and correct (truncation at 2 and 20 m shifts the thesis moments by a few %).
SizeDistribution fitSizeDistribution(double mean, double sd, double lo, double hi) {
  SizeDistribution dist{std::log(mean), 0, lo, hi};
  if (sd <= 0 || lo == hi) return dist;
  const double cv = sd / mean;
  dist.sigma = std::sqrt(std::log(1 + cv * cv));
  dist.mu = std::log(mean) - 0.5 * dist.sigma * dist.sigma;
  for (int it = 0; it < 200; ++it) {
    const double m = dist.mean(), s = dist.sd();
    if (std::fabs(m / mean - 1) < 1e-12 && std::fabs(s / sd - 1) < 1e-12) break;
    dist.mu += std::log(mean / m);
    // A cv beyond what the range allows cannot be met; the cap stops sigma from running away.
    if (s > 0) dist.sigma = std::min(10.0, dist.sigma * std::clamp(cv / (s / m), 0.5, 2.0));
  }
  return dist;
}

// ---------------------------------------------------------------------------------------------
// Input checks: messages name the scenario key; the scenario loader adds the file.
template <class... Args>
[[noreturn]] void fail(const Args&... parts) {
  std::ostringstream out;
  (out << ... << parts);
  throw InputError(out.str());
}

void checkDomain(const Domain& d) {
  if (!(std::isfinite(d.x0) && std::isfinite(d.x1) && d.x1 > d.x0))
    fail("domain.x: expected [x0, x1] with x0 < x1, got [", d.x0, ", ", d.x1, "]");
  if (!(std::isfinite(d.y0) && std::isfinite(d.y1) && d.y1 > d.y0))
    fail("domain.y: expected [y0, y1] with y0 < y1, got [", d.y0, ", ", d.y1, "]");
}

void checkCommon(Real concentration, Real thickness, Real minGap, bool thicknessUsed) {
  if (!(concentration > 0 && concentration < Real(0.9)))
    fail("field.concentration: expected a fraction in (0, 0.9), got ", concentration);
  if (thicknessUsed && !(thickness > 0 && std::isfinite(thickness)))
    fail("field.thickness: expected a positive thickness in m, got ", thickness);
  if (!(minGap >= 0 && std::isfinite(minGap))) fail("field.min_gap: expected >= 0 m, got ", minGap);
}

// ---------------------------------------------------------------------------------------------
// Small convex polygons: fixed capacity, each edge labelled with the site that made it (-1: the
// domain boundary), so that a power cell knows its neighbours.
constexpr int kPolyCapacity = 64;

struct Poly {
  int n = 0;
  P2 v[kPolyCapacity];
  int label[kPolyCapacity];
  void push(P2 p, int l) {
    if (n == kPolyCapacity) throw std::logic_error("field generator: polygon capacity exceeded");
    v[n] = p;
    label[n++] = l;
  }
};

double area(const Poly& q) {
  double twice = 0;
  for (int k = 0; k < q.n; ++k) twice += cross(q.v[k], q.v[(k + 1) % q.n]);
  return 0.5 * twice;
}

P2 centroid(const P2* v, int n) {  // relative to vertex 0, as areaCentroid in geometry/polygon.hpp
  const P2 o = v[0];
  double twice = 0, cx = 0, cy = 0;
  for (int k = 0; k < n; ++k) {
    const P2 a = v[k] - o, b = v[(k + 1) % n] - o;
    const double ak = cross(a, b);
    twice += ak;
    cx += (a.x + b.x) * ak;
    cy += (a.y + b.y) * ak;
  }
  return twice > 0 ? P2{o.x + cx / (3 * twice), o.y + cy / (3 * twice)} : o;
}
P2 centroid(const Poly& q) { return centroid(q.v, q.n); }

// Sutherland-Hodgman against one half-plane dot(a, x) <= b. A vertex carries the label of the
// edge that starts at it; the cut edge gets `label`.
void clip(const Poly& in, P2 a, double b, int label, Poly& out) {
  out.n = 0;
  for (int k = 0; k < in.n; ++k) {
    const P2 cur = in.v[k], nxt = in.v[(k + 1) % in.n];
    const double dc = dot(a, cur) - b, dn = dot(a, nxt) - b;
    if (dc <= 0) out.push(cur, in.label[k]);
    if ((dc <= 0) != (dn <= 0)) {
      const P2 x = cur + (dc / (dc - dn)) * (nxt - cur);
      out.push(x, dc <= 0 ? label : in.label[k]);
    }
  }
  if (out.n < 3) out.n = 0;
}

// The points of q at least delta from its boundary: q clipped by each edge moved inwards.
void inset(const Poly& q, double delta, Poly& out) {
  Poly work = q, tmp;
  for (int k = 0; k < q.n && work.n > 0; ++k) {
    const P2 e = q.v[(k + 1) % q.n] - q.v[k];
    const double l = length(e);
    if (!(l > 0)) continue;
    const P2 inward{-e.y / l, e.x / l};
    clip(work, -1.0 * inward, -(delta + dot(inward, q.v[k])), q.label[k], tmp);
    work = tmp;
  }
  out = work;
}

// Removes vertices that would make the polygon fail a strict convexity test after rounding to
// Real: edges shorter than minEdge, corners less than minEdge above the chord of their
// neighbours, and turns with sine below kMinTurnSine. Removing a vertex of a convex polygon cuts a
// corner, so the result stays inside the original.
constexpr double kMinTurnSine = 1e-3;

void cleanup(Poly& q, double minEdge) {
  bool changed = true;
  while (changed && q.n >= 3) {
    changed = false;
    for (int k = 0; k < q.n && q.n >= 3; ++k) {
      const P2 prev = q.v[(k + q.n - 1) % q.n], cur = q.v[k], nxt = q.v[(k + 1) % q.n];
      const P2 e0 = cur - prev, e1 = nxt - cur;
      const double l0 = length(e0), l1 = length(e1), turn = cross(e0, e1);
      if (l1 < minEdge || turn <= kMinTurnSine * l0 * l1 || turn <= minEdge * length(nxt - prev)) {
        std::copy(q.v + k + 1, q.v + q.n, q.v + k);
        std::copy(q.label + k + 1, q.label + q.n, q.label + k);
        --q.n;
        changed = true;
      }
    }
  }
  if (q.n < 3) q.n = 0;
}

// Brings the vertex count into [minSides, maxSides]: above, cut the corner of least area; below,
// chamfer the sharpest corner (new vertices a fifth of the way along its edges). Both keep the
// polygon convex and inside the original. Corners are also cut down towards `preferred` sides as
// long as the area stays above keepArea: a large power cell has many neighbours, and without this
// every large floe would be a near-regular heptagon.
void fitVertexCount(Poly& q, int minSides, int maxSides, int preferred, double keepArea) {
  double currentArea = area(q);
  while (q.n > maxSides || (q.n > preferred && q.n > minSides)) {
    int best = 0;
    double bestArea = std::numeric_limits<double>::infinity();
    for (int k = 0; k < q.n; ++k) {
      const double a = 0.5 * cross(q.v[k] - q.v[(k + q.n - 1) % q.n], q.v[(k + 1) % q.n] - q.v[k]);
      if (a < bestArea) bestArea = a, best = k;
    }
    if (q.n <= maxSides && currentArea - bestArea < keepArea) break;
    currentArea -= bestArea;
    std::copy(q.v + best + 1, q.v + q.n, q.v + best);
    std::copy(q.label + best + 1, q.label + q.n, q.label + best);
    --q.n;
  }
  while (q.n > 0 && q.n < minSides) {
    int best = 0;
    double bestCos = -2;
    for (int k = 0; k < q.n; ++k) {
      const P2 a = q.v[(k + q.n - 1) % q.n] - q.v[k], b = q.v[(k + 1) % q.n] - q.v[k];
      const double c = dot(a, b) / (length(a) * length(b));
      if (c > bestCos) bestCos = c, best = k;
    }
    const P2 cur = q.v[best], prev = q.v[(best + q.n - 1) % q.n], nxt = q.v[(best + 1) % q.n];
    std::copy_backward(q.v + best + 1, q.v + q.n, q.v + q.n + 1);
    std::copy_backward(q.label + best + 1, q.label + q.n, q.label + q.n + 1);
    ++q.n;
    q.v[best] = cur + 0.2 * (prev - cur);
    q.v[best + 1] = cur + 0.2 * (nxt - cur);
    q.label[best + 1] = q.label[best];
  }
}

// Natural floes are seldom longer than two to three times their width, but a small power cell
// squeezed between large ones can be a sliver. Such a container is cut back across its long
// axis, symmetrically about its centroid, until sqrt(largest / smallest principal second
// moment) (the length / width of a rectangle) is at most maxAspect.
void trimToAspect(Poly& q, double maxAspect) {
  Poly tmp;
  for (int pass = 0; pass < 6 && q.n >= 3; ++pass) {
    const P2 c = centroid(q);
    double sxx = 0, syy = 0, sxy = 0;  // second moments about the centroid (times 12)
    for (int k = 0; k < q.n; ++k) {
      const P2 a = q.v[k] - c, b = q.v[(k + 1) % q.n] - c;
      const double ak = cross(a, b);
      sxx += (a.x * a.x + a.x * b.x + b.x * b.x) * ak;
      syy += (a.y * a.y + a.y * b.y + b.y * b.y) * ak;
      sxy += 0.5 * (a.x * b.y + 2 * a.x * a.y + 2 * b.x * b.y + b.x * a.y) * ak;
    }
    const double mean = 0.5 * (sxx + syy), spread = std::hypot(0.5 * (sxx - syy), sxy);
    const double small = mean - spread, large = mean + spread;
    if (!(small > 0) || std::sqrt(large / small) <= maxAspect * (1 + 1e-9)) return;
    const double axisAngle = 0.5 * std::atan2(2 * sxy, sxx - syy);  // direction of largest spread
    const P2 u{std::cos(axisAngle), std::sin(axisAngle)};
    double lo = 0, hi = 0;
    for (int k = 0; k < q.n; ++k) lo = std::min(lo, dot(u, q.v[k] - c)), hi = std::max(hi, dot(u, q.v[k] - c));
    // For a rectangle the aspect is proportional to the length: aim there, slightly beyond.
    const double keep = 0.98 * maxAspect / std::sqrt(large / small);
    clip(q, u, dot(u, c) + keep * hi, -1, tmp);
    clip(tmp, -1.0 * u, -dot(u, c) - keep * lo, -1, q);
  }
}

bool containsAll(const Poly& outer, const P2* pts, int n) {
  for (int k = 0; k < outer.n; ++k) {
    const P2 a = outer.v[k], e = outer.v[(k + 1) % outer.n] - a;
    for (int i = 0; i < n; ++i)
      if (cross(e, pts[i] - a) < 0) return false;
  }
  return true;
}

// ---------------------------------------------------------------------------------------------
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
std::vector<P2> placeDisks(std::vector<double>& radius, const std::vector<double>& share, const Domain& d,
                           const Grid& grid, Random& rng) {
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

// The power diagram of weighted sites, clipped to the domain, one cell at a time: the domain
// rectangle cut by the power bisector of every site that can reach it, nearest first.
class PowerDiagram {
 public:
  PowerDiagram(const std::vector<P2>& site, const Domain& d, const Grid& grid)
      : m_site(site), m_domain(d), m_grid(grid) {
    rebuild();
  }

  // Sites bucketed by grid cell (counting sort: deterministic order within a cell); again after
  // the sites moved.
  void rebuild() {
    m_start.assign(static_cast<size_t>(m_grid.nx) * m_grid.ny + 1, 0);
    for (const P2& p : m_site) ++m_start[static_cast<size_t>(m_grid.cell(p)) + 1];
    std::partial_sum(m_start.begin(), m_start.end(), m_start.begin());
    m_items.resize(m_site.size());
    std::vector<int> fill(m_start.begin(), m_start.end() - 1);
    for (size_t i = 0; i < m_site.size(); ++i)
      m_items[static_cast<size_t>(fill[static_cast<size_t>(m_grid.cell(m_site[i]))]++)] = static_cast<int>(i);
  }

  // The weights for the cells that follow; per grid cell their maximum, so that whole grid cells
  // too far for their heaviest site are skipped.
  void setWeights(const std::vector<double>& w) {
    m_w = &w;
    m_wMax = -std::numeric_limits<double>::infinity();
    m_cellMaxW.assign(static_cast<size_t>(m_grid.nx) * m_grid.ny, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < m_site.size(); ++i) {
      double& m = m_cellMaxW[static_cast<size_t>(m_grid.cell(m_site[i]))];
      m = std::max(m, w[i]);
      m_wMax = std::max(m_wMax, w[i]);
    }
  }

  // Cell of site i in coordinates relative to the site. Site j cuts the cell only where its power
  // |x - p_j|^2 - w_j is below |x - p_i|^2 - w_i; with R the cell's largest vertex distance, that
  // needs |p_j - p_i|^2 - 2 R |p_j - p_i| < w_j - w_i, so the rings searched end at
  // R + sqrt(R^2 - w_i + wMax).
  void cell(int i, Poly& out) {
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

 private:
  static double maxDistance2(const Poly& q) {
    double r2 = 0;
    for (int k = 0; k < q.n; ++k) r2 = std::max(r2, dot(q.v[k], q.v[k]));
    return r2;
  }

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
std::vector<int> assignGroups(const std::vector<double>& floeArea, const std::vector<ThicknessGroup>& groups,
                              double domainArea, Random& rng) {
  const size_t n = floeArea.size();
  std::vector<double> lack(groups.size());
  for (size_t g = 0; g < groups.size(); ++g) lack[g] = groups[g].coverage * domainArea;
  std::vector<int> order(n), group(n, 0);
  std::iota(order.begin(), order.end(), 0);
  rng.shuffle(order);
  const size_t randomPart = n - n / 10;
  std::sort(order.begin() + static_cast<std::ptrdiff_t>(randomPart), order.end(), [&](int a, int b) {
    return floeArea[static_cast<size_t>(a)] != floeArea[static_cast<size_t>(b)]
               ? floeArea[static_cast<size_t>(a)] > floeArea[static_cast<size_t>(b)] : a < b;
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

}  // namespace

std::vector<BodySpec> generateRandomConvexField(const RandomFieldSpec& spec) {
  checkDomain(spec.domain);
  checkCommon(spec.concentration, spec.thickness, spec.minGap, spec.groups.empty());
  if (spec.count < 0) fail("field.count: expected a floe count >= 0 (0: from the size distribution), got ", spec.count);
  if (!(spec.sizeMin > 0 && std::isfinite(spec.sizeMin)))
    fail("field.size_min: expected a positive size in m, got ", spec.sizeMin);
  if (!(spec.sizeMax >= spec.sizeMin && std::isfinite(spec.sizeMax)))
    fail("field.size_max: expected >= field.size_min = ", spec.sizeMin, " m, got ", spec.sizeMax);
  if (!(spec.sizeMean >= spec.sizeMin && spec.sizeMean <= spec.sizeMax))
    fail("field.size_mean: expected within [field.size_min, field.size_max] = [", spec.sizeMin, ", ",
         spec.sizeMax, "] m, got ", spec.sizeMean);
  if (!(spec.sizeSd >= 0 && std::isfinite(spec.sizeSd))) fail("field.size_sd: expected >= 0 m, got ", spec.sizeSd);
  if (spec.minSides < 3 || spec.minSides > kMaxFloeVertices)
    fail("field.min_sides: expected 3 to ", kMaxFloeVertices, ", got ", spec.minSides);
  if (spec.maxSides < spec.minSides || spec.maxSides > kMaxFloeVertices)
    fail("field.max_sides: expected field.min_sides = ", spec.minSides, " to ", kMaxFloeVertices, ", got ",
         spec.maxSides);
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
    if (!(qc < 0))
      fail("field.min_gap: ", spec.minGap, " m between ", n, " floes leaves no room for ice in this domain");
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
    const double minFeature = std::max(1e-4 * std::sqrt(target[i]),
                                       roundingTol * std::sqrt(std::max(1.0, area(shrunk) / target[i])));
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
  for (int ny = 1; height / ny >= circumradius; ++ny) {
    const int around = static_cast<int>(std::round(ideal / ny));
    for (int nx = std::max(1, around - 2); nx <= around + 2; ++nx) {
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
          inside = inside && hex[k].x >= d.x0 + margin && hex[k].x <= d.x1 - margin &&
                   hex[k].y >= d.y0 + margin && hex[k].y <= d.y1 - margin;
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
        separated = apart(r, i, r, i + 1) && apart(r, i, r + 1, left) && apart(r, i, r + 1, left + 1) &&
                    apart(r, i, r + 2, i);
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
  fail("field.concentration: ", spec.concentration, " cannot be reached within 0.01 by hexagons of field.size = ",
       spec.size, " m in this domain, at least field.min_gap = ", spec.minGap, " m apart");
}

}  // namespace gem
