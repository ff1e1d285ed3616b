// What a triad calibration produced: each axis's own outcome (K(theta), D(theta) from the dual-rate
// plateaus while it pointed along the table axis), the axes' directions A in the body frame and the
// triad's matrix M = A^-1 with standard errors, the body bias from the rests against the Earth's
// rate, what each fixture position and each rest measured, the gates, and the files to write when
// accepted. Also its YAML report form.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/model/triad_parameters.h"

namespace hrg_gyro {
namespace core {

/// One fixture position with the table turning: how each axis answered the table's rate.
struct TriadPositionResponse {
  std::uint32_t position = 0;
  std::string name;
  Eigen::Vector3d table_axis = Eigen::Vector3d::Zero();  ///< the table's axis in the body frame (plan)
  Eigen::Vector3d response = Eigen::Vector3d::Zero();    ///< per axis: d alpha_i / d table angle
  Eigen::Vector3d response_std = Eigen::Vector3d::Zero();
  double duration = 0.0;       ///< s of plateau data used
  std::size_t increments = 0;  ///< window increments fitted
};

/// How far an axis leaned off the table's axis in a fixture position where it pointed along it, as
/// stage 1 measured it through the Earth's horizontal rate it sensed: the axis's horizontal component
/// in the platter frame (x along the zero mark), rad. Against it, what stage 2's A and the position's
/// logged orientation give (the difference: the fixture's own error in that position, and noise).
struct TriadAxisTilt {
  int axis = 0;
  std::uint32_t position = 0;
  std::string name;
  Eigen::Matrix3d body_to_table = Eigen::Matrix3d::Identity();  ///< the position's logged orientation
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  Eigen::Vector2d tilt_std = Eigen::Vector2d::Zero();
  bool from_directions_known = false;                         ///< stage 2 fitted A
  Eigen::Vector2d from_directions = Eigen::Vector2d::Zero();  ///< A_i turned into the platter frame (plan)
};

/// One rest of the table in a fixture position: the axes' rates against the Earth's.
struct TriadRest {
  std::uint32_t position = 0;
  std::string name;
  double table_angle = 0.0;                              ///< rad, where the table rested
  Eigen::Vector3d axis_rates = Eigen::Vector3d::Zero();  ///< rad/s, the axes' compensated mean rates
  Eigen::Vector3d axis_rates_std = Eigen::Vector3d::Zero();
  /// rad/s: what stage 1's D(theta) uncertainty at the rest's wave angles makes of each axis's rate
  Eigen::Vector3d axis_drift_std = Eigen::Vector3d::Zero();
  Eigen::Vector3d earth_body = Eigen::Vector3d::Zero();  ///< rad/s, the Earth's rate in the body frame
  Eigen::Vector3d bias = Eigen::Vector3d::Zero();        ///< rad/s, M rates - Earth: this rest's body bias
  double duration = 0.0;                                 ///< s
};

struct TriadOutcome {
  bool accepted = false;
  std::string reason;                      ///< first failed gate
  std::array<CalibrationOutcome, 3> axes;  ///< each axis's dual-rate outcome, in the triad's axis order
  std::array<std::string, 3> axis_names;
  TriadParameters triad;  ///< M, bias, their standard errors, provenance (meaningful when accepted)
  Eigen::Matrix3d body_to_axis = Eigen::Matrix3d::Identity();  ///< A = M^-1
  Eigen::Matrix3d body_to_axis_std = Eigen::Matrix3d::Zero();
  /// Per axis, sum over positions of ((response - A_i . table axis) / std)^2 and the positions fitted.
  Eigen::Vector3d fit_chi_square = Eigen::Vector3d::Zero();
  std::size_t positions_fitted = 0;
  bool bias_estimated = false;
  std::vector<TriadPositionResponse> positions;
  std::vector<TriadRest> rests;
  std::vector<TriadAxisTilt> tilts;  ///< stage 1's, per axis and position along the table's axis
  std::vector<GateResult> gates;
  std::vector<std::string> notes;

  void gate(const std::string& name, bool passed, double value, double limit, const std::string& message);
  void decide();
};

/// Human- and machine-readable YAML of the outcome (the per-axis outcomes in full under `axes`).
std::string emitTriadReport(const TriadOutcome& outcome);

}  // namespace core
}  // namespace hrg_gyro
