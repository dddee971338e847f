// The floe size distribution (floe_size_distribution.hpp): its moments and quantiles through the
// standard normal, and the fit of the lognormal parameters to the requested mean and sd.
// Compiled without fused multiply-add or vectorizing, as every generator file (CMakeLists.txt;
// why: field_shared.hpp).

#include "framework/field/floe_size_distribution.hpp"

#include <algorithm>
#include <cmath>

#include "framework/field/field_shared.hpp"

namespace gem::field_detail {
namespace {

double normalCdf(double z) { return 0.5 * std::erfc(-z / std::sqrt(2.0)); }

// Inverse of normalCdf: Acklam's rational approximation, polished by one Halley step (|error|
// about 1e-15).
double normalQuantile(double p) {
  static const double a[] = {-3.969683028665376e+01, 2.209460984245205e+02,  -2.759285104469687e+02,
                             1.383577518672690e+02,  -3.066479806614716e+01, 2.506628277459239e+00};
  static const double b[] = {-5.447609879822406e+01, 1.615858368580409e+02, -1.556989798598866e+02, 6.680131188771972e+01,
                             -1.328068155288572e+01};
  static const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                             -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  static const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00, 3.754408661907416e+00};
  p = std::clamp(p, 1e-300, 1 - 1e-16);
  double x;
  if (p < 0.02425 || p > 1 - 0.02425) {
    const double q = std::sqrt(-2 * std::log(p < 0.5 ? p : 1 - p));
    x = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) / ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1);
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
double normalMass(double z1, double z2) { return z1 >= 0 ? normalCdf(-z1) - normalCdf(-z2) : normalCdf(z2) - normalCdf(z1); }

}  // namespace

double SizeDistribution::moment(int k) const {
  if (sigma <= 0) return std::pow(std::clamp(std::exp(mu), lo, hi), k);
  const double za = (std::log(lo) - mu) / sigma, zb = (std::log(hi) - mu) / sigma;
  const double mass = normalMass(za, zb);
  if (!(mass > 1e-300)) return std::pow(za > 0 ? lo : hi, k);  // all of it beyond one bound
  return std::exp(k * mu + 0.5 * k * k * sigma * sigma) * normalMass(za - k * sigma, zb - k * sigma) / mass;
}

double SizeDistribution::quantile(double u) const {
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

}  // namespace gem::field_detail
