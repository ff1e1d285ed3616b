// hrg_bag calibrate --method triad: the triad calibration offline. Each axis's channels through its
// own processor (its prior parameter file), the table and the fixture's positions from the bag, the
// core's TriadCalibration, and on acceptance the axes' parameter files and the triad file written
// as one set (core::saveTriadResult).
#pragma once

#include <string>
#include <vector>

#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace bag_tools {

struct TriadCalibrateOptions {
  std::string bag;
  std::string triad;                       ///< prior triad file (axis names and order, frame_id); "" nominal
  std::vector<std::string> axis_params;    ///< NAME=FILE: each axis's prior parameter file
  std::vector<std::string> axis_out;       ///< NAME=FILE: each axis's calibrated parameter file
  std::vector<std::string> axis_channels;  ///< NAME=TOPIC: each axis's channels (default /NAME/channels)
  std::string out, report, config;         ///< the triad file written, the YAML report, the settings
  std::string turntable_topic, fixture_topic;
  core::ProcessorConfig processor;
};

/// Runs it; returns the exit code (0 accepted, 1 refused). Throws UsageError or OutputError.
int runTriadCalibrate(const TriadCalibrateOptions& options);

}  // namespace bag_tools
}  // namespace hrg_gyro
