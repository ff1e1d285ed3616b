// Plateau samples sorted into groups of equal table rate, each with its theta-binned rates, kept
// either whole or per slice of resonator frequency.
//
// The averaging window is long (more samples behind each window mean, measured: the noise of the
// harmonics falls by ~1.4x from 0.5 s to 2 s) but bounded in swept angle, because the smoothing
// correction sinc^2(k L / 2) is only first order in the rate's variation over the window (at
// L = 0.2 rad it biased a 7.7e-4 harmonic by 14 sigma).
// Plateaus at the same rate (within a tolerance) share a group, so a session can repeat its
// plateaus; a new plateau or a gap breaks the averaging chain so no increment spans a rate change.
//
// Frequency slices (the thermal calibration): across temperature K and D change with the resonator
// frequency f, so rates measured at the two table rates must be compared at the same f as well as at
// the same theta. With a slice width, a group's samples go to slices of that width on a grid
// anchored at 0 Hz, each with its own ThetaBinnedRates whose bins also keep the mean frequency of
// their data (the tag). A change of slice breaks the averaging chain (no increment spans two
// slices); a hysteresis of a tenth of the slice width keeps frequency noise at a slice edge from
// breaking the chain at every sample (the bins' mean frequency records where the data really were).
// Memory grows with bins x slices, bounded by max_slices, never with the session length. Without a
// slice width every group has one slice, index 0, and the frequency is ignored.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "hrg_gyro/core/estimation/theta_binned_rates.h"

namespace hrg_gyro {
namespace core {

struct RateGroup {
  double window = 0.0;                       ///< s, averaging window of this group's rates
  double rate_sum = 0.0, rate_sq_sum = 0.0;  ///< of the reported rate, for its mean and noise
  std::uint64_t rate_count = 0;
  /// The plateaus' own rates (the slope of the table angle), by which samples are grouped: a noisy
  /// reported rate must not start a new group with every sample.
  double plateau_rate_sum = 0.0;
  std::uint64_t last_plateau = 0;
  Nanoseconds last_stamp = 0;
  bool in_slice = false;
  long current_slice = 0;
  std::map<long, ThetaBinnedRates> slices;  ///< by slice index (slice i covers [i w, (i + 1) w) Hz)

  double meanRate() const { return rate_count ? rate_sum / rate_count : 0.0; }
  double meanPlateauRate() const { return rate_count ? plateau_rate_sum / rate_count : 0.0; }
  double rateStd() const;
  double totalTime() const;
  std::uint64_t samples() const;
  /// Electrical angle swept, rad.
  double thetaSwept() const;
  /// The binned rates of a group kept without frequency slices (its one slice).
  const ThetaBinnedRates& rates() const;
};

class RateGroups {
 public:
  /// max_order: highest harmonic order any fit of these groups will use. A group's averaging window
  /// is `window` s, shortened so that the wave angle sweeps at most `window_span` rad in it
  /// (theta_per_rate = |K0|: the angle rate per table rate). slice_width: Hz, 0 for no frequency
  /// slices; with slices at most max_slices (group, slice) pairs are kept.
  RateGroups(int bins, double window, double window_span, double theta_per_rate, int max_order, double tolerance,
             double max_gap, double slice_width = 0.0, int max_slices = 0);

  /// The window used for plateaus at this table rate, s.
  double windowFor(double rate) const {
    const double sweep = theta_per_rate_ * std::abs(rate);
    return sweep > 0.0 ? std::min(window_, window_span_ / sweep) : window_;
  }

  /// Adds a sample of plateau `plateau_id` whose detected rate is `plateau_rate`; `reported_rate`
  /// feeds the group's rate statistics; y is the quantity whose rate is binned; `frequency` (Hz,
  /// finite) chooses the slice and is the bins' tag when slicing. False when the sample would need a
  /// new slice beyond max_slices (it is dropped).
  bool add(Nanoseconds stamp, double theta, double y, std::uint64_t plateau_id, double plateau_rate,
           double reported_rate, double frequency = 0.0);

  bool sliced() const { return slice_width_ > 0.0; }
  double sliceWidth() const { return slice_width_; }
  double sliceCenter(long index) const { return (static_cast<double>(index) + 0.5) * slice_width_; }
  int binCount() const { return bins_; }
  int sliceCount() const { return slice_count_; }
  const std::vector<RateGroup>& groups() const { return groups_; }
  /// Indices of the groups, most data first.
  std::vector<std::size_t> byDuration() const;

 private:
  long sliceOf(double frequency) const {
    return sliced() ? static_cast<long>(std::floor(frequency / slice_width_)) : 0;
  }

  int bins_;
  double window_, window_span_, theta_per_rate_;
  int max_order_;
  double tolerance_, max_gap_, slice_width_;
  int max_slices_;
  int slice_count_ = 0;
  std::vector<RateGroup> groups_;
};

/// The regression group of a plateau at `rate`: the index in *rates of the last rate within
/// `tolerance` of it, or a new entry (appended) when none is.
inline int regressionGroupOf(std::vector<double>* rates, double rate, double tolerance) {
  int group = -1;
  for (std::size_t g = 0; g < rates->size(); ++g)
    if (std::abs((*rates)[g] - rate) <= tolerance) group = static_cast<int>(g);
  if (group < 0) {
    group = static_cast<int>(rates->size());
    rates->push_back(rate);
  }
  return group;
}

}  // namespace core
}  // namespace hrg_gyro
