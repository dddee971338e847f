// The floe size distribution of the random field: lognormal in s = sqrt(area), truncated to
// [lo, hi], fitted to a requested mean and standard deviation. Internal to framework/field/.
#pragma once
#include <algorithm>
#include <cmath>

namespace gem::field_detail {

struct SizeDistribution {
  double mu = 0, sigma = 0, lo = 0, hi = 0;

  // Raw moment E[s^k] of the truncated distribution (closed form for the lognormal).
  double moment(int k) const;
  // The size at cumulative probability u of the truncated distribution.
  double quantile(double u) const;
  double mean() const { return moment(1); }
  double sd() const { return std::sqrt(std::max(0.0, moment(2) - moment(1) * moment(1))); }
};

// Lognormal parameters whose truncation to [lo, hi] has the requested mean and sd: start from the
// untruncated match and correct (truncation at 2 and 20 m shifts the thesis moments by a few %).
SizeDistribution fitSizeDistribution(double mean, double sd, double lo, double hi);

}  // namespace gem::field_detail
