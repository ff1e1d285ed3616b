// Conversions between the core's types and ROS time and messages.
#pragma once

#include <string>

#include <ros/time.h>

#include "hrg_gyro/CalibrationResult.h"
#include "hrg_gyro/core/calibration_outcome.h"
#include "hrg_gyro/core/units.h"

namespace hrg_gyro {

inline core::Nanoseconds toNanoseconds(const ros::Time& t) {
  return static_cast<core::Nanoseconds>(t.sec) * 1000000000LL + static_cast<core::Nanoseconds>(t.nsec);
}

inline ros::Time toRosTime(core::Nanoseconds ns) {
  ros::Time t;
  t.fromNSec(static_cast<std::uint64_t>(ns < 0 ? 0 : ns));
  return t;
}

HarmonicEstimate toMessage(const core::HarmonicFitResult& fit, double frequency);
core::HarmonicFitResult fromMessage(const HarmonicEstimate& msg);

/// The outcome as a message; `written` and `file` say what happened to the parameter file.
CalibrationResult toMessage(const core::CalibrationOutcome& outcome, bool written, const std::string& file,
                            const ros::Time& stamp);
/// The parts of an outcome a message carries (for summaries built from a received result).
core::CalibrationOutcome fromMessage(const CalibrationResult& msg);

}  // namespace hrg_gyro
