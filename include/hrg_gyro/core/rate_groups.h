// Plateau samples sorted into groups of equal table rate, each with its theta-binned rates.
// The averaging window is long (more samples behind each window mean, measured: the noise of the
// harmonics falls by ~1.4x from 0.5 s to 2 s) but bounded in swept angle, because the smoothing
// correction sinc^2(k L / 2) is only first order in the rate's variation over the window (at
// L = 0.2 rad it biased a 7.7e-4 harmonic by 14 sigma).
// Plateaus at the same rate (within a tolerance) share a group, so a session can repeat its
// plateaus; a new plateau or a gap breaks the averaging chain so no increment spans a rate change.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "hrg_gyro/core/theta_binned_rates.h"

namespace hrg_gyro {
namespace core {

struct RateGroup {
  RateGroup(int bins, double window, int max_order) : rates(bins, window, max_order) {}
  ThetaBinnedRates rates;
  double rate_sum = 0.0, rate_sq_sum = 0.0;  ///< of the reported rate, for its mean and noise
  std::uint64_t rate_count = 0;
  std::uint64_t last_plateau = 0;
  Nanoseconds last_stamp = 0;

  double meanRate() const { return rate_count ? rate_sum / rate_count : 0.0; }
  double rateStd() const {
    if (rate_count < 2) return 0.0;
    const double m = meanRate();
    return std::sqrt(std::max(0.0, rate_sq_sum / rate_count - m * m));
  }
};

class RateGroups {
 public:
  /// max_order: highest harmonic order any fit of these groups will use. A group's averaging window
  /// is `window` s, shortened so that the wave angle sweeps at most `window_span` rad in it
  /// (theta_per_rate = |K0|: the angle rate per table rate).
  RateGroups(int bins, double window, double window_span, double theta_per_rate, int max_order, double tolerance,
             double max_gap)
      : bins_(bins),
        window_(window),
        window_span_(window_span),
        theta_per_rate_(theta_per_rate),
        max_order_(max_order),
        tolerance_(tolerance),
        max_gap_(max_gap) {}

  /// The window used for plateaus at this table rate, s.
  double windowFor(double rate) const {
    const double sweep = theta_per_rate_ * std::abs(rate);
    return sweep > 0.0 ? std::min(window_, window_span_ / sweep) : window_;
  }

  /// Adds a sample of plateau `plateau_id` whose detected rate is `plateau_rate`; `reported_rate`
  /// feeds the group's rate statistics; y is the quantity whose rate is binned.
  void add(Nanoseconds stamp, double theta, double y, std::uint64_t plateau_id, double plateau_rate,
           double reported_rate);

  const std::vector<RateGroup>& groups() const { return groups_; }
  /// Indices of the groups, most data first.
  std::vector<std::size_t> byDuration() const;

 private:
  int bins_;
  double window_, window_span_, theta_per_rate_;
  int max_order_;
  double tolerance_, max_gap_;
  std::vector<RateGroup> groups_;
};

}  // namespace core
}  // namespace hrg_gyro
