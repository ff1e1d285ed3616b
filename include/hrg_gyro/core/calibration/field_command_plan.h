// The virtual rotation a field calibration commands, planned from its settings: a rest at 0, then
// one segment per entry of `directions`, each at +-rate for long enough that its settled data sweep
// `turns` full turns of theta (the plateau's settle time first, half a smoothing span lost at its
// end, a second to spare), then 0 again. The live calibrator sends these commands on
// command/precession; a scenario's dynamics.commands may carry the same plan for an offline session.
#pragma once

#include <vector>

#include "hrg_gyro/core/calibration/calibration_settings.h"

namespace hrg_gyro {
namespace core {

struct PlannedPrecession {
  double time = 0.0;  ///< s from the start of the plan
  double rate = 0.0;  ///< rad/s, electrical, commanded from `time` on
};

/// The commands in order; the last one (rate 0) ends the virtual rotation.
std::vector<PlannedPrecession> fieldCommandPlan(const CalibrationSettings& settings);
/// s of one segment at the settings' rate.
double fieldSegmentDuration(const CalibrationSettings& settings);

}  // namespace core
}  // namespace hrg_gyro
