// The triad's chain without ROS, for the core's tests and offline tools: a triad scenario simulated,
// each axis through its own processor (TriadProcessor), into the triad calibration -- what `hrg_bag
// calibrate --method triad` does with a bag of the same session, on the samples directly -- or on
// into the triad combiner, as `hrg_bag process --triad` and the live nodes do, to check the body rates
// it publishes against the simulator's exact ones.
#pragma once

#include <Eigen/Core>
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/triad/triad_calibration.h"
#include "hrg_gyro/core/processing/triad_processor.h"
#include "hrg_gyro/core/simulation/triad_simulator.h"

namespace hrg_gyro {
namespace core {

struct OfflineTriadCalibration {
  TriadOutcome outcome;
  std::array<ProcessorCounters, 3> processors;
  double simulated_seconds = 0.0;
};

/// Runs `scenario` through one processor per axis (`priors`, in the scenario's axis order) into a
/// TriadCalibration, then finishes it. The fixture's log, the table's log and the channels are
/// handed over as a bag would hold them (the logged values, never the truth).
OfflineTriadCalibration calibrateOnTriadSimulation(const TriadSimulationConfig& scenario,
                                                   const std::array<GyroParameters, 3>& priors,
                                                   const CalibrationSettings& axis_settings,
                                                   const TriadCalibrationSettings& triad_settings,
                                                   const TriadParameters& prior_triad,
                                                   const ProcessorConfig& processor = {});

/// One set of files to verify: the three axes' parameters (in the scenario's axis order) and the
/// triad file.
struct TriadCalibrationFiles {
  std::string name;
  std::array<GyroParameters, 3> axes;
  TriadParameters triad;
};

/// A stretch of constant table rate in one fixture position: the published body rate's mean error
/// against the exact inertial body rate over it.
struct TriadVerificationSegment {
  std::string label;  ///< the profile piece's, "<position>/<piece>"
  std::size_t position = 0;
  double table_rate = 0.0;                               ///< rad/s
  double seconds = 0.0;                                  ///< of combined samples averaged
  Eigen::Vector3d mean_rate = Eigen::Vector3d::Zero();   ///< rad/s, body frame, exact (Earth's rate included)
  Eigen::Vector3d mean_error = Eigen::Vector3d::Zero();  ///< rad/s, published minus exact
  bool turning() const { return table_rate != 0.0; }
  /// |mean_error| / |mean_rate| in ppm (turning segments).
  double relativeErrorPpm() const { return 1e6 * mean_error.norm() / mean_rate.norm(); }
};

struct TriadVerification {
  std::string name;
  std::vector<TriadVerificationSegment> segments;
  TriadCounters combiner;
  double worst_turning_ppm = 0.0;  ///< the largest relativeErrorPpm of the turning segments
  double rms_turning_ppm = 0.0;    ///< their root mean square
  double worst_rest_error = 0.0;   ///< rad/s, the largest |mean_error| of the segments at rest
};

/// Runs `scenario` once through a TriadProcessor for each set of files (the nodes' default settings,
/// `processor` the processors'), and compares the combined body rates with the simulator's exact ones
/// (TriadMotion) over every piece of constant table rate, `margin` s in from each end (the
/// processors' delay, the settling after a rate change). The fixture's moves are no segment. Throws
/// std::invalid_argument when a set's files do not make a triad (TriadCombiner's check).
std::vector<TriadVerification> verifyTriadOnSimulation(const TriadSimulationConfig& scenario,
                                                       const std::vector<TriadCalibrationFiles>& files,
                                                       const ProcessorConfig& processor = {}, double margin = 2.0);

}  // namespace core
}  // namespace hrg_gyro
