// The one place a calibration method kind becomes its implementation (declared with the interface,
// calibration_method_interface.h): the single-axis methods, a file each. The triad is calibrated by
// its own session (triad_calibration.h) and is refused here.
#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/calibration/constant_rate_method.h"
#include "hrg_gyro/core/calibration/correction_matrix_method.h"
#include "hrg_gyro/core/calibration/dual_rate_method.h"
#include "hrg_gyro/core/calibration/field_method.h"
#include "hrg_gyro/core/calibration/step_method.h"
#include "hrg_gyro/core/calibration/thermal_method.h"

namespace hrg_gyro {
namespace core {

std::unique_ptr<CalibrationMethod> makeCalibrationMethod(const CalibrationSettings& s, const GyroParameters& prior) {
  const double k0 = std::abs(prior.scale_factor.meanAt(NAN));
  switch (s.method) {
    case CalibrationMethodKind::kDualRate:
      return std::make_unique<DualRateMethod>(s, k0);
    case CalibrationMethodKind::kConstantRate:
      return std::make_unique<ConstantRateMethod>(s, k0);
    case CalibrationMethodKind::kStep:
      return std::make_unique<StepMethod>(s);
    case CalibrationMethodKind::kCorrectionMatrix:
      return std::make_unique<CorrectionMatrixMethod>(s);
    case CalibrationMethodKind::kTriad:
      throw std::invalid_argument(
          "the triad method calibrates three axes at once: give it a triad session (hrg_bag calibrate --method triad "
          "on a bag with the three axes' channels and the fixture's positions, or the calibrator in triad mode)");
    case CalibrationMethodKind::kThermal:
      return std::make_unique<ThermalMethod>(s, k0);
    case CalibrationMethodKind::kField:
      return std::make_unique<FieldMethod>(s);
  }
  throw std::invalid_argument("calibration method out of range");
}

}  // namespace core
}  // namespace hrg_gyro
