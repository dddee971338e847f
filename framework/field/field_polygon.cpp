// The convex polygon operations of field_polygon.hpp: area, centroid, half-plane clip, inset, and
// the corner cuts (cleanup, vertex count, aspect) that shape a power cell into a floe container.
// Compiled without fused multiply-add or vectorizing, as every generator file (CMakeLists.txt;
// why: field_shared.hpp).

#include "framework/field/field_polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace gem::field_detail {

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

}  // namespace gem::field_detail
