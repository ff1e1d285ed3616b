// The settings of a triad calibration beyond each axis's dual-rate ones: the `triad` section of the
// calibrator's settings (config/triad_calibration.yaml), read by the live calibrator in triad mode
// and by `hrg_bag calibrate --method triad` alike. What each setting does is told at the stage that
// uses it (triad_calibration.h). No ROS.
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/axis_to_body_matrix.h"

namespace hrg_gyro {
namespace core {

struct TriadCalibrationSettings {
  double azimuth = 0.0;                             ///< rad: the table's zero mark from North towards East
  double window = 1.0;                              ///< s: window of the cross-axis response fit
  double store_rate = 20.0;                         ///< Hz: wave and table block means kept for stages 2 and 3
  double vertical_tolerance = 0.02;                 ///< an axis is along the table axis when |u . e_i| >= 1 - this
  double min_rest = 20.0;                           ///< s of settled rest for a bias estimate
  double min_position_time = 60.0;                  ///< s of moving plateaus for a position's responses
  double max_misalignment = kMaxTriadMisalignment;  ///< largest |A - I| accepted

  /// Parses the `triad` section of the calibrator settings. Throws ConfigError naming the key.
  static TriadCalibrationSettings parse(const YamlField& section);
  static std::vector<std::string> keys();
};

}  // namespace core
}  // namespace hrg_gyro
