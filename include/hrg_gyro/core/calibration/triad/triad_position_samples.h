// What stages 2 and 3 of a triad calibration (triad_calibration.h) read of the session: the stored
// series (block means at store_rate) of each axis's wave angle theta and of the table's angle and
// reported rate, and each axis's compensated angle alpha -- stage 1's K(theta) and D(theta) applied to
// its wave angle. In each locked fixture position they take the samples on the table's settled
// plateaus, judged as the axes' dual-rate sessions judge them, with every axis's alpha and theta and
// the table angle interpolated to the first axis's stamps; a sample across a gap of any series (longer
// than `max_gap`) is left out. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/plateau_detector.h"
#include "hrg_gyro/core/model/gyro_parameters.h"

namespace hrg_gyro {
namespace core {

/// Stamped values, sorted by stamp.
using StampedSeries = std::vector<std::pair<Nanoseconds, double>>;

/// The session at the stored stamps.
struct TriadSeries {
  std::array<StampedSeries, 3> alpha;  ///< rad, each axis's compensated angle (compensatedAngle)
  std::array<StampedSeries, 3> theta;  ///< rad, each axis's wave angle
  StampedSeries table;                 ///< rad, the table angle (unwrapped)
  std::vector<double> table_rates;     ///< rad/s, the table's reported rate at each table sample
};

/// The compensated angle of an axis whose wave angle is `theta`: 0 at the first sample, then the sum
/// of (dtheta - D dt) / K over the samples, K and D at each step's mean wave angle.
StampedSeries compensatedAngle(const StampedSeries& theta, const GyroParameters& parameters);

/// One sample of a position on a settled plateau of the table.
struct TriadPositionSample {
  Nanoseconds stamp;
  double alpha[3];        ///< rad, each axis's compensated angle
  double theta[3];        ///< rad, each axis's wave angle
  double phi;             ///< rad, the table angle
  std::uint64_t plateau;  ///< the plateau's id (PlateauDetector)
  bool is_static;         ///< the plateau is a rest
};

/// A locked fixture position: as the bench logged it, and its samples on settled plateaus.
struct TriadLockedPosition {
  std::uint32_t index = 0;
  std::string name;
  Eigen::Matrix3d body_to_table = Eigen::Matrix3d::Identity();  ///< the logged orientation
  Eigen::Vector3d table_axis = Eigen::Vector3d::UnitZ();        ///< u: the table's axis in the body frame
  std::vector<TriadPositionSample> samples;                     ///< in stamp order
};

/// The runs of `samples` on one plateau each, in order: [first, second) index ranges.
std::vector<std::pair<std::size_t, std::size_t>> plateauRuns(const std::vector<TriadPositionSample>& samples);

/// The samples of the stamps [from, to) on settled plateaus (none when the table's records there
/// decide fewer than three plateau records).
std::vector<TriadPositionSample> positionSamples(const TriadSeries& series, Nanoseconds from, Nanoseconds to,
                                                 const PlateauSettings& plateau, double max_gap);

}  // namespace core
}  // namespace hrg_gyro
