// The triad's chain without ROS, for the core's tests and offline tools: a triad scenario simulated,
// each axis through its own processor, into the triad calibration -- what `hrg_bag calibrate
// --method triad` does with a bag of the same session, on the samples directly.
#pragma once

#include <array>
#include <memory>

#include "hrg_gyro/core/calibration/triad_calibration.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
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

}  // namespace core
}  // namespace hrg_gyro
