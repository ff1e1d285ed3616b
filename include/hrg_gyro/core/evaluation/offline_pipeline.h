// The whole chain without ROS, for the core's end-to-end tests and offline tools:
// simulate -> process -> calibrate, and simulate -> process with several parameter sets -> evaluate
// against the truth. The nodes run exactly these classes on the same samples.
#pragma once

#include <memory>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/evaluation/output_evaluator.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
#include "hrg_gyro/core/simulation/gyro_simulator.h"

namespace hrg_gyro {
namespace core {

struct OfflineCalibration {
  CalibrationOutcome outcome;
  ProcessorCounters processor;
  SessionCounters session;
  double simulated_seconds = 0.0;
};

/// Runs a scenario through a processor with `parameters` into a calibration session, then finishes it.
/// A method fed by the virtual rotation (field) gets the precession loop's state instead of the table's.
OfflineCalibration calibrateOnSimulation(const SimulationConfig& scenario,
                                         std::shared_ptr<const GyroParameters> parameters,
                                         const CalibrationSettings& calibration, const ProcessorConfig& processor = {});

/// Runs a scenario through one processor per parameter set and evaluates each output.
std::vector<EvaluationResult> verifyOnSimulation(const SimulationConfig& scenario,
                                                 const std::vector<std::shared_ptr<const GyroParameters>>& parameters,
                                                 const EvaluationSettings& evaluation = {},
                                                 const ProcessorConfig& processor = {});

}  // namespace core
}  // namespace hrg_gyro
