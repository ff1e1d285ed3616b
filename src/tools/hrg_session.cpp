// hrg_session: the calibrate-then-verify session of `make run`, without ROS.
//   hrg_session --calibration dual_rate.yaml --verification verification.yaml --params P.yaml [--out OUT.yaml]
// Simulates the calibration scenario through the processor (with P.yaml) into the calibrator,
// writes the refreshed parameters (atomically) when the quality gates accept them, then runs the
// verification scenario through an uncalibrated and a calibrated processor and prints the summary.
#include <cstring>
#include <iostream>
#include <memory>
#include <string>

#include "hrg_gyro/core/calibration_session.h"
#include "hrg_gyro/core/offline_pipeline.h"
#include "hrg_gyro/core/parameter_file.h"
#include "hrg_gyro/core/session_summary.h"

using namespace hrg_gyro::core;

namespace {

void usage(std::ostream& out) {
  out << "usage: hrg_session --calibration SCENARIO.yaml --verification SCENARIO.yaml --params PARAMS.yaml\n"
         "                   [--out NEW_PARAMS.yaml] [--method dual_rate|constant_rate|step]\n"
         "                   [--orders 2,4,6,8] [--drift-orders 2,4] [--evaluation-orders 2,4,...,12]\n"
         "                   [--window SECONDS] [--bins N]\n"
         "Calibrates a simulated gyro without ROS and verifies the result against the ground truth.\n";
}

}  // namespace

int main(int argc, char** argv) {
  std::string calibration, verification, params, out, method = "dual_rate";
  CalibrationSettings settings;
  EvaluationSettings evaluation;
  auto parseOrders = [](const std::string& text) {
    std::vector<int> orders;
    std::size_t pos = 0;
    while (pos < text.size()) {
      const std::size_t comma = text.find(',', pos);
      orders.push_back(std::stoi(text.substr(pos, comma - pos)));
      pos = comma == std::string::npos ? text.size() : comma + 1;
    }
    return orders;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "hrg_session: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--calibration") calibration = value();
    else if (a == "--verification") verification = value();
    else if (a == "--params") params = value();
    else if (a == "--out") out = value();
    else if (a == "--method") method = value();
    else if (a == "--orders") settings.scale_factor_orders = parseOrders(value());
    else if (a == "--drift-orders") settings.drift_orders = parseOrders(value());
    else if (a == "--evaluation-orders") evaluation.orders = parseOrders(value());
    else if (a == "--window") settings.window = std::stod(value());
    else if (a == "--bins") settings.bins = std::stoi(value());
    else if (a == "-h" || a == "--help") {
      usage(std::cout);
      return 0;
    } else {
      std::cerr << "hrg_session: unknown argument '" << a << "'\n";
      usage(std::cerr);
      return 2;
    }
  }
  if (calibration.empty() || verification.empty() || params.empty()) {
    usage(std::cerr);
    return 2;
  }
  try {
    const SimulationConfig cal_scenario = SimulationConfig::load(calibration, nodeOnlyScenarioKeys());
    const SimulationConfig ver_scenario = SimulationConfig::load(verification, nodeOnlyScenarioKeys());
    const auto uncalibrated = std::make_shared<const GyroParameters>(loadParameterFile(params));
    settings.method = method;
    std::cerr << "hrg_session: simulating and calibrating " << calibration << " ...\n";
    const OfflineCalibration cal = calibrateOnSimulation(cal_scenario, uncalibrated, settings);
    SessionSummary summary;
    summary.calibration = cal.outcome;
    summary.injected = computeEffectiveModel(cal_scenario, uncalibrated->correction, settings.scale_factor_orders,
                                             settings.drift_orders);
    auto calibrated = uncalibrated;
    if (cal.outcome.accepted) {
      calibrated = std::make_shared<const GyroParameters>(cal.outcome.parameters);
      if (!out.empty()) {
        saveParameterFile(out, *calibrated);
        std::cerr << "hrg_session: wrote " << out << "\n";
      }
    }
    std::cerr << "hrg_session: verifying on " << verification << " ...\n";
    const auto results = verifyOnSimulation(ver_scenario, {uncalibrated, calibrated}, evaluation);
    summary.before = results[0];
    summary.after = results[1];
    printSessionSummary(std::cout, summary);
    return cal.outcome.accepted && summary.after.ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "hrg_session: " << e.what() << "\n";
    return 2;
  }
}
