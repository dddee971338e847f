// The fits of gem analyze (framework/analysis/statistics.hpp): maximum-likelihood Weibull and lognormal
// recover known parameters from samples, the log-log power law is exact on noiseless data, and
// degenerate inputs give ok == false with finite placeholders (never NaN, never a throw).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "framework/analysis/statistics.hpp"

using namespace gem;

namespace {

// Weibull samples by inverse CDF: x = lambda (-ln(1 - u))^(1/k).
std::vector<double> weibullSamples(double k, double lambda, size_t n, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<double> x(n);
  for (double& v : x) v = lambda * std::pow(-std::log1p(-u(rng)), 1.0 / k);
  return x;
}

bool finite(const WeibullFit& f) { return std::isfinite(f.shape) && std::isfinite(f.scale); }

}  // namespace

TEST(Statistics, WeibullMaximumLikelihoodRecoversParameters) {
  // Impact forces (thesis Figure 6.38) have k near 1; apex angles (Figure 6.31) are peaked.
  for (const auto& [k, lambda] : {std::pair{0.8, 3.0e5}, std::pair{1.3, 2.0e6}, std::pair{4.0, 120.0}}) {
    const WeibullFit fit = fitWeibull(weibullSamples(k, lambda, 20000, 12345));
    ASSERT_TRUE(fit.ok) << fit.reason;
    EXPECT_EQ(fit.count, 20000u);
    EXPECT_NEAR(fit.shape, k, 0.03 * k);
    EXPECT_NEAR(fit.scale, lambda, 0.03 * lambda);
  }
}

TEST(Statistics, WeibullSolvesTheLikelihoodEquation) {
  // At the returned k the profile-likelihood equation holds, and lambda = (mean x^k)^(1/k).
  const std::vector<double> x = weibullSamples(2.2, 7.0, 500, 7);
  const WeibullFit fit = fitWeibull(x);
  double s = 0, a = 0, meanLog = 0;
  for (double v : x) {
    s += std::pow(v, fit.shape);
    a += std::pow(v, fit.shape) * std::log(v);
    meanLog += std::log(v) / double(x.size());
  }
  EXPECT_NEAR(a / s - 1.0 / fit.shape - meanLog, 0.0, 1e-10);
  EXPECT_NEAR(fit.scale, std::pow(s / double(x.size()), 1.0 / fit.shape), 1e-9 * fit.scale);
}

TEST(Statistics, WeibullIsScaleEquivariantAndIgnoresNonPositive) {
  std::vector<double> x = weibullSamples(1.5, 1.0, 1000, 3);
  const WeibullFit base = fitWeibull(x);
  std::vector<double> scaled;
  for (double v : x) scaled.push_back(v * 1e6);
  scaled.insert(scaled.end(), {0.0, -5.0, NAN, INFINITY});  // not samples of a load: ignored
  const WeibullFit fit = fitWeibull(scaled);
  EXPECT_EQ(fit.count, 1000u);
  EXPECT_NEAR(fit.shape, base.shape, 1e-9 * base.shape);
  EXPECT_NEAR(fit.scale, base.scale * 1e6, 1e-6 * base.scale * 1e6);
}

TEST(Statistics, LognormalMaximumLikelihoodRecoversParameters) {
  std::mt19937_64 rng(2024);
  std::normal_distribution<double> z(0.0, 1.0);
  const double mu = 10.5, sigma = 1.2;  // floe masses of tens of tonnes (thesis Figure 6.32)
  std::vector<double> x(20000);
  for (double& v : x) v = std::exp(mu + sigma * z(rng));
  const LognormalFit fit = fitLognormal(x);
  ASSERT_TRUE(fit.ok) << fit.reason;
  EXPECT_NEAR(fit.mu, mu, 0.03 * mu);
  EXPECT_NEAR(fit.sigma, sigma, 0.03 * sigma);
  // Exactly the mean and the 1/n standard deviation of the logs.
  const LognormalFit small = fitLognormal(std::vector<double>{1.0, std::exp(2.0)});
  EXPECT_DOUBLE_EQ(small.mu, 1.0);
  EXPECT_DOUBLE_EQ(small.sigma, 1.0);
}

TEST(Statistics, PowerLawIsExactOnNoiselessData) {
  std::vector<double> x, y;
  for (int i = 1; i <= 50; ++i) {
    x.push_back(0.1 * i);
    y.push_back(2.5e5 * std::pow(0.1 * i, -0.7));
  }
  x.push_back(0.0), y.push_back(1.0);   // x = 0: left out
  x.push_back(2.0), y.push_back(-1.0);  // y < 0: left out
  const PowerLawFit fit = fitPowerLaw(x, y);
  ASSERT_TRUE(fit.ok) << fit.reason;
  EXPECT_EQ(fit.count, 50u);
  EXPECT_NEAR(fit.a, 2.5e5, 1e-9 * 2.5e5);
  EXPECT_NEAR(fit.b, -0.7, 1e-12);
  EXPECT_NEAR(fit.r2, 1.0, 1e-12);
}

TEST(Statistics, DegenerateInputsGiveDefinedResults) {
  // Documented choice: not ok, a reason, finite placeholders; no throw and no NaN.
  const std::vector<double> none, one{4.0}, same{3.0, 3.0, 3.0}, zeros{0.0, -1.0};
  for (const auto* data : {&none, &zeros}) {
    const WeibullFit w = fitWeibull(*data);
    EXPECT_FALSE(w.ok);
    EXPECT_FALSE(w.reason.empty());
    EXPECT_EQ(w.count, 0u);
    EXPECT_EQ(w.shape, 0.0);
    EXPECT_EQ(w.scale, 0.0);
    const LognormalFit l = fitLognormal(*data);
    EXPECT_FALSE(l.ok);
    EXPECT_EQ(l.mu, 0.0);
    EXPECT_EQ(l.sigma, 0.0);
  }
  for (const auto* data : {&one, &same}) {
    const WeibullFit w = fitWeibull(*data);
    EXPECT_FALSE(w.ok);
    EXPECT_FALSE(w.reason.empty());
    EXPECT_TRUE(finite(w));
    EXPECT_EQ(w.shape, 0.0);
    EXPECT_EQ(w.scale, data->front());  // the point mass
    const LognormalFit l = fitLognormal(*data);
    EXPECT_FALSE(l.ok);
    EXPECT_DOUBLE_EQ(l.mu, std::log(data->front()));
    EXPECT_EQ(l.sigma, 0.0);
  }
  const PowerLawFit empty = fitPowerLaw(none, none);
  EXPECT_FALSE(empty.ok);
  EXPECT_EQ(empty.a, 0.0);
  const PowerLawFit vertical = fitPowerLaw(std::vector<double>{2.0, 2.0}, std::vector<double>{1.0, 4.0});
  EXPECT_FALSE(vertical.ok);
  EXPECT_DOUBLE_EQ(vertical.a, 2.0);  // geometric mean of y
  EXPECT_EQ(vertical.b, 0.0);
  const PowerLawFit flat = fitPowerLaw(std::vector<double>{1.0, 2.0}, std::vector<double>{5.0, 5.0});
  EXPECT_TRUE(flat.ok);
  EXPECT_DOUBLE_EQ(flat.b, 0.0);
  EXPECT_DOUBLE_EQ(flat.a, 5.0);
  // x spread too little: ship speeds of 4.887 to 4.9 m/s against forces of 1e5 to 4e5 N (a 50-step
  // run) gave b = 470 and a = 9e-320, a subnormal number written into statistics.csv as the fit.
  const PowerLawFit narrow = fitPowerLaw(std::vector<double>{4.887, 4.89, 4.895, 4.9}, std::vector<double>{1e5, 2e5, 3e5, 4e5});
  EXPECT_FALSE(narrow.ok) << "a = " << narrow.a << ", b = " << narrow.b;
  EXPECT_EQ(narrow.reason, "x spreads too little for a power law");
}

TEST(Statistics, NearlyEqualValuesStillConverge) {
  // A very narrow spread makes k large; the fit must neither overflow nor stall.
  std::vector<double> x;
  for (int i = 0; i < 100; ++i) x.push_back(1000.0 + 1e-6 * i);
  const WeibullFit fit = fitWeibull(x);
  ASSERT_TRUE(fit.ok) << fit.reason;
  EXPECT_GT(fit.shape, 1e5);
  EXPECT_NEAR(fit.scale, 1000.0, 1e-3);
}

TEST(Statistics, DistributionFunctions) {
  EXPECT_NEAR(weibullCdf(2.0, 1.7, 2.0), 1.0 - std::exp(-1.0), 1e-15);
  EXPECT_EQ(weibullCdf(0.0, 1.7, 2.0), 0.0);
  EXPECT_NEAR(weibullPdf(1.0, 1.0, 1.0), std::exp(-1.0), 1e-15);
  EXPECT_NEAR(lognormalLogDensity(3.0, 3.0, 2.0), 1.0 / (2.0 * std::sqrt(2.0 * M_PI)), 1e-15);
  const std::vector<double> p = medianRanks(3);
  EXPECT_NEAR(p[0], 0.7 / 3.4, 1e-15);
  EXPECT_NEAR(p[2], 2.7 / 3.4, 1e-15);
}
