// hrg_session: the calibrate-then-verify session of `make run`, without ROS.
//   hrg_session --calibration dual_rate.yaml --verification verification.yaml --params P.yaml [--out OUT.yaml]
// Every argument is checked before anything runs: numbers whole (CLI11 plus tools/cli_checks.h),
// the calibration settings by the calibrator's own parser (CalibrationSettings::parse).
// Simulates the calibration scenario through the processor (with P.yaml) into the calibrator,
// writes the refreshed parameters (atomically) when the quality gates accept them, then runs the
// verification scenario through an uncalibrated and a calibrated processor and prints the summary.
#include <sys/stat.h>

#include <cstring>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "cli_checks.h"
#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/common/atomic_file.h"
#include "hrg_gyro/core/evaluation/offline_pipeline.h"
#include "hrg_gyro/core/evaluation/session_summary.h"
#include "hrg_gyro/core/model/parameter_file.h"

using namespace hrg_gyro::core;

namespace {

/// Thrown for an argument the core's settings parser refuses; names the option.
struct ArgumentError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// The calibration settings the options give, through the calibrator's own settings parser (the
/// node's rules: even increasing orders in [2, 64], bins in [8, 4096], window > 0, known method).
CalibrationSettings checkedSettings(const std::string& method, const std::vector<int>& orders,
                                    const std::vector<int>& drift_orders, int bins, double window) {
  YAML::Node n;
  n["method"] = method;
  for (int order : orders) n["scale_factor_orders"].push_back(order);
  for (int order : drift_orders) n["drift_orders"].push_back(order);
  n["bins"] = bins;
  n["window"] = window;
  try {
    CalibrationSettings s = CalibrationSettings::parse(YamlField(n, ""));
    if (traitsOf(s.method).three_axes) {
      throw ArgumentError("--method " + method +
                          ": hrg_session simulates one axis; calibrate a triad with hrg_bag calibrate --method triad");
    }
    return s;
  } catch (const ConfigError& e) {
    static const std::pair<const char*, const char*> kOptions[] = {{"method", "--method"},
                                                                   {"scale_factor_orders", "--orders"},
                                                                   {"drift_orders", "--drift-orders"},
                                                                   {"bins", "--bins"},
                                                                   {"window", "--window"}};
    for (const auto& ko : kOptions) {
      if (e.key().rfind(ko.first, 0) == 0)
        throw ArgumentError(ko.second + e.key().substr(std::strlen(ko.first)) + ": " + e.problem());
    }
    throw ArgumentError(e.what());
  }
}

/// The evaluator's harmonic orders follow the same rules as the calibrator's.
std::vector<int> checkedEvaluationOrders(const std::vector<int>& orders) {
  YAML::Node n;
  for (int order : orders) n["scale_factor_orders"].push_back(order);
  try {
    return CalibrationSettings::parse(YamlField(n, "")).scale_factor_orders;
  } catch (const ConfigError& e) {
    throw ArgumentError("--evaluation-orders" + e.key().substr(std::strlen("scale_factor_orders")) + ": " +
                        e.problem());
  }
}

/// Before anything runs: --out (when given) must be a regular file or none, and not one of the
/// `inputs` read; ArgumentError otherwise.
void checkOutputFile(const std::string& out, const std::vector<std::string>& inputs) {
  if (out.empty()) return;
  try {
    struct stat st {};
    if (::stat(out.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
      throw std::runtime_error("'" + out + "' exists and is not a regular file (a directory?)");
    }
    checkDistinct(inputs, {out});
  } catch (const std::runtime_error& e) {
    throw ArgumentError(std::string("--out refused: ") + e.what());
  }
}

/// The accepted parameters into `out` (atomically, the previous file kept); false, said on stderr,
/// when they could not be written.
bool writeCalibrated(const std::string& out, const GyroParameters& calibrated) {
  try {
    saveParameterFile(out, calibrated);
  } catch (const std::exception& e) {
    std::cerr << "hrg_session: the calibration was accepted but not written: " << e.what() << "\n";
    return false;
  }
  std::cerr << "hrg_session: wrote " << out << "\n";
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  using hrg_gyro::tools::finiteNumber;
  using hrg_gyro::tools::wholeNumber;
  const CalibrationSettings defaults;
  std::string calibration, verification, params, out, method = nameOf(defaults.method);
  std::vector<int> orders = defaults.scale_factor_orders, drift_orders = defaults.drift_orders;
  std::vector<int> evaluation_orders = EvaluationSettings().orders;
  int bins = defaults.bins;
  double window = defaults.window;

  CLI::App app("Calibrates a simulated gyro without ROS and verifies the result against the ground truth.",
               "hrg_session");
  app.get_formatter()->label("Usage", "usage");
  app.get_formatter()->column_width(34);
  app.add_option("--calibration", calibration, "calibration scenario (YAML, the driver_sim parameters)")->required();
  app.add_option("--verification", verification, "verification scenario (YAML)")->required();
  app.add_option("--params", params, "parameter file of the gyro before calibration")->required();
  app.add_option("--out", out, "calibrated parameter file, written atomically when the gates accept")
      ->check(hrg_gyro::tools::notEmpty());
  app.add_option("--method", method, singleAxisMethodNames("|"))->capture_default_str();
  auto orders_option = [&](const char* name, std::vector<int>* target, const char* meaning) {
    app.add_option(name, *target, meaning)->delimiter(',')->transform(wholeNumber(2, 64))->capture_default_str();
  };
  orders_option("--orders", &orders, "scale-factor harmonic orders, even, increasing, e.g. 2,4,6,8");
  orders_option("--drift-orders", &drift_orders, "drift harmonic orders, even, increasing, e.g. 2,4");
  orders_option("--evaluation-orders", &evaluation_orders, "harmonic orders of the verification's K_rel fit");
  app.add_option("--window", window, "s, > 0: longest averaging window of the calibration")
      ->transform(finiteNumber())
      ->capture_default_str();
  app.add_option("--bins", bins, "wave-angle bins over [0, pi), in [8, 4096]")
      ->transform(wholeNumber(8, 4096))
      ->capture_default_str();
  app.footer(
      "Simulates the calibration scenario through the processor into the calibrator, writes the refreshed\n"
      "parameters when the quality gates accept them, then runs the verification scenario through an\n"
      "uncalibrated and a calibrated processor and prints the summary.\n"
      "--out is replaced atomically (the previous file kept as .bak) and may not be one of the inputs.\n"
      "Exit 0 accepted and verified, 1 refused or not verified, 2 bad usage or unreadable input, 3 --out\n"
      "could not be written (an existing file unchanged).");
  const int parsed = hrg_gyro::tools::parseCommandLine(app, argc, argv);
  if (parsed >= 0) return parsed;
  try {
    checkOutputFile(out, {calibration, verification, params});
    CalibrationSettings settings = checkedSettings(method, orders, drift_orders, bins, window);
    EvaluationSettings evaluation;
    evaluation.orders = checkedEvaluationOrders(evaluation_orders);
    const SimulationConfig cal_scenario = SimulationConfig::load(calibration, nodeOnlyScenarioKeys());
    const SimulationConfig ver_scenario = SimulationConfig::load(verification, nodeOnlyScenarioKeys());
    const auto uncalibrated = std::make_shared<const GyroParameters>(loadParameterFile(params));
    std::cerr << "hrg_session: simulating and calibrating " << calibration << " ...\n";
    const OfflineCalibration cal = calibrateOnSimulation(cal_scenario, uncalibrated, settings);
    SessionSummary summary;
    summary.calibration = cal.outcome;
    summary.injected = computeEffectiveModel(cal_scenario, uncalibrated->correction, settings.scale_factor_orders,
                                             settings.drift_orders);
    auto calibrated = uncalibrated;
    if (cal.outcome.accepted) {
      calibrated = std::make_shared<const GyroParameters>(cal.outcome.parameters);
      if (!out.empty() && !writeCalibrated(out, *calibrated)) return 3;
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
