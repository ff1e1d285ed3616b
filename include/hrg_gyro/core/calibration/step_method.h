// The step calibration method ("step", docs/math.md 'Calibration methods', method 1): the table
// steps its angle between dwells; each step's wave-angle change over the table's gives K at the
// step's mid angle, each dwell's rest rate gives D at the dwell's angle (the Earth rate's share,
// K Omega_E, taken off). Memory is bounded by the bins.
#pragma once

#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/estimation/dwell_fit.h"

namespace hrg_gyro {
namespace core {

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

}  // namespace core
}  // namespace hrg_gyro
