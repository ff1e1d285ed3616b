// Plateau samples sorted into groups of equal table rate, each with its theta-binned rates.
// Plateaus at the same rate (within a tolerance) share a group, so a session can repeat its
// plateaus; a new plateau or a gap breaks the averaging chain so no increment spans a rate change.
#pragma once

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
  /// max_order: highest harmonic order any fit of these groups will use.
  RateGroups(int bins, double window, int max_order, double tolerance, double max_gap)
      : bins_(bins), window_(window), max_order_(max_order), tolerance_(tolerance), max_gap_(max_gap) {}

  /// Adds a sample of plateau `plateau_id` whose detected rate is `plateau_rate`; `reported_rate`
  /// feeds the group's rate statistics; y is the quantity whose rate is binned.
  void add(Nanoseconds stamp, double theta, double y, std::uint64_t plateau_id, double plateau_rate,
           double reported_rate);

  const std::vector<RateGroup>& groups() const { return groups_; }
  /// Indices of the groups, most data first.
  std::vector<std::size_t> byDuration() const;

 private:
  int bins_;
  double window_;
  int max_order_;
  double tolerance_, max_gap_;
  std::vector<RateGroup> groups_;
};

}  // namespace core
}  // namespace hrg_gyro
