// Theta-binned rates of the plateau groups, kept separately per slice of resonator frequency.
//
// Why: across temperature K and D change with the resonator frequency f, so rates measured at the
// two table rates must be compared at the same f as well as at the same theta. Samples are grouped
// by table rate as RateGroups does; within a group they go to frequency slices of a fixed width on
// a grid anchored at 0 Hz, each with its own ThetaBinnedRates whose bins also keep the mean
// frequency of their data. A change of slice breaks the averaging chain (no increment spans two
// slices); a hysteresis of a tenth of the slice width keeps frequency noise at a slice edge from
// breaking the chain at every sample (the bins' mean frequency records where the data really
// were). Memory grows with bins x slices, bounded by max_slices, never with the session length.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

#include "hrg_gyro/core/theta_binned_rates.h"

namespace hrg_gyro {
namespace core {

struct SlicedRateGroup {
  double window = 0.0;                       ///< s, averaging window of this group's rate
  double rate_sum = 0.0, rate_sq_sum = 0.0;  ///< of the reported rate
  std::uint64_t rate_count = 0;
  std::uint64_t last_plateau = 0;
  Nanoseconds last_stamp = 0;
  bool in_slice = false;
  long current_slice = 0;
  std::map<long, ThetaBinnedRates> slices;  ///< by slice index (slice i covers [i w, (i + 1) w) Hz)

  double meanRate() const { return rate_count ? rate_sum / rate_count : 0.0; }
  double rateStd() const;
  double totalTime() const;
  std::uint64_t samples() const;
  /// Electrical angle swept, rad.
  double thetaSwept() const;
};

class FrequencySlicedRates {
 public:
  /// bins, window, window_span, theta_per_rate, max_order, tolerance, max_gap: as RateGroups;
  /// slice_width in Hz; at most max_slices (group, slice) pairs are kept.
  FrequencySlicedRates(int bins, double window, double window_span, double theta_per_rate, int max_order,
                       double tolerance, double max_gap, double slice_width, int max_slices);

  /// Adds a plateau sample at resonator frequency f (finite). False when it would need a new slice
  /// beyond max_slices (the sample is dropped).
  bool add(Nanoseconds stamp, double theta, double frequency, std::uint64_t plateau_id, double plateau_rate,
           double reported_rate);

  double sliceWidth() const { return slice_width_; }
  double sliceCenter(long index) const { return (static_cast<double>(index) + 0.5) * slice_width_; }
  int binCount() const { return bins_; }
  int sliceCount() const { return slice_count_; }
  const std::vector<SlicedRateGroup>& groups() const { return groups_; }
  /// Indices of the groups, most data first.
  std::vector<std::size_t> byDuration() const;

 private:
  double windowFor(double rate) const;
  long sliceOf(double frequency) const { return static_cast<long>(std::floor(frequency / slice_width_)); }

  int bins_;
  double window_, window_span_, theta_per_rate_;
  int max_order_;
  double tolerance_, max_gap_, slice_width_;
  int max_slices_;
  int slice_count_ = 0;
  std::vector<SlicedRateGroup> groups_;
};

}  // namespace core
}  // namespace hrg_gyro
