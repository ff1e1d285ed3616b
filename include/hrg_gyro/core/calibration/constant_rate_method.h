// The constant-rate calibration method ("constant_rate", docs/math.md 'Calibration methods',
// method 2): the theta-binned rate at one table rate gives K(theta), a dwell at rest the rest rate
// K Omega_E + D; D(theta)'s harmonics cannot be told from K's and leak into it by D_k / Omega, so
// the drift written is the constant D0. Memory is bounded by the bins.
#pragma once

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/estimation/dwell_fit.h"
#include "hrg_gyro/core/estimation/rate_groups.h"

namespace hrg_gyro {
namespace core {

class ConstantRateMethod : public CalibrationMethod {
 public:
  /// k0: the prior's mean scale factor (the angle rate per table rate, for the window length).
  ConstantRateMethod(const CalibrationSettings& settings, double k0);
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kConstantRate; }
  void addSample(const PlateauSample& s) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;

 private:
  double minBinTime() const { return 0.25 * settings_.window; }
  double dwellTime() const;
  void closeDwell();
  CalibrationSettings settings_;
  RateGroups groups_;
  // Rest rate: duration-weighted slopes of the completed dwells plus the current one.
  double rest_weighted_slope_ = 0.0, rest_weight_ = 0.0, rest_time_ = 0.0, rest_noise_ = 0.0;
  DwellFit dwell_;
  std::uint64_t dwell_plateau_ = 0;
  std::uint64_t samples_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
