// What the ground under a fixture does while a session runs: the base that a gyrocompass assumes
// still, moving about its rest attitude as a real bench, vehicle or floor does. A scenario's
// `base_motion` section (off by default; docs/simulation.md, "A base that moves"):
//
//   leans       a rotation that grows over `duration` s as a raised cosine and stays: a person leaning
//               on the table, the floor settling. `rotation` is its rotation vector in ENU, rad.
//   knocks      a step of `rotation` over 0.05 s plus a ringing about the same axis, `ring` times the
//               step's size, at `ring_frequency` Hz, decaying with `ring_decay` s: a door slam, a
//               dropped tool. It leaves the base turned by `rotation`.
//   sways       amplitude sin(2 pi t / period + phase) rad about `axis` (ENU): a mast, a ship, a
//               vehicle on its suspension.
//   yaw_jitter  a band-limited random rotation about Up, `rms` rad over `low`..`high` Hz: a vehicle's
//               engine mount, a bench on a soft floor.
//   vibration   linear acceleration of the base, `rms` m/s^2 per ENU axis over `low`..`high` Hz: an
//               engine running. It moves nothing the gyros see; the accelerometer reads it.
// The random parts are sums of `components` sinusoids (frequencies uniform in the band, random
// phases, equal amplitudes), drawn from the scenario's seed: every value is exact and so are its
// derivative and integral, at any time.
//
// The base's attitude is the rotation D(t) in ENU, applied to everything on it: a body whose
// attitude on a still base is C_nominal(t) has C(t) = D(t) C_nominal(t) (body -> ENU). D composes the
// motions in the order above, D = D_lean... D_knock... D_sway... D_yaw, each a rotation about a fixed
// axis; its ENU angular velocity w (dD/dt = [w x] D) follows from theirs. The body's inertial rate is
// then C^T (Omega_n + w) + the nominal motion's own rate relative to the Earth (in the body frame).
// No ROS.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {

struct BaseLean {
  double time = 0.0;                                   ///< s from the scenario start
  double duration = 1.0;                               ///< s, > 0
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  ///< rad, ENU rotation vector
};

struct BaseKnock {
  double time = 0.0;                                   ///< s
  Eigen::Vector3d rotation = Eigen::Vector3d::Zero();  ///< rad, ENU: what it leaves
  double ring = 2.0;                                   ///< ringing amplitude over the step's size
  double ring_frequency = 8.0;                         ///< Hz
  double ring_decay = 0.15;                            ///< s
};

struct BaseSway {
  double amplitude = 0.0;                           ///< rad
  double period = 10.0;                             ///< s, > 0
  Eigen::Vector3d axis = Eigen::Vector3d::UnitX();  ///< ENU, unit
  double phase = 0.0;                               ///< rad
};

/// A band of random sinusoids: rms over [low, high] Hz.
struct BaseBand {
  double rms = 0.0;
  double low = 0.5, high = 5.0;  ///< Hz
  int components = 20;
};

struct BaseMotionConfig {
  std::vector<BaseLean> leans;
  std::vector<BaseKnock> knocks;
  std::vector<BaseSway> sways;
  BaseBand yaw_jitter{0.0, 0.5, 5.0, 20};   ///< rad
  BaseBand vibration{0.0, 10.0, 40.0, 20};  ///< m/s^2 per ENU axis
  bool enabled() const;
  /// Throws ConfigError naming the key ("base_motion.leans[0].duration").
  void validate(const std::string& prefix = "base_motion") const;
};

/// Reads the section (a map: leans, knocks, sways, yaw_jitter, vibration), refusing unknown keys.
BaseMotionConfig parseBaseMotion(const YamlField& section);

/// The base's motion at any time: exact, from a config and a seed (the random bands' draws).
class BaseMotion {
 public:
  BaseMotion() = default;
  BaseMotion(const BaseMotionConfig& config, std::uint64_t seed);

  bool enabled() const { return enabled_; }
  /// D(t), ENU -> ENU (identity when still).
  Eigen::Matrix3d rotationAt(double t) const;
  /// D(t) and its ENU angular velocity w (dD/dt = [w x] D), rad/s.
  void stateAt(double t, Eigen::Matrix3d* rotation, Eigen::Vector3d* rate) const;
  /// The base's linear acceleration in ENU, m/s^2 (the vibration).
  Eigen::Vector3d accelerationAt(double t) const;
  /// Its mean over [a, b] (what an accelerometer that reports delta-velocity / dt reads), m/s^2.
  Eigen::Vector3d meanAccelerationOver(double a, double b) const;

 private:
  struct Sine {
    double amplitude, omega, phase;  // rad (or m/s^2), rad/s, rad
  };
  // One rotation about a fixed axis: its angle and the angle's rate at t.
  struct Part {
    Eigen::Vector3d axis;
    enum Kind { kLean, kKnock, kSway, kYaw } kind;
    std::size_t index;
  };
  void angleOf(const Part& part, double t, double* angle, double* rate) const;

  bool enabled_ = false;
  BaseMotionConfig config_;
  std::vector<Part> parts_;
  std::vector<Sine> yaw_;
  std::vector<Sine> vibration_[3];
};

}  // namespace core
}  // namespace hrg_gyro
