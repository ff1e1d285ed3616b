// Stage 3 of a triad calibration (triad_calibration.h): the body bias.
//
// In every rest of a locked fixture position (a settled static plateau of triad/min_rest s or more),
// each axis's mean compensated rate -- the slope of its alpha over the rest, with the standard error
// of its residuals -- against the Earth's 3-D rate in the body frame (the site's latitude, the table's
// azimuth from the settings, the table angle at rest, the position's logged orientation). A rest's
// bias is M rates - Earth; the body bias is their mean. Its standard error is the rests' noise (or
// their scatter, if larger, from three rests on) plus stage 1's D(theta) uncertainty at the angles
// where the waves rested: that part is common to the rests and does not shrink with them. No rest:
// the prior's bias is kept, and a note says so. No ROS.
#pragma once

#include <Eigen/Core>

#include "hrg_gyro/core/calibration/triad/triad_calibration_settings.h"
#include "hrg_gyro/core/calibration/triad/triad_outcome.h"
#include "hrg_gyro/core/calibration/triad/triad_position_samples.h"

namespace hrg_gyro {
namespace core {

/// The Earth's rate in the platter's frame (z up along the table axis, x at the table's zero mark
/// turned by the table angle): the zero mark points at `azimuth` from North towards East, and a
/// positive (counter-clockwise seen from above) table angle turns it towards West. rad, rad/s.
Eigen::Vector3d earthInPlatter(double latitude, double azimuth, double table_angle);

/// Each rest of `position` appended to o->rests, measured as above (o->axes: stage 1's outcomes,
/// whose D(theta) uncertainty enters axis_drift_std); `latitude` the site's, rad.
void measureRests(const TriadLockedPosition& position, double latitude, const TriadCalibrationSettings& settings,
                  TriadOutcome* o);

/// Each rest's bias through M = o->triad.axis_to_body, and the body bias with its standard error
/// into o->triad (bias_estimated set); a note when o->rests is empty.
void estimateBodyBias(const TriadCalibrationSettings& settings, TriadOutcome* o);

}  // namespace core
}  // namespace hrg_gyro
