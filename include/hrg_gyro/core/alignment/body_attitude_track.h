// The triad body's attitude through an alignment window, from its own increments alone: every
// rotation of the base (a lean, a knock, a sway, a yaw jitter) and the Earth's turn, as the gyros
// measured them. The reference is the body at the window's start, b0, which does not rotate: an
// inertial frame for the window. Per sample k (body increment dtheta_k over dt_k):
//
//   C_k = C_{k-1} Exp(dtheta_k + dtheta_{k-1} x dtheta_k / 12)        (C: body -> b0, C_0 = I)
//
// the second term the coning correction of two successive increments (exact for a rotation whose
// rate changes linearly within two samples). Between samples the attitude is the earlier one turned
// by its sample's increment in proportion to the time. For the budget the track also keeps
// S(t) = int_0^t C ds: a constant gyro bias e turns the computed attitude by S(t) e (b0 frame).
// A sample that does not start where the previous ended is not added (add() returns false): the
// body's turn over a gap is unknown. No ROS.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <vector>

namespace hrg_gyro {
namespace core {

class BodyAttitudeTrack {
 public:
  /// `start`: s, the track's first instant (the first sample's start).
  explicit BodyAttitudeTrack(double start = 0.0);

  /// One sample ending at `t` s, lasting `dt` s; false (nothing added) unless it starts where the
  /// previous ended (within a tenth of dt) and dt > 0.
  bool add(double t, double dt, const Eigen::Vector3d& increment);

  std::size_t size() const { return time_.size() - 1; }  ///< samples
  double start() const { return time_.front(); }
  double end() const { return time_.back(); }
  /// C at `t` (clamped to the track), body -> b0.
  Eigen::Matrix3d attitudeAt(double t) const;
  /// S(t) = int C ds from the start to `t` (clamped), rad per rad/s of a body bias.
  Eigen::Matrix3d biasResponseAt(double t) const;
  /// The mean rate over the whole track, rad/s, b0 frame: the rotation vector of C(end) over its length.
  Eigen::Vector3d meanRate() const;

 private:
  std::size_t segmentOf(double t) const;  // k with time_[k-1] <= t <= time_[k]

  std::vector<double> time_;                  // sample ends; [0] the start
  std::vector<Eigen::Quaterniond> attitude_;  // C at time_[k]
  std::vector<Eigen::Vector3d> increment_;    // the k-th sample's corrected increment (at index k)
  std::vector<Eigen::Matrix3d> integral_;     // S at time_[k]
  Eigen::Vector3d previous_ = Eigen::Vector3d::Zero();
};

}  // namespace core
}  // namespace hrg_gyro
