// The chains of window increments that the dual-rate and field methods feed their exact regression
// (increment_regression.h), and the window each chain averages over.
//
// A chain is the run of samples of one settled plateau: a new plateau, a gap in the stamps beyond
// plateau/max_gap or a stamp that is not ahead starts the next one, so that no increment spans a
// change of rate. Plateaus whose rates lie within group_tolerance share a regression group. The
// window is sized for the fitted harmonics: the highest order's phase advances at most 1 rad in it
// (the increments then keep >= 92 % of that harmonic), the wave angle at most window_span, and
// `window` bounds it; the regression is exact for any window.
#pragma once

#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/estimation/increment_regression.h"

namespace hrg_gyro {
namespace core {

class IncrementChains {
 public:
  /// top_order: the highest harmonic order fitted (maxFittedOrder); theta_per_rate: radians of
  /// theta per radian of the plateau's rotation (|K0| on a table, 1 for a commanded virtual rate).
  IncrementChains(const CalibrationSettings& settings, int top_order, double theta_per_rate);

  /// The averaging window of a chain at this plateau rate, s.
  double window(double plateau_rate) const;
  /// Swept time a theta bin needs to count (coverage) and to enter the fit: a quarter of the window.
  double minBinTime(double plateau_rate) const { return 0.25 * window(plateau_rate); }

  /// Takes the sample as the chain's newest; when it starts a new chain, starts it in `regression`
  /// (group and window from the plateau's rate) and returns true.
  bool follow(const PlateauSample& s, IncrementRegression* regression);
  /// s from the chain's previous sample to the newest (meaningful when follow() returned false).
  double sinceLast() const { return since_last_; }

 private:
  double window_, window_span_, max_gap_, group_tolerance_;
  int top_order_;
  double theta_per_rate_;
  std::vector<double> group_rates_;  // plateau rate of each regression group
  bool in_chain_ = false;
  std::uint64_t chain_plateau_ = 0;
  Nanoseconds last_stamp_ = 0;
  double since_last_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
