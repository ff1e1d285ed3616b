// hrg_bag import --imu: a navigation-grade IMU's text log (imu_log.h reads it) into a bag of
// sensor_msgs/Imu in the body frame FLU, and one sensor_msgs/NavSatFix of the site when the log or the
// options give it. A mode of `hrg_bag import` beside the bench logs' (import.cpp): it adds its own
// options to that command and shares the rest (--out, --delimiter, --column, --no-header,
// --skip-bad-rows, --quiet, --frame-id, --compression), which import.cpp hands over.
#pragma once

#include <CLI/CLI.hpp>
#include <istream>
#include <string>
#include <vector>

namespace hrg_gyro {
namespace bag_tools {

struct ImuImportOptions {
  std::string log;  ///< --imu
  std::string format = "columns", comment = "#", gyro_unit, accel_unit, gyro_scale, accel_scale;
  std::string frame, rotation, epoch, imu_topic = "/imu/data_raw", fix_topic = "/fix";
  double interval = 0.0, gravity = 0.0, latitude = 0.0, longitude = 0.0, height = 0.0;
  long long skip_lines = 0;
  // The options shared with the bench logs' import, set by import.cpp.
  std::string out, compression, frame_id, delimiter;
  std::vector<std::string> columns;
  bool no_header = false, skip_bad_rows = false, quiet = false;
  /// The parsed command: which options were given (a given one wins over the PSINS header).
  const CLI::App* command = nullptr;
};

/// Adds --imu and the options only it takes to `command` (`hrg_bag import`).
void addImuImportOptions(CLI::App& command, ImuImportOptions* options);
/// The names of those options, which the bench logs' import refuses.
const std::vector<std::string>& imuOnlyOptions();
/// Imports `log` (the --imu file, already open: `log_bytes` long, for the progress) into --out.
/// Returns the exit code; UsageError and OutputError as the other subcommands.
int runImuImport(const ImuImportOptions& options, std::istream& log, double log_bytes);

}  // namespace bag_tools
}  // namespace hrg_gyro
