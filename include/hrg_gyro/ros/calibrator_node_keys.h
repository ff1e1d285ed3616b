// The calibrator node's private keys that are not calibration settings: the files, services,
// queues and timers both modes (CalibratorRos, TriadCalibratorRos) read from the one shared
// template, so core::CalibrationSettings::parse is told to leave them alone. One list, so the two
// modes cannot drift apart on what the template may hold.
#pragma once

#include <string>
#include <vector>

namespace hrg_gyro {

inline const std::vector<std::string>& calibratorNodeOnlyKeys() {
  static const std::vector<std::string> keys = {
      "parameter_file", "report_file", "output_directory", "reload_service", "write", "autostart", "stages",
      "queue_size", "diagnostic_period", "heap_trim_period",
      // read by the triad mode only (TriadCalibratorRos), accepted in the shared template
      "triad_file", "axis_parameter_files", "reload_services", "stream_hold", "triad"};
  return keys;
}

}  // namespace hrg_gyro
