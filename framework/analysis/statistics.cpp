#include "framework/analysis/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace gem {

namespace {

std::vector<double> positiveFinite(std::span<const double> values) {
  std::vector<double> out;
  out.reserve(values.size());
  for (double v : values)
    if (std::isfinite(v) && v > 0) out.push_back(v);
  return out;
}

// Profile-likelihood equation of the Weibull shape and its derivative, on logs of the data
// divided by its maximum (l <= 0): the equation is unchanged by scaling, and y^k <= 1 cannot
// overflow however large k grows.
struct ShapeEquation {
  const std::vector<double>& logs;  // ln(x / max x)
  double meanLog;

  void evaluate(double k, double& g, double& dg) const {
    double s = 0, a = 0, b = 0;
    for (double l : logs) {
      const double w = std::exp(k * l);
      s += w;
      a += w * l;
      b += w * l * l;
    }
    g = a / s - 1.0 / k - meanLog;
    dg = (b * s - a * a) / (s * s) + 1.0 / (k * k);
  }
  double value(double k) const {
    double g, dg;
    evaluate(k, g, dg);
    return g;
  }
};

}  // namespace

WeibullFit fitWeibull(std::span<const double> values) {
  WeibullFit fit;
  const std::vector<double> x = positiveFinite(values);
  fit.count = x.size();
  if (x.empty()) {
    fit.reason = "no positive value";
    return fit;
  }
  const auto [minIt, maxIt] = std::minmax_element(x.begin(), x.end());
  const double xMax = *maxIt;
  if (*minIt == xMax) {
    fit.scale = xMax;
    fit.reason = x.size() == 1 ? "one value" : "all values equal";
    return fit;
  }
  std::vector<double> logs(x.size());
  double meanLog = 0;
  for (size_t i = 0; i < x.size(); ++i) meanLog += logs[i] = std::log(x[i] / xMax);
  meanLog /= double(x.size());
  double var = 0;
  for (double l : logs) var += (l - meanLog) * (l - meanLog);
  var /= double(x.size());
  const ShapeEquation eq{logs, meanLog};

  // Start from the moment estimate of the log data (sd of ln x = pi / (k sqrt 6) for a Weibull),
  // then bracket the root: g -> -inf as k -> 0 and g -> -mean(l) > 0 as k -> inf.
  double k = std::clamp(std::numbers::pi / (std::sqrt(6.0 * var) + 1e-300), 1e-3, 1e6);
  double lo = k, hi = k;
  for (int i = 0; i < 200 && eq.value(lo) > 0; ++i) lo *= 0.5;
  for (int i = 0; i < 200 && eq.value(hi) < 0; ++i) hi *= 2.0;
  // Safeguarded Newton: a step that leaves the bracket becomes a bisection.
  for (int i = 0; i < 200; ++i) {
    double g, dg;
    eq.evaluate(k, g, dg);
    if (g < 0)
      lo = k;
    else
      hi = k;
    double next = k - g / dg;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    const bool done = std::abs(next - k) <= 1e-12 * k;
    k = next;
    if (done || hi - lo <= 1e-14 * hi) break;
  }
  double s = 0;
  for (double l : logs) s += std::exp(k * l);
  fit.shape = k;
  fit.scale = xMax * std::pow(s / double(x.size()), 1.0 / k);
  fit.ok = std::isfinite(fit.shape) && std::isfinite(fit.scale) && fit.scale > 0;
  if (!fit.ok) {
    fit.shape = 0;
    fit.scale = xMax;
    fit.reason = "no convergence";
  }
  return fit;
}

LognormalFit fitLognormal(std::span<const double> values) {
  LognormalFit fit;
  const std::vector<double> x = positiveFinite(values);
  fit.count = x.size();
  if (x.empty()) {
    fit.reason = "no positive value";
    return fit;
  }
  double mu = 0;
  for (double v : x) mu += std::log(v);
  mu /= double(x.size());
  double var = 0;
  for (double v : x) var += (std::log(v) - mu) * (std::log(v) - mu);
  var /= double(x.size());
  fit.mu = mu;
  fit.sigma = std::sqrt(var);
  const bool allEqual = std::all_of(x.begin(), x.end(), [&](double v) { return v == x.front(); });
  if (allEqual) {
    fit.mu = std::log(x.front());
    fit.sigma = 0;
    fit.reason = x.size() == 1 ? "one value" : "all values equal";
    return fit;
  }
  fit.ok = true;
  return fit;
}

PowerLawFit fitPowerLaw(std::span<const double> x, std::span<const double> y) {
  PowerLawFit fit;
  std::vector<double> lx, ly;
  const size_t n = std::min(x.size(), y.size());
  for (size_t i = 0; i < n; ++i) {
    if (std::isfinite(x[i]) && std::isfinite(y[i]) && x[i] > 0 && y[i] > 0) {
      lx.push_back(std::log(x[i]));
      ly.push_back(std::log(y[i]));
    }
  }
  fit.count = lx.size();
  if (lx.empty()) {
    fit.reason = "no pair with both values positive";
    return fit;
  }
  double mx = 0, my = 0;
  for (size_t i = 0; i < lx.size(); ++i) {
    mx += lx[i];
    my += ly[i];
  }
  mx /= double(lx.size());
  my /= double(lx.size());
  double sxx = 0, sxy = 0, syy = 0;
  for (size_t i = 0; i < lx.size(); ++i) {
    sxx += (lx[i] - mx) * (lx[i] - mx);
    sxy += (lx[i] - mx) * (ly[i] - my);
    syy += (ly[i] - my) * (ly[i] - my);
  }
  if (!(sxx > 0)) {
    fit.a = std::exp(my);
    fit.reason = lx.size() == 1 ? "one pair" : "all x equal";
    return fit;
  }
  fit.b = sxy / sxx;
  fit.a = std::exp(my - fit.b * mx);
  // All y equal gives syy = 0 and an exact (flat) fit.
  fit.r2 = syy > 0 ? (sxy * sxy) / (sxx * syy) : 1.0;
  // x spread too little for a power law: the exponent runs away (ship speeds of 4.887 to 4.9 m/s
  // gave b = 470 and a = 9e-320, a subnormal number written as the fit). The fit stands only when
  // a and its curve over the data are ordinary numbers.
  const auto [least, most] = std::minmax_element(lx.begin(), lx.end());
  const double atLeast = fit.a * std::exp(fit.b * *least), atMost = fit.a * std::exp(fit.b * *most);
  if (!std::isnormal(fit.a) || !std::isfinite(fit.b) || !std::isnormal(atLeast) || !std::isnormal(atMost)) {
    fit.reason = "x spreads too little for a power law";
    return fit;
  }
  fit.ok = true;
  return fit;
}

double weibullCdf(double x, double shape, double scale) {
  if (!(x > 0) || !(shape > 0) || !(scale > 0)) return 0;
  return -std::expm1(-std::pow(x / scale, shape));
}

double weibullPdf(double x, double shape, double scale) {
  if (!(x > 0) || !(shape > 0) || !(scale > 0)) return 0;
  const double z = x / scale;
  return shape / scale * std::pow(z, shape - 1) * std::exp(-std::pow(z, shape));
}

double lognormalLogDensity(double lnX, double mu, double sigma) {
  if (!(sigma > 0)) return 0;
  const double z = (lnX - mu) / sigma;
  return std::exp(-0.5 * z * z) / (sigma * std::sqrt(2 * std::numbers::pi));
}

std::vector<double> medianRanks(std::size_t n) {
  std::vector<double> p(n);
  for (size_t i = 0; i < n; ++i) p[i] = (double(i + 1) - 0.3) / (double(n) + 0.4);
  return p;
}

}  // namespace gem
