// Test support: the scenario files the package ships (config/scenarios/), read as driver_sim reads them.
#pragma once

#include <string>

#include "hrg_gyro/core/simulation/simulation_config.h"

namespace hrg_gyro {
namespace core {
namespace testing {

/// The path of a shipped scenario file.
inline std::string shippedScenarioPath(const std::string& name) {
  return std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/" + name;
}

/// A shipped single-gyro scenario, the ROS node's own keys allowed.
inline SimulationConfig shippedScenario(const std::string& name) {
  return SimulationConfig::load(shippedScenarioPath(name), nodeOnlyScenarioKeys());
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
