// The Allan readings of a still record as a YAML file, written by `hrg_bag allan --yaml` and read
// back where a setting takes its noise from the measurement instead of a hand copy (the alignment's
// `noise/allan_file`): each of Q, N, B and K in SI with whether it was identified and the tau range
// it was read from, and the record it came from (samples, tau0, length); for a triad or an IMU, each
// axis's readings too, the top level then the worst axis's per term.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "hrg_gyro/core/estimation/allan_deviation.h"

namespace hrg_gyro {
namespace core {

/// One axis's readings of a triad's or an IMU's record.
struct AxisAllanReadings {
  std::string axis;  ///< "x", "y", "z" (the stream's own axes)
  AllanResult result;
};

struct AllanReadings {
  std::size_t samples = 0;  ///< of the record
  double tau0 = 0.0;        ///< s, its sample period
  /// The four readings; the curve is not in the file (empty when read). A record of several axes:
  /// worstOfAxes(axes), what a setting of one noise model per axis may claim.
  AllanResult result;
  std::vector<AxisAllanReadings> axes;  ///< each axis's (under `axes`), empty for one gyro
};

/// Per term the largest identified reading over the axes (with its axis's tau range); identified when
/// any axis identified it.
AllanResult worstOfAxes(const std::vector<AxisAllanReadings>& axes);

/// The file's text: a comment line saying the units, then the map.
std::string allanReadingsYaml(const AllanReadings& readings);

/// Reads a file allanReadingsYaml wrote. Throws ConfigError naming the key ("rate_random_walk.value")
/// and the file for a missing, mistyped or negative entry, and for an unreadable file.
AllanReadings loadAllanReadings(const std::string& path);

}  // namespace core
}  // namespace hrg_gyro
