// A triad's axis-to-body matrix M (the triad file holds it with the bias: triad_parameters.h) and
// what it says. In SI units and REP-103 frames (right-handed, rad, rad/s):
//
//   omega_body = M omega_axis - bias        omega_axis = A (omega_body + bias),   A = M^-1
//
// omega_axis = (r_1, r_2, r_3): each axis's compensated inertial rate dalpha/dt (rad/s about its own
// sensitive axis, counter-clockwise positive seen from its tip), in the order of the triad's axes;
// omega_body: the inertial angular velocity of the body frame, in that frame. Row i of A is axis i's
// sensitive direction in the body frame times its residual scale. A is I plus small terms: its
// off-diagonal entries are the axes' six misalignment angles (A_ij: the tilt of axis i towards body
// axis j, rad) in full form, not triangular: the body frame is the fixture's (its mounting faces),
// tied to no axis. Its diagonal is 1 plus each axis's residual scale (what the per-axis K(theta)
// leaves, zero when K was calibrated on the same fixture). Covariances map as the rates do:
// Sigma_body = M diag(sigma_i^2) M^T (the combiner's, processing/triad_combiner.h).
//
// Here: the bound on |M - I| that a calibration and the file's loader enforce, the angles and scales
// read from A, and M's standard errors from A's (a calibration measures A). No ROS.
#pragma once

#include <Eigen/Core>
#include <string>

namespace hrg_gyro {
namespace core {

/// Largest |M_ij - I_ij| accepted: beyond it the axes are not the nominal body axes (a wrong axis
/// order or sign, a unit slip), which a calibration refuses to write and the loader to read.
constexpr double kMaxTriadMisalignment = 0.1;

/// max |X_ij - I_ij| of M or A: how far the axes are from the nominal body axes.
double largestMisalignment(const Eigen::Matrix3d& x);

/// The six misalignment angles A_ij and the three residual scales A_ii - 1 of A = M^-1, as text
/// for the reader of a triad file (two lines, "misalignment A_ij, rad: xy ..." and "residual scale").
std::string describeAlignment(const Eigen::Matrix3d& body_to_axis);

/// The standard errors of M = A^-1 from those of A's entries (`a_std`), taken as independent:
/// dM = -M dA M, each entry's variance the sum of its terms' squares.
Eigen::Matrix3d axisToBodyStd(const Eigen::Matrix3d& axis_to_body, const Eigen::Matrix3d& body_to_axis_std);

}  // namespace core
}  // namespace hrg_gyro
