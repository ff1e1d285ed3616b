// The dual-rate calibration method ("dual_rate", docs/math.md 'Calibration methods', method 3):
// window increments of the wave angle at two (or more) table rates, fitted by one exact regression
// (increment_regression.h) for K(theta), D(theta) and a bias trend at once; the drift cancels
// between the rates. Memory is bounded by the regression's sums and the bins, whatever the session
// length.
#pragma once

#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/calibration/increment_chains.h"
#include "hrg_gyro/core/estimation/increment_regression.h"
#include "hrg_gyro/core/estimation/rate_groups.h"

namespace hrg_gyro {
namespace core {

class DualRateMethod : public CalibrationMethod {
 public:
  /// k0: the prior's mean scale factor (the angle rate per table rate, for the window length).
  DualRateMethod(const CalibrationSettings& settings, double k0);
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kDualRate; }
  void addSample(const PlateauSample& s) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;
  /// Two more columns per slot in the increment regression (cos psi dt, sin psi dt).
  bool modelHorizontalEarthRate(int slots) override;

 private:
  /// Swept time a theta bin needs to count (coverage) and to enter the fit: a quarter of the window
  /// the increments at this table rate use, which is shorter than `window` at high rates.
  double minBinTime(double table_rate) const { return chains_.minBinTime(table_rate); }
  // The phases of finish(), in its order.
  /// The note on the error budget of the K harmonics (largest term of each kind) and the fit.
  void noteErrorBudget(const IncrementFit& e, CalibrationOutcome* o) const;
  /// The bias trend's gate: refused when the session cannot tell it from K0.
  void gateBiasTrend(const IncrementFit& e, CalibrationOutcome* o) const;
  /// The table's gate: what the data scatter beyond the wave-angle noise, charged to the table.
  void gateTableError(const IncrementFit& e, CalibrationOutcome* o) const;

  CalibrationSettings settings_;
  RateGroups groups_;  // coverage, progress and the plateau summaries
  // The estimate, with phi the session's table angle: the logged angle, or the integral of the
  // logged rate for a controller that logs none (the session decides, PlateauSample::angle_logged).
  // Where both are logged, the regression weighs the angle against the rate's integral (its slope
  // from the angle) by their measured noise: jittered stamps spoil the angle, not the integral.
  IncrementRegression regression_;
  IncrementChains chains_;
  double last_table_angle_ = 0.0, unwrap_ = 0.0;
  double rate_integral_ = 0.0, last_table_rate_ = 0.0;  // of the logged rate over the open chain
  bool angle_logged_ = true;                            // of the last sample: named in the report
  std::uint64_t samples_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
