// The virtual rotation a field calibration commands, planned from its settings: a rest at 0, then
// one segment per entry of `directions`, each at +-rate for long enough that its settled data sweep
// `turns` full turns of theta (the plateau's settle time first, half a smoothing span lost at its
// end, a second to spare), then 0 again. The live calibrator sends these commands on
// command/precession; a scenario's dynamics.commands may carry the same plan for an offline session.
//
// What the plan's rate costs: a wave precessed faster leaves the loops further behind, and the part
// of that lag which keeps its sign both ways reads as drift (precessionLagDrift). For a gyro whose
// resonator the settings describe (field.resonator), fieldLoopLag predicts it.
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_settings.h"

namespace hrg_gyro {
namespace core {

/// The longest plan, s: a day of a still vehicle.
constexpr double kMaxFieldPlanDuration = 86400.0;

struct PlannedPrecession {
  double time = 0.0;  ///< s from the start of the plan
  double rate = 0.0;  ///< rad/s, electrical, commanded from `time` on
};

/// The commands in order; the last one (rate 0) ends the virtual rotation. Throws
/// std::invalid_argument when the plan would last longer than kMaxFieldPlanDuration (or for ever).
std::vector<PlannedPrecession> fieldCommandPlan(const CalibrationSettings& settings);
/// s of one segment at the settings' rate.
double fieldSegmentDuration(const CalibrationSettings& settings);
/// s from the plan's start to its last command (rest + one segment per direction); may be infinite.
double fieldPlanDuration(const CalibrationSettings& settings);
/// "the plan lasts ...: ..." when it is longer than kMaxFieldPlanDuration (or not finite), else "".
std::string fieldPlanLengthProblem(const CalibrationSettings& settings);

/// The largest drift (rad/s, the peak over theta) the loops' lag adds to a wave precessed at `rate`
/// for the gyro of field.resonator; NaN when that is unknown.
double fieldLoopLag(const FieldSettings& field, double rate);
/// Throws std::invalid_argument when the planned run cannot be carried out or cannot pass: a plan
/// too long, or (field.resonator known) a loop lag at field.rate above field.max_drift_std, which
/// the loop_lag gate (the lag within the largest standard error of a D term, itself within
/// max_drift_std) would always refuse. The live calibrator calls it before commanding anything.
void checkFieldPlan(const CalibrationSettings& settings);

}  // namespace core
}  // namespace hrg_gyro
