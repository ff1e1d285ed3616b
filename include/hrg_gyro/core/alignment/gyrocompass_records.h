// What a gyrocompass window holds once its intake has checked every record: each gyro stream's
// samples (stamp, dt, increment, whether it continues the one before), the indexer's, the
// accelerometer's and the precession states' records, the window's bounds, the triad's file, and the
// refusal the intake met, if any. Gyrocompass fills it as records come (gyrocompass.h: the stamp rule,
// the window); GyrocompassSolver reads it (gyrocompass_solver.h). A type of its own so the solver
// needs nothing of the intake, and the two do not include each other. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/triad_parameters.h"
#include "hrg_gyro/core/processing/precession_watch.h"

namespace hrg_gyro {
namespace core {

/// The indexer's (or rate table's) state, as TurntableState carries it.
struct IndexerRecord {
  Nanoseconds stamp = 0;
  double angle = 0.0;  ///< rad, counter-clockwise seen from above (about the platform's z)
  double rate = NAN;   ///< rad/s; NaN: taken from the angles
};

/// One accelerometer sample: the specific force in the accelerometer's frame (sensor_msgs/Imu
/// linear_acceleration, REP-145: +g up at rest), m/s^2.
struct AccelerometerRecord {
  Nanoseconds stamp = 0;
  Eigen::Vector3d specific_force = Eigen::Vector3d::Zero();
};

/// One gyro stream's samples in the window: a triad's three body axes, one gyro, or one axis of a sweep.
struct GyroStreamRecords {
  std::size_t channels = 3;
  std::vector<Nanoseconds> stamp;
  std::vector<double> dt;
  std::vector<double> increment;     ///< `channels` per sample, rad
  std::vector<std::uint8_t> broken;  ///< 1: the sample does not continue the previous one
  Nanoseconds last = 0;              ///< the newest stamp taken (a gap's too)
  /// Drops every sample (the channel count stays).
  void clear();
};

struct GyrocompassRecords {
  std::array<GyroStreamRecords, 3> streams;  ///< [0]: triad or single gyro; sweep: one per axis
  std::size_t stream_count = 1;
  bool started = false;            ///< a gyro sample opened the window
  Nanoseconds start = 0, end = 0;  ///< the window's, gyro stamps
  std::vector<IndexerRecord> indexer;
  std::vector<AccelerometerRecord> accelerometer;
  std::array<std::vector<PrecessionStateRecord>, 3> precession;  ///< per sweep axis
  TriadParameters triad;                                         ///< M and the body bias (the sweep mode applies them)
  std::string refused_gate, refused_reason;                      ///< set when the intake refused the window

  /// Seconds from the window's start.
  double seconds(Nanoseconds stamp) const { return toSeconds(stamp - start); }
  /// The newest gyro stamp taken on any stream (0 before any).
  Nanoseconds lastSample() const;
  /// Drops every record of the window (a restart on a new timeline); the settings' parts stay.
  void clearWindow();
};

}  // namespace core
}  // namespace hrg_gyro
