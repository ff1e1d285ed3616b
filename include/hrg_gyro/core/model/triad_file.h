// The triad file: a TriadParameters set (triad_parameters.h) as YAML, validated on every read and
// before every write, with the equation and a comment on every key for its reader:
//
//   frame_id: imu_link                 the body frame
//   axes: [x, y, z]                    the columns of M: each axis's name and namespace
//   axis_to_body: [[1, 0, 0], ...]     M, rows body x, y, z (|M - I| at most kMaxTriadMisalignment)
//   axis_to_body_std, bias, bias_std   rad/s for the bias, body frame
//   calibration: {method, time, source}
//
// Written atomically (common/atomic_file.h), the replaced file kept as <file>.bak. No ROS.
#pragma once

#include <string>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/model/triad_parameters.h"

namespace hrg_gyro {
namespace core {

/// Validates and converts a parsed triad document. Throws ConfigError naming the key.
TriadParameters parseTriadParameters(const YAML::Node& root);
/// Reads and validates a triad file (regular file, bounded size, every bad key named).
TriadParameters loadTriadFile(const std::string& path);
/// The file text, with the equation and a comment on every key; the misalignment angles and the
/// residual scales (from A = M^-1: describeAlignment) as comments for the reader.
std::string emitTriadParameters(const TriadParameters& triad);
/// Atomic, validated save; the replaced file kept as <file>.bak when `keep_backup`.
void saveTriadFile(const std::string& path, const TriadParameters& triad, bool keep_backup = true);

}  // namespace core
}  // namespace hrg_gyro
