// North-finding on a base that moves: the attitude tracked by the gyros, gravity followed in the
// inertial frame. Where the still-base fit reads a lean or a sway as Earth rate, this estimator lets
// the gyros carry every rotation of the body and takes from the accelerometer only what the Earth
// alone can do to it: turn gravity about the Earth's axis.
//
// Frames: b0 the body at the window's start, n0 ENU at the window's start; both are inertial for the
// window. The gyros give C(t) = body -> b0 (BodyAttitudeTrack). At rest the specific force in ENU is
// (0, 0, g) (REP-145), so in n0 it turns with the site about the Earth's axis u = (0, cos lat, sin lat):
// f_n0(t) = Rot(u, Omega t) (0, 0, g). Measured, f_b0(t) = C(t) f_body(t) has the body's motion removed
// by the gyros, so one constant rotation C0 (b0 -> n0) remains: f_n0 = C0 f_b0. Both sides integrated
// from the start (the velocity, V_b0 and V_n0, exact in closed form for V_n0) turn a sway's or an
// engine's acceleration into a bounded velocity while gravity's turn grows as t^2:
//   coarse  V_b0(t) ~ a t + b t^2 by least squares, the same for V_n0; C0 by TRIAD from the gravity
//           direction a and the direction of its turn a x b (the East).
//   fine    zero velocity: with C0 = (I + [psi x]) C0^, y(t) = C0^ V_b0(t) - V_n0(t) = [C0^ V_b0 x] psi
//           + v(t) (the base's velocity, ~0) + noise; psi and a vertical velocity slope (g's local
//           value, the accelerometer's vertical bias and scale) fitted by weighted least squares on
//           the velocities every ~0.1 s (IntegratedAngleFit: the accelerometer's white noise is a
//           random walk of the velocity, the base's vibration a white velocity noise; both measured
//           from the residuals' Allan variance, 3 Q^2 / tau^2 + N^2 / tau), two Gauss-Newton steps.
//           It is the batch form of the zero-velocity Kalman filter with constant biases: the same
//           states and measurement, solved over the window at once.
// The heading is that of the direction gravity turns (the North velocity's t^2 term, g Omega cos(lat)
// t^2 / 2 per rad of heading); the accelerometer's noise limits it (N sqrt(12 / T^3) / (g Omega
// cos(lat)): 2.5e-4 m/s/sqrt(s) over 300 s at 0.9 rad gives 0.38 mrad), not the gyros', and no
// rotation of the base enters it. What stays as in the still fit: a gyro bias b turns the computed
// attitude (b_East / (Omega cos(lat)) of heading), an accelerometer's bias or mounting tips the
// turning gravity (e tan(lat)). Each enters the budget through the fit's exact response to it.
// The attitude given is the body's at the track's end: Rot(u, -Omega T) C0 C(T). No ROS.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "hrg_gyro/core/alignment/body_attitude_track.h"

namespace hrg_gyro {
namespace core {

struct InertialFrameInput {
  double latitude = 0.0;                     ///< rad
  std::vector<double> accel_time;            ///< s, each record's stamp on the track's clock
  std::vector<Eigen::Vector3d> accel_force;  ///< m/s^2, body frame (the mounting applied), at its stamp
  // What the budget takes as known, 1 sigma per body axis.
  double gyro_bias = 0.0;               ///< rad/s, the calibration's residual bias
  double gyro_drift_harmonics = 0.0;    ///< rad/s, D(theta)'s residual at resting waves
  double gyro_rate_random_walk = 0.0;   ///< rad/s/sqrt(s): taken as a bias of variance K^2 T / 3
  double gyro_angle_random_walk = 0.0;  ///< rad/sqrt(s): taken as a bias of variance (6/5) N^2 / T
  double accel_bias = 0.0;              ///< m/s^2
  double accel_mounting = 0.0;          ///< rad, the mounting rotation's error about each axis
};

/// Each source's share of the covariance of the attitude at the end (ENU small rotation, rad^2).
struct InertialFrameBudget {
  Eigen::Matrix3d noise = Eigen::Matrix3d::Zero();  ///< the accelerometer's and the base's velocity noise
  Eigen::Matrix3d residual_bias = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d drift_harmonics = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d bias_random_walk = Eigen::Matrix3d::Zero();  ///< the gyros' rate and angle random walks
  Eigen::Matrix3d level = Eigen::Matrix3d::Zero();             ///< the accelerometer's bias and mounting
  Eigen::Matrix3d total() const { return noise + residual_bias + drift_harmonics + bias_random_walk + level; }
};

struct InertialFrameResult {
  bool ok = false;
  std::string problem;                                                ///< why nothing was solved
  Eigen::Matrix3d start_to_enu = Eigen::Matrix3d::Identity();         ///< C0: b0 -> n0
  Eigen::Matrix3d end_to_enu = Eigen::Matrix3d::Identity();           ///< the body at the end -> ENU then
  Eigen::Matrix3d coarse_start_to_enu = Eigen::Matrix3d::Identity();  ///< the TRIAD solution
  InertialFrameBudget budget;                                         ///< at the end
  /// The attitude error at the end that a constant body bias leaves, rad per rad/s (hold's start).
  Eigen::Matrix3d bias_to_attitude = Eigen::Matrix3d::Zero();
  double velocity_white = 0.0;        ///< m/s: the base's velocity noise measured
  double velocity_random_walk = 0.0;  ///< m/s/sqrt(s): the accelerometer's white noise measured
  double scatter = 0.0;               ///< rms residual over the noise model's, worst horizontal channel
  double gravity = 0.0;               ///< m/s^2, |mean specific force|
  Eigen::Vector3d up_start = Eigen::Vector3d::UnitZ();  ///< unit, the vertical in b0 the accelerometer gives
  std::size_t records = 0;                              ///< accelerometer records used
  double seconds = 0.0;                                 ///< the track's length
};

/// Aligns from a track and the accelerometer's records within it. Refused (ok false) with fewer than
/// 100 records or 10 s, or when gravity's turn cannot be told from noise.
InertialFrameResult alignInInertialFrame(const BodyAttitudeTrack& track, const InertialFrameInput& input);

/// int_0^t Rot(u, Omega s) v ds: the specific force of a site at rest integrated in the frame frozen
/// at its start, closed form (u unit).
Eigen::Vector3d turningGravityIntegral(const Eigen::Vector3d& u, const Eigen::Vector3d& v, double t);

}  // namespace core
}  // namespace hrg_gyro
