// Attitude hold after an alignment: the triad's body angle increments integrated from the aligned
// attitude, the Earth's rate removed in the local-level frame, giving the orientation body -> ENU and
// a covariance that grows as the gyros' noise and bias say. The frame is the site's ENU: the vehicle's
// own travel over the Earth (transport rate, a moving local level) is out of scope, as are velocity and
// position. Frames and signs: local_level.h.
//
// Orientation, per triad sample (delta_angle over dt):   C <- exp(-[Omega_n x] dt) C exp([delta_angle x])
//
// Error state: the attitude error delta (ENU small rotation, C_true = (I + [delta x]) C), the triad's
// body bias error b (rad/s) and its scale-factor errors s (relative, per body axis):
//   d delta/dt = -Omega_n x delta - C (b + diag(omega) s + n),    db/dt = w,    ds/dt = 0
// n the rate noise of an angle random walk N, w that of a rate random walk K; s starts at
// scale_factor_sigma, so a turning body's heading sigma grows with the angle it turned. Its covariance starts
// from the alignment's: the attitude's, the bias the triad carries at rest (the calibration's residual
// bias and its D(theta) at resting waves), and their cross-covariance (a static alignment's heading
// error is the bias's own image, b_East / (Omega cos(lat)), and the two cancel in the East tilt's drift
// at rest). It is propagated every `covariance_interval` s (through the sum of C dt over the block),
// and the reported covariance adds the white angle noise of the latest angle and of the aligned one
// (2 s^2 per axis, which does not accumulate). At rest the heading's variance then grows as
//   sigma_yaw^2(t) ~ sigma_yaw^2(0) + N^2 t + (b_Up^2 + K^2 t / 3) t^2 (+ the Earth rate's coupling of the
// tilts into the heading, which the propagation carries).
// Time, the one stamp rule (stamp_timeline.h; forward_jump 1 s, backward_reset 0.5 s, jump_persist 5):
// a glitched stamp is dropped and counted; a sample whose dt its stamps contradict (beyond 1.5 times
// the spacing) too. Up to `max_bridge` s of lost samples (one glitched, one dropped) are bridged: the
// body turned at the last sample's rate, the covariance grown by that rate's own noise (two angle
// noises over a sample) over the missing time, counted in bridged(). A longer gap, a gap or reset the
// triad flags, a stream that jumps for good, or a wave turned on command (the rate is not the body's)
// loses the attitude: the body's turn over it is unknown; align again. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>

#include "hrg_gyro/core/alignment/alignment_result.h"
#include "hrg_gyro/core/alignment/alignment_settings.h"
#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/processing/triad_combiner.h"

namespace hrg_gyro {
namespace core {

struct AttitudeHoldSettings {
  double latitude = NAN;  ///< rad
  /// The triad's noise per body axis: N, K and the white angle noise (negative: the alignment's
  /// measured one). The residual bias comes with the alignment.
  GyroNoiseModel noise;
  /// Relative scale-factor error per body axis, 1 sigma (the triad calibration's K standard error);
  /// NaN: not given (required).
  double scale_factor_sigma = NAN;
  double covariance_interval = 0.1;  ///< s between covariance propagations
  double max_bridge = 0.05;          ///< s of lost samples bridged at the last rate, [0, 1]
  /// Throws ConfigError naming the key.
  void validate() const;
};

/// Where a hold starts.
struct HoldStart {
  Nanoseconds stamp = 0;  ///< its attitude's time: the last gyro sample of the window
  Eigen::Quaterniond body_to_enu = Eigen::Quaterniond::Identity();
  Eigen::Matrix3d covariance_enu = Eigen::Matrix3d::Zero();            ///< rad^2
  double bias_variance = 0.0;                                          ///< (rad/s)^2 per body axis
  Eigen::Matrix3d attitude_bias_covariance = Eigen::Matrix3d::Zero();  ///< rad rad/s
  double white_noise = 0.0;                                            ///< rad per sample and axis
};

/// The start an accepted alignment of the triad gives (its body at the window's end). Throws
/// std::invalid_argument for a refused one or one of a single gyro (no triad to hold with).
HoldStart holdStartFrom(const AlignmentResult& aligned);

class AttitudeHold {
 public:
  /// Throws ConfigError for bad settings.
  AttitudeHold(const AttitudeHoldSettings& settings, const HoldStart& start);

  /// One triad sample, in stamp order; samples at or before the latest are dropped (counted). Returns
  /// false once the attitude is lost (and for every sample after).
  bool add(const TriadBodySample& sample);

  bool holding() const { return lost_.empty(); }
  const std::string& lostReason() const { return lost_; }
  Nanoseconds stamp() const { return stamp_; }
  double elapsed() const { return elapsed_; }  ///< s since the start
  std::uint64_t dropped() const { return dropped_; }
  std::uint64_t bridged() const { return bridged_; }  ///< samples lost and bridged

  Eigen::Quaterniond orientation() const { return q_; }  ///< body -> ENU
  EulerAngles attitude() const { return eulerFromOrientation(q_); }
  /// rad^2, ENU small rotation (x East tilt, y North tilt, z heading).
  Eigen::Matrix3d covariance() const;
  /// rad^2, of (roll, pitch, yaw).
  Eigen::Matrix3d covarianceRpy() const { return eulerCovarianceFromEnu(attitude(), covariance()); }
  double heading() const { return trueHeadingDegrees(attitude().yaw); }  ///< deg, true, clockwise from North
  double headingSigma() const;                                           ///< deg, 1 sigma
  /// The whole error state's covariance (delta, b, s), 9 x 9.
  Eigen::Matrix<double, 9, 9> stateCovariance() const;

 private:
  using State = Eigen::Matrix<double, 9, 9>;
  void propagate(State* p) const;  // the pending block into *p
  void lose(const std::string& reason);
  // The stamp rule and the bridge of lost samples; false: the sample is not used (dropped, or lost).
  bool timed(const TriadBodySample& sample);
  void integrate(const Eigen::Vector3d& increment, double dt);

  AttitudeHoldSettings settings_;
  Eigen::Vector3d earth_;
  Eigen::Quaterniond q_;
  State p_;
  double white_variance_ = 0.0, white_noise_ = 0.0;
  Nanoseconds stamp_ = 0;
  double elapsed_ = 0.0;
  // The block since the last propagation: its length, the sum of C dt and of C diag(increment).
  double block_ = 0.0;
  Eigen::Matrix3d block_c_dt_ = Eigen::Matrix3d::Zero(), block_c_angle_ = Eigen::Matrix3d::Zero();
  Eigen::Matrix3d bridge_ = Eigen::Matrix3d::Zero();  // the bridges' attitude variance, ENU, since the last block
  Eigen::Vector3d last_rate_ = Eigen::Vector3d::Zero();
  StampTimeline timeline_;
  std::string lost_;
  std::uint64_t dropped_ = 0, samples_ = 0, bridged_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
