// The four calibration methods (docs/math.md, 'Calibration methods' and 'Correction matrix'):
//   DualRateMethod         window increments at two (or more) table rates, one exact regression; drift
//                          cancels (method 3)
//   ConstantRateMethod     one table rate and a dwell for the rest rate; drift leaks into K (method 2)
//   StepMethod             steps of the table angle between dwells; the dwells give D (method 1)
//   CorrectionMatrixMethod P from generator pairs (the paper's first refinement stage)
// (and, in thermal_method.h, ThermalMethod: the dual-rate method across temperature)
// Each keeps memory bounded by its bins, whatever the session length.
#pragma once

#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/estimation/dwell_fit.h"
#include "hrg_gyro/core/estimation/increment_regression.h"
#include "hrg_gyro/core/estimation/rate_groups.h"
#include "hrg_gyro/core/model/correction_matrix.h"

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

 private:
  /// Swept time a theta bin needs to count (coverage) and to enter the fit: a quarter of the window
  /// the increments at this table rate use, which is shorter than `window` at high rates.
  double minBinTime(double table_rate) const { return 0.25 * windowFor(table_rate); }
  /// The averaging window of a plateau at this table rate, s (see docs/calibration.md).
  double windowFor(double table_rate) const;
  CalibrationSettings settings_;
  double k0_;
  RateGroups groups_;  // coverage, progress and the plateau summaries
  // The estimate, with phi the session's table angle: the logged angle, or the integral of the
  // logged rate for a controller that logs none (the session decides, PlateauSample::angle_logged).
  // Where both are logged, the regression weighs the angle against the rate's integral (its slope
  // from the angle) by their measured noise: jittered stamps spoil the angle, not the integral.
  IncrementRegression regression_;
  std::vector<double> group_rates_;  // plateau rate of each regression group
  bool in_chain_ = false;
  std::uint64_t chain_plateau_ = 0;
  Nanoseconds last_stamp_ = 0;
  double last_table_angle_ = 0.0, unwrap_ = 0.0;
  double rate_integral_ = 0.0, last_table_rate_ = 0.0;  // of the logged rate over the open chain
  bool angle_logged_ = true;                            // of the last sample: named in the report
  std::uint64_t samples_ = 0;
};

class ConstantRateMethod : public CalibrationMethod {
 public:
  ConstantRateMethod(const CalibrationSettings& settings, double k0);
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kConstantRate; }
  void addSample(const PlateauSample& s) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;

 private:
  double minBinTime() const { return 0.25 * settings_.window; }
  double dwellTime() const;
  CalibrationSettings settings_;
  RateGroups groups_;
  // Rest rate: duration-weighted slopes of the completed dwells plus the current one.
  double rest_weighted_slope_ = 0.0, rest_weight_ = 0.0, rest_time_ = 0.0, rest_noise_ = 0.0;
  DwellFit dwell_;
  std::uint64_t dwell_plateau_ = 0;
  std::uint64_t samples_ = 0;
  void closeDwell();
};

class StepMethod : public CalibrationMethod {
 public:
  explicit StepMethod(const CalibrationSettings& settings);
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kStep; }
  void addSample(const PlateauSample& s) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;

 private:
  struct StepBin {  // step results binned by mid angle; the fit uses their mean angle, not the bin centre
    double k_sum = 0.0, theta_sum = 0.0, span_sum = 0.0, count = 0.0;
  };
  struct DwellBin {
    double rate_sum = 0.0, theta_sum = 0.0, count = 0.0;
  };
  /// Bins the step between two consecutive dwells and the first dwell's rest rate.
  void pair(const DwellFit& before, const DwellFit& after);
  void closeDwell();
  double coverage() const;
  CalibrationSettings settings_;
  DwellFit current_, previous_;
  bool has_previous_ = false;
  std::uint64_t current_plateau_ = 0;
  std::vector<StepBin> steps_;
  std::vector<DwellBin> dwells_;
  std::vector<bool> swept_;  // theta sub-bins covered by some step
  int step_count_ = 0;
  double step_angle_sum_ = 0.0, step_time_sum_ = 0.0, endpoint_noise_sq_ = 0.0, dwell_time_ = 0.0;
  std::uint64_t samples_ = 0;
};

class CorrectionMatrixMethod : public CalibrationMethod {
 public:
  explicit CorrectionMatrixMethod(const CalibrationSettings& settings) : settings_(settings) {}
  CalibrationMethodKind kind() const override { return CalibrationMethodKind::kCorrectionMatrix; }
  void addSample(const PlateauSample&) override {}
  void addGeneratorPair(const ChannelVector& raw, const ChannelVector& reference) override;
  bool complete() const override;
  CalibrationProgress progress() const override;
  CalibrationOutcome finish(const GyroParameters& prior) const override;

 private:
  CalibrationSettings settings_;
  CorrectionMatrixEstimator estimator_;
  double reference_energy_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
