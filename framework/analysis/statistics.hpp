// Maximum-likelihood fits for the impact-load statistics of `gem analyze` (thesis 6.2.2.3 to
// 6.2.2.4): Weibull (impact forces, Figure 6.38; apex angles, Figure 6.31), lognormal (floe
// masses, Figure 6.32) and power laws fitted in log-log space (force against distance from the
// stem and against speed, Figures 6.35 and 6.36).
//
// Degenerate inputs never throw and never produce NaN: a fit that the data cannot determine comes
// back with ok == false, a one-line reason, and finite placeholder parameters documented on each
// function. Callers (the CSV writer) print the parameters of a fit that is not ok as empty cells.
#pragma once
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace gem {

// F(x) = 1 - exp(-(x / scale)^shape), x >= 0 (thesis 6.2.2.4).
struct WeibullFit {
  double shape = 0;       // k
  double scale = 0;       // lambda, in the unit of the data
  std::size_t count = 0;  // positive finite values used
  bool ok = false;
  std::string reason;  // why not ok ("" when ok)
};

// ln x ~ Normal(mu, sigma^2).
struct LognormalFit {
  double mu = 0;
  double sigma = 0;
  std::size_t count = 0;
  bool ok = false;
  std::string reason;
};

// y = a * x^b, fitted by least squares on (ln x, ln y).
struct PowerLawFit {
  double a = 0;
  double b = 0;
  double r2 = 0;          // coefficient of determination in log-log space
  std::size_t count = 0;  // pairs with x > 0 and y > 0 (both finite)
  bool ok = false;
  std::string reason;
};

// Weibull maximum likelihood over the positive finite values (others are ignored: a zero force is
// "no impact", not a sample). The shape solves the profile-likelihood equation
//   sum(x^k ln x) / sum(x^k) - 1/k - mean(ln x) = 0
// (increasing in k, so bracketing plus safeguarded Newton always converges), and then
// scale = (mean x^k)^(1/k). Not ok: no value (shape = scale = 0), or all values equal, one value
// included (the likelihood grows without bound as k -> infinity; shape = 0, scale = that value).
WeibullFit fitWeibull(std::span<const double> values);

// Lognormal maximum likelihood over the positive finite values: mu = mean(ln x),
// sigma = sqrt(mean((ln x - mu)^2)) (the 1/n MLE, not the 1/(n-1) estimate). Not ok: no value
// (mu = sigma = 0), or all values equal, one value included (mu = ln x, sigma = 0).
LognormalFit fitLognormal(std::span<const double> values);

// Least squares of ln y on ln x over the pairs with both positive and finite. Not ok: no pair
// (a = b = 0), or all ln x equal, one pair included (b = 0, a = geometric mean of y).
PowerLawFit fitPowerLaw(std::span<const double> x, std::span<const double> y);

double weibullCdf(double x, double shape, double scale);
double weibullPdf(double x, double shape, double scale);
// Density of ln x (a normal density): the curve to lay over a histogram of ln(mass).
double lognormalLogDensity(double lnX, double mu, double sigma);

// Median-rank plotting positions (Benard: (i - 0.3) / (n + 0.4)) of sorted data, as Minitab's
// probability plots in thesis Figures 6.31, 6.32 and 6.38 use.
std::vector<double> medianRanks(std::size_t n);

}  // namespace gem
