// The motion of a triad's body on the rate table (TriadSimulationConfig), exactly, at any time: the
// table angle and rate, the body's true orientation in the table frame and its inertial rate
//
//   omega_body = R^T W^T (phidot e_z + Rz(phi)^T omega_E0) + sdot(u) rho
//
// with R the body's orientation on the platter (the position's Exp(error) R_nominal, or during a
// move R_previous Exp(s(u) rho), rho the move's rotation vector in the body frame), W the platter's
// wobble tilt, phi the table angle and omega_E0 the Earth's rate in the table-zero frame. The moves
// turn about a fixed body axis, so the body sees their rate along rho alone. The body's attitude in
// ENU is the one place the truth of heading and level comes from (the accelerometer, the tests).
//
// On a moving base (TriadSimulationConfig::base_motion, base_motion.h) the whole table stands on a
// base turned by D(t) in ENU, with ENU rate w (dD/dt = [w x] D): the attitude is C = D C_nominal,
// C_nominal the still base's, and as dC/dt = [w x] C + D dC_nominal/dt,
//
//   omega_body = omega_nominal + (C^T - C_nominal^T) Omega_enu + C^T w,
//
// Omega_enu = W (0, cos lat, sin lat). The table frame turns with D (tableFrameRateAt has the same
// share); the table angle, the positions and body_to_table are relative to the base and do not.
// Without a base motion nothing of it is evaluated: the values are those of a still base, bit for bit.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

#include "hrg_gyro/core/simulation/base_motion.h"
#include "hrg_gyro/core/simulation/triad_simulation_config.h"

namespace hrg_gyro {
namespace core {

struct TriadBodyState {
  double table_angle = 0.0;                                       ///< rad, Earth-fixed (the encoder's angle)
  double table_rate = 0.0;                                        ///< rad/s
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();     ///< rad/s, inertial, in the body frame
  Eigen::Matrix3d body_to_table = Eigen::Matrix3d::Identity();    ///< true: fixture error and wobble included
  Eigen::Matrix3d body_to_platter = Eigen::Matrix3d::Identity();  ///< true, without the wobble
  /// The true attitude, body -> ENU: D Rz(pi/2 - azimuth) Rz(table_angle) body_to_table.
  Eigen::Matrix3d body_to_enu = Eigen::Matrix3d::Identity();
  /// D, the base's rotation in ENU (identity on a still base).
  Eigen::Matrix3d base_rotation = Eigen::Matrix3d::Identity();
  std::size_t position = 0;  ///< index of the position; during a move, the one being moved into
  bool locked = true;        ///< false while the fixture is being moved
};

class TriadMotion {
 public:
  explicit TriadMotion(const TriadSimulationConfig& config);

  /// Everything at t s from the scenario start; after the end the last position holds.
  TriadBodyState stateAt(double t) const;
  /// omega_body alone (the axes' inputs call it several times per resonator period).
  Eigen::Vector3d angularVelocityAt(double t) const;
  /// The Earth's rate plus the table's (and the base's), in the table frame: its inertial rate.
  Eigen::Vector3d tableFrameRateAt(double t) const;
  /// The base under the table (its vibration is the accelerometer's).
  const BaseMotion& base() const { return base_; }

 private:
  struct Span {
    double move_start, start, move;
    Eigen::Matrix3d from;           // body_to_platter before the move (that of the position itself if none)
    Eigen::Matrix3d to;             // body_to_platter in the position
    Eigen::Matrix3d table_to_body;  // (W to)^T
    Eigen::Vector3d rho;            // the move's rotation vector, body frame: to = from Exp(rho)
  };
  const Span& spanAt(double t) const;
  /// The body on the platter during span's move at t, and the move's rate in the body frame.
  void moving(const Span& span, double t, Eigen::Matrix3d* body_to_platter, Eigen::Vector3d* rate) const;
  /// The base's share of the table frame's inertial rate at table angle phi, in the table frame:
  /// Rz(phi)^T T0^T ((D^T - I) Omega_enu + D^T w), D and w at t.
  Eigen::Vector3d baseShareInTable(double t, double phi) const;

  TurntableProfile profile_;
  Eigen::Matrix3d wobble_;
  Eigen::Matrix3d table_zero_to_enu_;
  Eigen::Vector3d earth_zero_;
  Eigen::Vector3d earth_enu_;  // Omega_enu
  BaseMotion base_;
  std::vector<Span> spans_;
  mutable std::size_t cursor_ = 0;  // evaluation is nearly always monotonic in t
};

}  // namespace core
}  // namespace hrg_gyro
