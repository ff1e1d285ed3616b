// The correction-matrix calibration method ("correction_matrix", docs/math.md 'Correction matrix'):
// the pickoff's correction P from generator pairs, the raw channel amplitudes against the known
// wave's ideal ones (the first refinement stage; K and D are measured again through the new P).
// Memory is bounded by the estimator's normal equations.
#pragma once

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/model/correction_matrix.h"

namespace hrg_gyro {
namespace core {

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
