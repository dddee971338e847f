// sin, cos and atan2 from IEEE additions, multiplications and divisions alone, so that the host and
// the device get the very same bits (libm's and CUDA's differ in the last bits; the device build
// contracts no a*b+c into an FMA, and the host build targets no FMA). The flexural break uses them
// (events/flexural_cut.hpp, World::addPiece): the resident CUDA kernel cuts floes itself, and its
// pieces must be those the host's topology phase makes, bit for bit, so that a case stepped on the
// device steps as it does anywhere else.
//
// Accuracy (tests/portable_trig_test.cpp): within 4 ulp of libm, and 2e-21 |x| more for the
// reduction of large angles (1e-15 at 1e6 rad; a floe's angle is its accumulated turn); the series
// below are truncated past 1e-20 relative.
#pragma once
#include <cmath>

#include "geometry/polygon.hpp"

namespace gem {

namespace detail {
// pi/2 in three parts: the first two with trailing zero bits, so that k * part is exact for
// |k| < 2^20 (Cody and Waite's reduction).
constexpr double kHalfPi1 = 1.5707963267341256e+00;
constexpr double kHalfPi2 = 6.0771005065061922e-11;
constexpr double kHalfPi3 = 2.0222662487959506e-21;
constexpr double kTwoOverPi = 6.3661977236758138e-01;
constexpr double kPi = 3.1415926535897931e+00;
constexpr double kHalfPi = 1.5707963267948966e+00;
constexpr double kSixthPi = 5.2359877559829882e-01;
constexpr double kSqrt3 = 1.7320508075688772e+00;
constexpr double kTanTwelfthPi = 2.6794919243112270e-01;  // tan(pi/12)

// sin r and cos r for |r| <= pi/4 + a little: Taylor series to r^21 and r^20 (Horner).
GEM_HD inline void sinCosReduced(double r, double* s, double* c) {
  const double r2 = r * r;
  double ps = 1.0 / 51090942171709440000.0;   // 1/21!
  ps = 1.0 / 121645100408832000.0 - r2 * ps;  // 1/19!
  ps = 1.0 / 355687428096000.0 - r2 * ps;     // 1/17!
  ps = 1.0 / 1307674368000.0 - r2 * ps;       // 1/15!
  ps = 1.0 / 6227020800.0 - r2 * ps;          // 1/13!
  ps = 1.0 / 39916800.0 - r2 * ps;            // 1/11!
  ps = 1.0 / 362880.0 - r2 * ps;              // 1/9!
  ps = 1.0 / 5040.0 - r2 * ps;                // 1/7!
  ps = 1.0 / 120.0 - r2 * ps;                 // 1/5!
  ps = 1.0 / 6.0 - r2 * ps;                   // 1/3!
  *s = r - r * (r2 * ps);
  double pc = 1.0 / 2432902008176640000.0;  // 1/20!
  pc = 1.0 / 6402373705728000.0 - r2 * pc;  // 1/18!
  pc = 1.0 / 20922789888000.0 - r2 * pc;    // 1/16!
  pc = 1.0 / 87178291200.0 - r2 * pc;       // 1/14!
  pc = 1.0 / 479001600.0 - r2 * pc;         // 1/12!
  pc = 1.0 / 3628800.0 - r2 * pc;           // 1/10!
  pc = 1.0 / 40320.0 - r2 * pc;             // 1/8!
  pc = 1.0 / 720.0 - r2 * pc;               // 1/6!
  pc = 1.0 / 24.0 - r2 * pc;                // 1/4!
  pc = 0.5 - r2 * pc;                       // 1/2!
  *c = 1.0 - r2 * pc;
}

// atan t for 0 <= t <= tan(pi/12): the alternating series to t^41 (below 1e-24 there).
GEM_HD inline double atanReduced(double t) {
  const double t2 = t * t;
  double p = 1.0 / 41.0;
  for (int k = 39; k >= 3; k -= 2) p = 1.0 / k - t2 * p;
  return t - t * (t2 * p);
}
}  // namespace detail

// sin x and cos x, the same bits on the host and the device.
GEM_HD inline void portableSinCos(Real x, Real* sine, Real* cosine) {
  const double v = static_cast<double>(x);
  const double k = std::floor(v * detail::kTwoOverPi + 0.5);
  const double r = ((v - k * detail::kHalfPi1) - k * detail::kHalfPi2) - k * detail::kHalfPi3;
  double s, c;
  detail::sinCosReduced(r, &s, &c);
  // x = k pi/2 + r: the quadrant k mod 4 turns (s, c).
  const double q = k - 4.0 * std::floor(k * 0.25);
  double outS = s, outC = c;
  if (q == 1.0) outS = c, outC = -s;
  if (q == 2.0) outS = -s, outC = -c;
  if (q == 3.0) outS = -c, outC = s;
  *sine = static_cast<Real>(outS);
  *cosine = static_cast<Real>(outC);
}

// atan2(y, x) in (-pi, pi], the same bits on the host and the device; 0 for (0, 0).
GEM_HD inline Real portableAtan2(Real yIn, Real xIn) {
  const double y = static_cast<double>(yIn), x = static_cast<double>(xIn);
  const double ay = std::fabs(y), ax = std::fabs(x);
  if (ay == 0.0 && ax == 0.0) return Real(0);
  // The angle of (ax, ay) in [0, pi/2]: atan of the smaller over the larger, then reduced below
  // tan(pi/12) by atan t = pi/6 + atan((t sqrt3 - 1) / (t + sqrt3)).
  const bool steep = ay > ax;
  const double t = steep ? ax / ay : ay / ax;
  double angle;
  if (t > detail::kTanTwelfthPi) {
    const double u = (t * detail::kSqrt3 - 1.0) / (t + detail::kSqrt3);
    angle = u >= 0.0 ? detail::kSixthPi + detail::atanReduced(u) : detail::kSixthPi - detail::atanReduced(-u);
  } else {
    angle = detail::atanReduced(t);
  }
  if (steep) angle = detail::kHalfPi - angle;
  if (x < 0.0) angle = detail::kPi - angle;
  return static_cast<Real>(y < 0.0 ? -angle : angle);
}

// massProperties' and toWorld's trigonometry by the functions above (geometry/polygon.hpp LibmTrig).
struct PortableTrig {
  GEM_HD static Real atan2(Real y, Real x) { return portableAtan2(y, x); }
  GEM_HD static void sinCos(Real angle, Real* s, Real* c) { portableSinCos(angle, s, c); }
};

// toWorld (geometry/polygon.hpp) with the portable sin and cos.
GEM_HD inline void toWorldPortable(const Vec2* local, int n, Vec2 position, Real angle, Vec2* world) {
  Real s, c;
  portableSinCos(angle, &s, &c);
  for (int i = 0; i < n; ++i) world[i] = toWorldPoint(local[i], position, c, s);
}

}  // namespace gem
