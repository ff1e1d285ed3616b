// The human summary of a calibrate-then-verify session, shared by the offline tool and the ROS
// main job so both print the same table: injected vs estimated harmonics, nonlinearity and angle
// error before/after, and the machine-readable last line
//   nonlinearity_ppm before=<X> after=<Y>
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/evaluation/output_evaluator.h"
#include "hrg_gyro/core/simulation/injected_model.h"

namespace hrg_gyro {
namespace core {

struct SessionSummary {
  EffectiveModel injected;  ///< what a perfect calibration would find
  CalibrationOutcome calibration;
  bool has_calibration = true;        ///< false: no calibration result arrived (printed as method none)
  EvaluationResult before, after;     ///< measured on the verification profile
  std::vector<std::string> warnings;  ///< printed before the machine-readable last line
};

void printSessionSummary(std::ostream& out, const SessionSummary& s);

}  // namespace core
}  // namespace hrg_gyro
