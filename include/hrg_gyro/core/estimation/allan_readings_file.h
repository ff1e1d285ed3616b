// The Allan readings of a still record as a YAML file, written by `hrg_bag allan --yaml` and read
// back where a setting takes its noise from the measurement instead of a hand copy (the alignment's
// `noise/allan_file`): each of Q, N, B and K in SI with whether it was identified and the tau range
// it was read from, and the record it came from (samples, tau0, length).
#pragma once

#include <cstddef>
#include <string>

#include "hrg_gyro/core/estimation/allan_deviation.h"

namespace hrg_gyro {
namespace core {

struct AllanReadings {
  std::size_t samples = 0;  ///< of the record
  double tau0 = 0.0;        ///< s, its sample period
  AllanResult result;       ///< the four readings; the curve is not in the file (empty when read)
};

/// The file's text: a comment line saying the units, then the map.
std::string allanReadingsYaml(const AllanReadings& readings);

/// Reads a file allanReadingsYaml wrote. Throws ConfigError naming the key ("rate_random_walk.value")
/// and the file for a missing, mistyped or negative entry, and for an unreadable file.
AllanReadings loadAllanReadings(const std::string& path);

}  // namespace core
}  // namespace hrg_gyro
