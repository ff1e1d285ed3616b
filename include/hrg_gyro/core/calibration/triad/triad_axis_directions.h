// Stage 2 of a triad calibration (triad_calibration.h): the axes' directions A in the body frame.
//
// In every locked fixture position, each axis's response c_i,p = A_i . u_p to the table's rate (u_p:
// the table's axis in the body frame, from the position's logged orientation). Over the position's
// moving plateaus, window means (triad/window s) of the axes' compensated angles alpha_i, the table
// angle phi, the time and the integrals C, S of cos phi and sin phi; their increments fitted by least
// squares as alpha_i = c_i phi + b_i t + e_c C + e_s S (b_i: the axis's residual bias; e_c, e_s: the
// Earth's horizontal rate, which turns with the table). The standard error of c_i is the sandwich
// over the increments' covariance a D D^T + b I: a the window means' own noise (neighbouring
// increments share a window mean, so along a plateau it telescopes), b noise white from increment to
// increment, both read from the residuals' lag-zero and lag-one covariances. A position with less than
// triad/min_position_time s of moving plateaus gives no response (a note says so).
//
// A_i is then the weighted least-squares solution over the positions' responses: at least three
// independent table-axis directions are needed (refused otherwise, the missing body axes named); where
// the positions disagree beyond their errors, the scatter widens A's. M = A^-1 with its standard
// errors (axis_to_body_matrix.h), and the gate on the largest |A - I|. No ROS.
#pragma once

#include <string>

#include "hrg_gyro/core/calibration/triad/triad_calibration_settings.h"
#include "hrg_gyro/core/calibration/triad/triad_outcome.h"
#include "hrg_gyro/core/calibration/triad/triad_position_samples.h"

namespace hrg_gyro {
namespace core {

/// The positions that put body axis `body_axis` (0..2) along the table axis, as the refusals name
/// them: "+x or -x".
std::string alongTableAxis(int body_axis);

/// The axes' responses to the table's rate in `position`, appended to o->positions; or a note when
/// the position turned the table for less than triad/min_position_time.
void measureResponses(const TriadLockedPosition& position, const TriadCalibrationSettings& settings, TriadOutcome* o);

/// A from o->positions, M = A^-1 and their standard errors into *o, with the gate "misalignment".
/// False, with the gate "positions" failed (naming the body axes no position put along the table
/// axis, then `refusal_note`), when the positions' table axes do not span the body frame.
bool fitAxisDirections(const TriadCalibrationSettings& settings, const std::string& refusal_note, TriadOutcome* o);

}  // namespace core
}  // namespace hrg_gyro
