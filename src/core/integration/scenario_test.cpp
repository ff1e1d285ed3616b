// Turntable profiles and scenario files.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/calibration/field_command_plan.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/parameter_file.h"
#include "hrg_gyro/core/simulation/injected_model.h"
#include "hrg_gyro/core/simulation/simulation_config.h"
#include "hrg_gyro/core/simulation/triad_simulation_config.h"
#include "hrg_gyro/core/simulation/triad_simulator.h"

namespace hrg_gyro {
namespace core {
namespace {

YamlField parse(const std::string& text) { return YamlField(YAML::Load(text), ""); }

TEST(TurntableProfile, StepsMoveExactlyTheirAngleAndRest) {
  const TurntableProfile p = TurntableProfile::parse(
      parse("profile: [{type: steps, angle: 0.35, rate: 0.17, dwell: 10.0, count: 4}]")["profile"], 0.5);
  double angle, rate;
  p.evaluate(p.duration(), &angle, &rate);
  EXPECT_NEAR(angle, 4 * 0.35, 1e-12);
  EXPECT_EQ(rate, 0.0);
  // Mid-dwell after the second step.
  const std::string* label = nullptr;
  double t = 0.0;
  for (const auto& piece : p.pieces()) {
    if (piece.label == "steps_0/dwell") t = piece.start + 0.5 * piece.duration;
  }
  p.evaluate(t, &angle, &rate, &label);
  EXPECT_EQ(*label, "steps_0/dwell");
  EXPECT_EQ(rate, 0.0);
  const double steps_done = angle / 0.35;
  EXPECT_NEAR(steps_done, std::round(steps_done), 1e-9);
}

TEST(TurntableProfile, RateAndDualRateRampAtTheAccelerationLimit) {
  const TurntableProfile p = TurntableProfile::parse(
      parse("profile: [{type: dual_rate, rates: [0.1, -0.1], duration: 20.0, settle: 1.0, label: cal}]")["profile"],
      0.5);
  // ramp 0.2 s, settle 1, hold 20, ramp 0.4 s, settle 1, hold 20, ramp to 0 0.2 s
  EXPECT_NEAR(p.duration(), 0.2 + 1 + 20 + 0.4 + 1 + 20 + 0.2, 1e-12);
  double angle, rate;
  const std::string* label;
  p.evaluate(10.0, &angle, &rate, &label);
  EXPECT_DOUBLE_EQ(rate, 0.1);
  EXPECT_EQ(*label, "cal/rate1");
  p.evaluate(30.0, &angle, &rate, &label);
  EXPECT_DOUBLE_EQ(rate, -0.1);
  // Angle is the integral of the rate: symmetric profile returns to (almost) zero.
  p.evaluate(p.duration(), &angle, &rate);
  EXPECT_NEAR(angle, 0.0, 1e-12);
}

/// The plateaus of a dual_rate segment labelled `label`: [start, end) and rate.
struct Plateau {
  double start, end, rate;
};
std::vector<Plateau> plateausOf(const TurntableProfile& p, const std::string& label) {
  std::vector<Plateau> out;
  for (const TurntableProfile::Piece& piece : p.pieces()) {
    if (piece.label == label + "/rate1" || piece.label == label + "/rate2") {
      out.push_back({piece.start, piece.start + piece.duration, piece.rate0});
    }
  }
  return out;
}

/// The integral of t^power over the plateaus of `rate` minus that over the others: what a bias
/// trend of that power leaves in the difference of the two rates' mean readings (times a duration).
double imbalance(const std::vector<Plateau>& plateaus, double rate, int power, std::size_t count) {
  double sum = 0.0;
  for (std::size_t n = 0; n < count; ++n) {
    const Plateau& q = plateaus[n];
    const double integral = (std::pow(q.end, power + 1) - std::pow(q.start, power + 1)) / (power + 1);
    sum += q.rate == rate ? integral : -integral;
  }
  return sum;
}

TEST(TurntableProfile, DualRateBalancedOrderCancelsLinearAndQuadraticTrends) {
  const std::string segment = "{type: dual_rate, rates: [0.05, -0.05], duration: 20.0, settle: 1.0, repeat: 4";
  auto parseProfile = [&](const std::string& order) {
    return TurntableProfile::parse(
        parse("profile: [{type: dwell, duration: 5}, " + segment + order + ", label: cal}]")["profile"], 0.5);
  };
  const TurntableProfile balanced = parseProfile(", order: balanced");
  const TurntableProfile alternating = parseProfile("");
  const std::vector<Plateau> b = plateausOf(balanced, "cal"), a = plateausOf(alternating, "cal");
  ASSERT_EQ(b.size(), 8u);
  ASSERT_EQ(a.size(), 8u);
  const double order[8] = {0.05, -0.05, -0.05, 0.05, -0.05, 0.05, 0.05, -0.05};  // + - - + - + + -
  // Evenly spaced as the alternating plateaus are: the reversal's 0.2 s, the settle, the plateau.
  for (std::size_t n = 0; n < 8; ++n) {
    EXPECT_EQ(b[n].rate, order[n]) << n;
    EXPECT_EQ(a[n].rate, n % 2 == 0 ? 0.05 : -0.05) << n;
    EXPECT_NEAR(b[n].start, a[n].start, 1e-12) << n;
    EXPECT_NEAR(b[n].end - b[n].start, 20.0, 1e-12) << n;
  }
  EXPECT_NEAR(balanced.duration(), alternating.duration(), 1e-12);
  // The table really holds the rate between two plateaus of the same rate (no stop, no ramp).
  double angle, rate;
  balanced.evaluate(0.5 * (b[1].end + b[2].start), &angle, &rate);
  EXPECT_EQ(rate, -0.05);
  // A trend t (t^2) integrates to the same over both rates' plateaus: over the first 4 (all 8).
  // Relative to the integral over one rate's plateaus, to the round-off of the sums.
  const double scale1 = 4 * 20.0 * b[7].end, scale2 = scale1 * b[7].end;
  EXPECT_NEAR(imbalance(b, 0.05, 1, 4) / scale1, 0.0, 1e-14);
  EXPECT_NEAR(imbalance(b, 0.05, 1, 8) / scale1, 0.0, 1e-14);
  EXPECT_NEAR(imbalance(b, 0.05, 2, 8) / scale2, 0.0, 1e-14);
  // The alternating order leaves a trend's share: each + plateau comes one slot (21.2 s) before its -.
  EXPECT_NEAR(imbalance(a, 0.05, 1, 8), -4 * 20.0 * 21.2, 1e-9);
  // The default is today's profile, piece by piece.
  const TurntableProfile explicit_alternating = parseProfile(", order: alternating");
  ASSERT_EQ(explicit_alternating.pieces().size(), alternating.pieces().size());
  for (std::size_t i = 0; i < alternating.pieces().size(); ++i) {
    const TurntableProfile::Piece &x = explicit_alternating.pieces()[i], &y = alternating.pieces()[i];
    EXPECT_EQ(x.start, y.start);
    EXPECT_EQ(x.duration, y.duration);
    EXPECT_EQ(x.rate0, y.rate0);
    EXPECT_EQ(x.accel, y.accel);
    EXPECT_EQ(x.label, y.label);
  }
}

TEST(TurntableProfile, PiecewiseIsLinearInRate) {
  const TurntableProfile p = TurntableProfile::parse(
      parse("profile: [{type: piecewise, points: [[0, 0.0], [10, 0.2], [20, 0.2]]}]")["profile"], 0.5);
  double angle, rate;
  p.evaluate(5.0, &angle, &rate);
  EXPECT_NEAR(rate, 0.1, 1e-15);
  EXPECT_NEAR(angle, 0.25, 1e-12);  // integral of 0.02 t from 0 to 5
}

TEST(TurntableProfile, BadSegmentsNameTheirKey) {
  auto expectError = [](const std::string& yaml, const std::string& key) {
    try {
      TurntableProfile::parse(parse(yaml)["profile"], 0.5);
      ADD_FAILURE() << yaml;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  expectError("profile: [{type: spin}]", "profile[0].type");
  expectError("profile: [{type: dwell}]", "profile[0].duration");
  expectError("profile: [{type: rate, rate: 0.1, duration: -1}]", "profile[0].duration");
  expectError("profile: [{type: dual_rate, rates: [0.1, 0.1], duration: 5}]", "profile[0].rates");
  expectError("profile: [{type: piecewise, points: [[1, 0], [2, 1]]}]", "profile[0].points[0]");
  expectError("profile: [{type: dwell, duration: 1, speed: 2}]", "profile[0].speed");
  expectError("profile: [{type: dual_rate, rates: [0.1, -0.1], duration: 5, order: random}]", "profile[0].order");
  expectError("profile: [{type: dual_rate, rates: [0.1, -0.1], duration: 5, order: [balanced]}]", "profile[0].order");
}

std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// The text without its lines that start with `prefix`.
std::string withoutLines(const std::string& text, const std::string& prefix) {
  std::istringstream in(text);
  std::string line, out;
  while (std::getline(in, line)) {
    if (line.compare(0, prefix.size(), prefix) != 0) out += line + "\n";
  }
  return out;
}

/// The scenarios of the gyro simulated from its equations of motion (dynamics.model: averaged).
const std::set<std::string>& resonatorScenarios() {
  static const std::set<std::string> names = {"resonator_dual_rate.yaml", "resonator_field.yaml",
                                              "resonator_still.yaml"};
  return names;
}

TEST(Scenarios, ResonatorScenariosDescribeTheSameShell) {
  const std::string dir = std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/";
  std::string reference_gyro;
  for (const std::string& name : resonatorScenarios()) {
    SCOPED_TRACE(name);
    const SimulationConfig c = SimulationConfig::load(dir + name, nodeOnlyScenarioKeys());
    EXPECT_TRUE(c.dynamics.averaged());
    EXPECT_EQ(c.resonator.samples_per_period, 32);
    EXPECT_DOUBLE_EQ(c.pickoff.gap, 20.0);
    // Everything from start_time up to the schedule of precession commands (a property of the session).
    const std::string text = readFile(dir + name);
    const std::size_t from = text.find("start_time:"), to = text.find("  commands:");
    ASSERT_NE(from, std::string::npos);
    ASSERT_NE(to, std::string::npos);
    const std::string gyro = text.substr(from, to - from);
    if (reference_gyro.empty()) reference_gyro = gyro;
    EXPECT_EQ(gyro, reference_gyro);
  }
}

TEST(Scenarios, ShippedScenariosParseAndDescribeTheSameGyro) {
  const std::string dir = std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/";
  const std::set<std::string> shipped = {"dual_rate.yaml",
                                         "constant_rate.yaml",
                                         "steps.yaml",
                                         "verification.yaml",
                                         "generator.yaml",
                                         "demo.yaml",
                                         "two_stage.yaml",
                                         "thermal_ramp.yaml",
                                         "dual_rate_drifting.yaml",
                                         "dual_rate_table_clock.yaml"};
  // Every scenario file is checked here, but diagnosis.yaml (its isotropic resonator differs), the
  // triad's (the Triad...Scenario tests) and the resonator's (ResonatorScenariosDescribeTheSameShell).
  std::set<std::string> files;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) files.insert(entry.path().filename().string());
  files.erase("diagnosis.yaml");
  files.erase("triad.yaml");
  files.erase("triad_verification.yaml");
  for (const std::string& name :
       {"north_static.yaml", "north_indexed_two.yaml", "north_indexed_four.yaml", "north_continuous.yaml",
        "north_sweep.yaml", "north_vehicle_idle.yaml", "north_try.yaml"}) {
    files.erase(name);  // the triad's north-finding sessions (NorthScenarios..., NorthTry...)
  }
  for (const std::string& name : resonatorScenarios()) files.erase(name);
  EXPECT_EQ(files, shipped);
  std::string reference_gyro;
  for (const std::string& name : shipped) {
    SCOPED_TRACE(name);
    const SimulationConfig c = SimulationConfig::load(dir + name, nodeOnlyScenarioKeys());
    EXPECT_EQ(c.resonator.samples_per_period, 32);
    EXPECT_DOUBLE_EQ(c.pickoff.gap, 20.0);
    // The gyro block (everything after the seed line up to the session part) is identical; a warming
    // gyro's bias drift is a line of its own there, a property of the session rather than of the gyro.
    const std::string text = readFile(dir + name);
    const std::size_t from = text.find("start_time:"), to = text.find("# ---- The session");
    ASSERT_NE(from, std::string::npos);
    ASSERT_NE(to, std::string::npos);
    const std::string gyro = withoutLines(text.substr(from, to - from), "  bias_drift:");
    if (reference_gyro.empty()) reference_gyro = gyro;
    EXPECT_EQ(gyro, reference_gyro);
  }
}

// dual_rate_drifting.yaml: D0 moves by 1.0e-6 rad/s over the whole session, the plateaus in the
// balanced order; dual_rate_table_clock.yaml: the table at 100 Hz on its own clock.
TEST(Scenarios, DriftingAndTableClockScenariosAreWhatTheySay) {
  const std::string dir = std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/";
  const SimulationConfig drifting = SimulationConfig::load(dir + "dual_rate_drifting.yaml", nodeOnlyScenarioKeys());
  const SimulationConfig plain = SimulationConfig::load(dir + "dual_rate.yaml", nodeOnlyScenarioKeys());
  const double duration = drifting.profile.duration();
  EXPECT_NEAR(duration, 1868.6, 1e-9);
  EXPECT_NEAR(duration, plain.profile.duration(), 1e-9);
  // The rate is given to 5 digits: 1e-6 rad/s within 1e-5 of it.
  EXPECT_NEAR(injectedBiasTrend(drifting, duration) - injectedBiasTrend(drifting, 0.0), 1e-6, 1e-11);
  EXPECT_EQ(drifting.resonator.bias_drift.random_walk, 0.0);
  EXPECT_FALSE(plain.resonator.bias_drift.enabled());
  const std::vector<Plateau> plateaus = plateausOf(drifting.profile, "calibration");
  ASSERT_EQ(plateaus.size(), 8u);
  const double order[8] = {0.05, -0.05, -0.05, 0.05, -0.05, 0.05, 0.05, -0.05};
  for (std::size_t n = 0; n < 8; ++n) EXPECT_EQ(plateaus[n].rate, order[n]) << n;

  const SimulationConfig clock = SimulationConfig::load(dir + "dual_rate_table_clock.yaml", nodeOnlyScenarioKeys());
  const TurntableLogConfig& log = clock.turntable_log;
  EXPECT_EQ(log.rate, 100.0);
  EXPECT_EQ(log.angle_noise, 2e-6);
  EXPECT_NEAR(log.angle_resolution, kTwoPi / (1 << 23), 1e-10);
  EXPECT_EQ(log.clock.offset, 0.1);
  EXPECT_EQ(log.clock.jitter, 0.002);
  EXPECT_EQ(log.clock.rate_error, 0.0);
  EXPECT_TRUE(log.clock.steps.empty());
  EXPECT_NEAR(clock.profile.duration(), plain.profile.duration(), 1e-9);
}

/// The text between `from` and `to` (both must be there).
std::string between(const std::string& text, const std::string& from, const std::string& to) {
  const std::size_t a = text.find(from), b = text.find(to);
  EXPECT_NE(a, std::string::npos) << from;
  EXPECT_NE(b, std::string::npos) << to;
  return a == std::string::npos || b == std::string::npos ? std::string() : text.substr(a, b - a);
}

/// The plateaus (rate != 0, constant) of a position's profile, and its longest rest.
void plateausAndRest(const TurntableProfile& p, std::vector<Plateau>* plateaus, double* rest) {
  *rest = 0.0;
  for (const TurntableProfile::Piece& piece : p.pieces()) {
    if (piece.accel != 0.0) continue;
    if (piece.rate0 == 0.0) *rest = std::max(*rest, piece.duration);
    if (piece.rate0 != 0.0 && piece.label.find("/settle") == std::string::npos) {
      plateaus->push_back({piece.start, piece.start + piece.duration, piece.rate0});
    }
  }
}

// config/scenarios/triad.yaml is the documented calibration session: the shipped gyro on each axis
// (varied a little), misalignments of tens to hundreds of microradians, a perfect fixture in the six
// positions +-z, +-x, +-y, each with a rest of 60 s and plateaus at +-0.05 rad/s that sweep the up
// axis's theta by 2 pi, moves of 10 s; triad_verification.yaml the same triad in tilted positions
// (the table's axis along a body diagonal) at +-0.08 rad/s; test/scenarios/triad_short.yaml its short
// form for the tests.
const std::string kScenarioDir = std::string(HRG_GYRO_SOURCE_DIR) + "/config/scenarios/";
const std::string kTriadShort = std::string(HRG_GYRO_SOURCE_DIR) + "/test/scenarios/triad_short.yaml";
/// The calibration's six positions: each axis up, then down.
const std::vector<std::string> kTriadUps = {"+z", "-z", "+x", "-x", "+y", "-y"};

TriadSimulationConfig loadTriadScenario(const std::string& path) {
  return TriadSimulationConfig::load(path, nodeOnlyScenarioKeys());
}

TEST(Scenarios, TriadScenariosShareOneTriadOfTheShippedGyro) {
  const TriadSimulationConfig cal = loadTriadScenario(kScenarioDir + "triad.yaml");
  // One triad in the three files, word for word.
  const std::string axes = between(readFile(kScenarioDir + "triad.yaml"), "  axes:", "  # ---- The session");
  EXPECT_EQ(between(readFile(kScenarioDir + "triad_verification.yaml"), "  axes:", "  # ---- The session"), axes);
  EXPECT_EQ(between(readFile(kTriadShort), "  axes:", "  # ---- The session"), axes);
  // The shipped gyro on each axis, a little different on each.
  const SimulationConfig shipped = SimulationConfig::load(kScenarioDir + "dual_rate.yaml", nodeOnlyScenarioKeys());
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const TriadAxisConfig& a = cal.axes[i];
    EXPECT_EQ(a.name, std::string(1, static_cast<char>('x' + i)));
    EXPECT_EQ(a.resonator.frequency, shipped.resonator.frequency);
    EXPECT_EQ(a.resonator.periods_per_output, shipped.resonator.periods_per_output);
    EXPECT_EQ(a.pickoff.gap, shipped.pickoff.gap);
    EXPECT_EQ(a.pickoff.noise, shipped.pickoff.noise);
    EXPECT_NEAR(a.resonator.scale_factor.meanAt(NAN), -0.56, 0.005);
    EXPECT_EQ(a.resonator.scale_factor.orders(), shipped.resonator.scale_factor.orders());
    if (i > 0) {
      EXPECT_NE(a.resonator.scale_factor, cal.axes[0].resonator.scale_factor);
      EXPECT_NE(a.pickoff.misplacement, cal.axes[0].pickoff.misplacement);
    }
    for (const double m : a.misalignment) {
      EXPECT_GE(std::abs(m), 1e-5);
      EXPECT_LE(std::abs(m), 1e-3);
    }
  }
  EXPECT_EQ(cal.axes[0].resonator.scale_factor, shipped.resonator.scale_factor);
  EXPECT_EQ(cal.axes[0].pickoff.misplacement, shipped.pickoff.misplacement);
}

TEST(Scenarios, TriadCalibrationScenarioTurnsEachAxisUpAndDown) {
  const TriadSimulationConfig cal = loadTriadScenario(kScenarioDir + "triad.yaml");
  // Six positions, each axis up and down, a perfect fixture.
  ASSERT_EQ(cal.positions.size(), kTriadUps.size());
  EXPECT_EQ(cal.fixture_error_std, 0.0);
  EXPECT_EQ(cal.turntable.wobble.amplitude, 0.0);
  for (std::size_t k = 0; k < kTriadUps.size(); ++k) {
    SCOPED_TRACE(kTriadUps[k]);
    const FixturePositionConfig& p = cal.positions[k];
    Eigen::Matrix3d r;
    ASSERT_TRUE(rotationForUp(kTriadUps[k], &r));
    EXPECT_EQ(p.nominal, r);
    EXPECT_EQ(p.error, Eigen::Vector3d::Zero());
    EXPECT_EQ(p.move, k == 0 ? 0.0 : 10.0);
    std::vector<Plateau> plateaus;
    double rest;
    plateausAndRest(p.profile, &plateaus, &rest);
    EXPECT_GE(rest, 60.0);
    ASSERT_EQ(plateaus.size(), 4u);
    const int up = kTriadUps[k][1] - 'x';
    for (const Plateau& q : plateaus) {
      EXPECT_EQ(std::abs(q.rate), 0.05);
      // The up axis's theta sweeps at least 2 pi on each plateau (today's dual-rate coverage).
      EXPECT_GE(std::abs(cal.axes[up].resonator.scale_factor.meanAt(NAN) * q.rate) * (q.end - q.start), kTwoPi);
    }
  }
  EXPECT_NEAR(cal.duration(), 5910.8, 1e-6);
}

TEST(Scenarios, TriadVerificationScenarioTurnsTheTableAboutBodyDiagonals) {
  const TriadSimulationConfig ver = loadTriadScenario(kScenarioDir + "triad_verification.yaml");
  // Every axis senses 1/sqrt(3) of the table's rate, +-0.08 rad/s, and each plateau sweeps every
  // axis's theta by at least 2 pi.
  EXPECT_GE(ver.positions.size(), 4u);
  for (const FixturePositionConfig& p : ver.positions) {
    SCOPED_TRACE(p.name);
    const Eigen::Vector3d table_axis = p.nominal.transpose() * Eigen::Vector3d::UnitZ();
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::abs(table_axis[i]), 1.0 / std::sqrt(3.0), 1e-12);
    EXPECT_EQ(p.error, Eigen::Vector3d::Zero());
    std::vector<Plateau> plateaus;
    double rest;
    plateausAndRest(p.profile, &plateaus, &rest);
    EXPECT_GE(rest, 60.0);
    ASSERT_EQ(plateaus.size(), 2u);
    for (const Plateau& q : plateaus) {
      EXPECT_EQ(std::abs(q.rate), 0.08);
      for (int i = 0; i < 3; ++i) {
        EXPECT_GE(
            std::abs(ver.axes[i].resonator.scale_factor.meanAt(NAN) * q.rate) / std::sqrt(3.0) * (q.end - q.start),
            kTwoPi);
      }
    }
  }
  // The diagonals of the four positions span the body frame (the body rate is checked about each axis
  // with both signs of the others).
  Eigen::MatrixXd diagonals(3, static_cast<Eigen::Index>(ver.positions.size()));
  for (std::size_t k = 0; k < ver.positions.size(); ++k) {
    diagonals.col(static_cast<Eigen::Index>(k)) = ver.positions[k].nominal.transpose() * Eigen::Vector3d::UnitZ();
  }
  EXPECT_EQ(Eigen::FullPivLU<Eigen::MatrixXd>(diagonals).rank(), 3);
}

TEST(Scenarios, TriadShortScenarioIsTheCalibrationInTenMinutes) {
  const TriadSimulationConfig brief = loadTriadScenario(kTriadShort);
  // The calibration's positions at +-0.4 rad/s, one plateau of each, ten minutes.
  ASSERT_EQ(brief.positions.size(), kTriadUps.size());
  for (std::size_t k = 0; k < kTriadUps.size(); ++k) {
    Eigen::Matrix3d r;
    rotationForUp(kTriadUps[k], &r);
    EXPECT_EQ(brief.positions[k].nominal, r) << kTriadUps[k];
    std::vector<Plateau> plateaus;
    double rest;
    plateausAndRest(brief.positions[k].profile, &plateaus, &rest);
    ASSERT_EQ(plateaus.size(), 2u);
    for (const Plateau& q : plateaus) EXPECT_GE(0.56 * std::abs(q.rate) * (q.end - q.start), kTwoPi);
  }
  EXPECT_LT(brief.duration(), 600.0);
}

/// The rests (pieces at rate 0, not accelerating) of a profile: their angle and length.
std::vector<std::pair<double, double>> restsOf(const TurntableProfile& p) {
  std::vector<std::pair<double, double>> rests;
  for (const TurntableProfile::Piece& piece : p.pieces()) {
    if (piece.accel == 0.0 && piece.rate0 == 0.0 && piece.duration > 0.0)
      rests.push_back({piece.angle0, piece.duration});
  }
  return rests;
}

// config/scenarios/north_*.yaml: the triad of triad.yaml, its D(theta) replaced by the residual a table
// calibration leaves, at latitude 0.9 rad and a true heading of 0.4137 rad, with an accelerometer;
// one session for each alignment mode.
TEST(Scenarios, NorthScenariosAreTheCalibratedTriadInEachAlignmentMode) {
  const TriadSimulationConfig cal = loadTriadScenario(kScenarioDir + "triad.yaml");
  std::map<std::string, TriadSimulationConfig> north;
  for (const char* name : {"north_static.yaml", "north_indexed_two.yaml", "north_indexed_four.yaml",
                           "north_continuous.yaml", "north_vehicle_idle.yaml"}) {
    SCOPED_TRACE(name);
    const TriadSimulationConfig c = loadTriadScenario(kScenarioDir + name);
    EXPECT_EQ(c.turntable.latitude, 0.9);
    EXPECT_EQ(c.turntable.azimuth, 0.4137);
    EXPECT_TRUE(c.accelerometer.enabled);
    EXPECT_LE(c.accelerometer.bias.cwiseAbs().maxCoeff(), 5e-4);
    for (int i = 0; i < 3; ++i) {
      const TriadAxisConfig &a = c.axes[i], &b = cal.axes[i];
      EXPECT_EQ(a.misalignment, b.misalignment);
      EXPECT_EQ(a.resonator.scale_factor, b.resonator.scale_factor);
      EXPECT_EQ(a.resonator.frequency, b.resonator.frequency);
      EXPECT_EQ(a.resonator.initial_theta, b.resonator.initial_theta);
      EXPECT_EQ(a.pickoff.noise, b.pickoff.noise);
      EXPECT_EQ(a.pickoff.misplacement, b.pickoff.misplacement);
      // The residual: 1e-8 rad/s of body rate, an order-2 term of 8e-9 rad/s.
      const HarmonicModel& d = a.resonator.drift;
      EXPECT_NEAR(std::abs(d.meanAt(NAN) / a.resonator.scale_factor.meanAt(NAN)), 1e-8, 1e-10);
      ASSERT_EQ(d.orders(), std::vector<int>{2});
      double coefficients[3];
      d.coefficientsAt(NAN, coefficients);  // mean, cos 2, sin 2
      EXPECT_NEAR(std::hypot(coefficients[1], coefficients[2]), 8e-9, 1e-10);
    }
    north.emplace(name, c);
  }
  // Static: one position, tilted by milliradians, the table at rest 125 s.
  const TriadSimulationConfig& st = north.at("north_static.yaml");
  ASSERT_EQ(st.positions.size(), 1u);
  EXPECT_EQ(restsOf(st.table_profile).size(), 1u);
  EXPECT_GE(st.duration(), 121.0);
  const Eigen::Vector3d up = st.positions[0].bodyToPlatter().transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_GT(std::hypot(up.x(), up.y()), 1e-3);
  EXPECT_LT(std::hypot(up.x(), up.y()), 5e-3);
  // Indexed: rests of 61 s (60 s after the alignment's settle) 180 and 90 deg apart; continuous: two
  // whole turns.
  const double steps[2] = {kPi, kPi / 2};
  const std::size_t counts[2] = {2, 4};
  const char* indexed[2] = {"north_indexed_two.yaml", "north_indexed_four.yaml"};
  for (int k = 0; k < 2; ++k) {
    SCOPED_TRACE(indexed[k]);
    const std::vector<std::pair<double, double>> rests = restsOf(north.at(indexed[k]).table_profile);
    ASSERT_EQ(rests.size(), counts[k]);
    for (std::size_t n = 0; n < rests.size(); ++n) {
      EXPECT_NEAR(rests[n].first, n * steps[k], 1e-12);
      EXPECT_GE(rests[n].second, 61.0);
    }
  }
  const TriadSimulationConfig& turning = north.at("north_continuous.yaml");
  double angle, rate;
  turning.table_profile.evaluate(turning.duration() - 1.0, &angle, &rate);
  EXPECT_NEAR(rate, kTwoPi / 120.0, 1e-12);
  EXPECT_GE(angle, 2.0 * kTwoPi);
}

// config/scenarios/north_sweep.yaml: north_static.yaml's triad, level and site, its axes run by the
// averaged resonator (triad.yaml's K0, the shell and drive calibrated but for the precession gain), D's
// order-2 residual of 8e-9 rad/s without the bias, each wave turned on the field calibration's plan.
TEST(Scenarios, NorthSweepScenarioTurnsTheCalibratedTriadOnTheFieldPlan) {
  const TriadSimulationConfig cal = loadTriadScenario(kScenarioDir + "triad.yaml");
  const TriadSimulationConfig st = loadTriadScenario(kScenarioDir + "north_static.yaml");
  const TriadSimulationConfig c = loadTriadScenario(kScenarioDir + "north_sweep.yaml");
  YAML::Node settings;
  settings["field"] = YAML::LoadFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/calibrator.yaml")["field"];
  const std::vector<PlannedPrecession> plan = fieldCommandPlan(CalibrationSettings::parse(YamlField(settings, "")));
  EXPECT_EQ(c.turntable.latitude, st.turntable.latitude);
  EXPECT_EQ(c.turntable.azimuth, st.turntable.azimuth);
  EXPECT_EQ(c.accelerometer.bias, st.accelerometer.bias);
  EXPECT_EQ(c.accelerometer.noise, st.accelerometer.noise);
  ASSERT_EQ(c.positions.size(), 1u);
  EXPECT_EQ(c.positions[0].bodyToPlatter(), st.positions[0].bodyToPlatter());
  EXPECT_EQ(restsOf(c.table_profile).size(), 1u);
  ASSERT_FALSE(plan.empty());
  EXPECT_GE(c.duration(), plan.back().time + 1.0);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    const TriadAxisConfig &a = c.axes[i], &b = cal.axes[i];
    EXPECT_EQ(a.misalignment, b.misalignment);
    EXPECT_EQ(a.resonator.initial_theta, b.resonator.initial_theta);
    EXPECT_EQ(a.pickoff.noise, b.pickoff.noise);
    EXPECT_EQ(a.pickoff.misplacement, b.pickoff.misplacement);
    ASSERT_TRUE(a.dynamics.averaged());
    EXPECT_NEAR(a.resonator.scale_factor.meanAt(NAN), b.resonator.scale_factor.meanAt(NAN), 1e-12);
    EXPECT_EQ(a.dynamics.shell.damping_anisotropy, 0.0);
    EXPECT_EQ(a.dynamics.shell.frequency_split, 0.0);
    const HarmonicModel& d = a.resonator.drift;
    ASSERT_EQ(d.orders(), std::vector<int>{2});
    double coefficients[3];
    d.coefficientsAt(NAN, coefficients);  // mean, cos 2, sin 2
    EXPECT_EQ(coefficients[0], 0.0);
    EXPECT_NEAR(std::hypot(coefficients[1], coefficients[2]), 8e-9, 1e-10);
    ASSERT_EQ(a.dynamics.commands.size(), plan.size());
    for (std::size_t k = 0; k < plan.size(); ++k) {
      EXPECT_NEAR(a.dynamics.commands[k].time, plan[k].time, 1e-6) << k;
      EXPECT_EQ(a.dynamics.commands[k].rate, plan[k].rate) << k;
    }
  }
}

// config/scenarios/north_try.yaml, the README's scenario to try the gyrocompass with: gyros the
// uncalibrated processors and the nominal triad file measure (K0 -0.56 and nothing else of K, no D, no
// misalignment: config/params_uncalibrated.yaml and config/triad.yaml are their exact model), an
// accelerometer, a base that moves, 150 s at latitude 0.9 rad.
TEST(Scenarios, NorthTryIsATriadTheUncalibratedChainMeasuresOnAMovingBase) {
  const TriadSimulationConfig c = loadTriadScenario(kScenarioDir + "north_try.yaml");
  const GyroParameters nominal =
      loadParameterFile(std::string(HRG_GYRO_SOURCE_DIR) + "/config/params_uncalibrated.yaml");
  for (const TriadAxisConfig& a : c.axes) {
    SCOPED_TRACE(a.name);
    EXPECT_EQ(a.misalignment, (std::array<double, 2>{0.0, 0.0}));
    EXPECT_EQ(a.scale, 0.0);
    EXPECT_EQ(a.resonator.scale_factor.meanAt(NAN), nominal.scale_factor.meanAt(NAN));
    for (const HarmonicModel* m : {&a.resonator.scale_factor, &a.resonator.drift}) {
      std::vector<double> terms(m->termCount());
      m->coefficientsAt(NAN, terms.data());
      for (std::size_t i = 1; i < terms.size(); ++i) EXPECT_EQ(terms[i], 0.0) << i;  // no harmonic
    }
    EXPECT_EQ(a.resonator.drift.meanAt(NAN), 0.0);
  }
  EXPECT_TRUE(c.accelerometer.enabled);
  EXPECT_TRUE(c.base_motion.enabled());
  EXPECT_EQ(c.base_motion.sways.size(), 2u);
  EXPECT_EQ(c.base_motion.vibration.rms, 0.05);
  EXPECT_EQ(c.turntable.latitude, 0.9);
  EXPECT_EQ(c.turntable.azimuth, 1.0);
  EXPECT_NEAR(c.duration(), 150.0, 1e-9);
}

// config/scenarios/north_vehicle_idle.yaml: north_static.yaml word for word up to its positions (the
// triad, accelerometer and table), a 300 s rest, on a vehicle idling: yaw jitter, a roll sway about the
// body's x and a pitch sway about its y (their ENU directions at the rest attitude), the engine's
// vibration. Its first seconds run, against north_static.yaml's: the gyros see the base turn, the
// accelerometer its vibration too.
TEST(Scenarios, NorthVehicleIdleScenarioIsTheStaticTriadOnAnIdlingVehicle) {
  const std::string static_text = readFile(kScenarioDir + "north_static.yaml"),
                    idle_text = readFile(kScenarioDir + "north_vehicle_idle.yaml");
  EXPECT_EQ(between(idle_text, "seed: 1", "  positions:"), between(static_text, "seed: 1", "  positions:"));
  const TriadSimulationConfig st = loadTriadScenario(kScenarioDir + "north_static.yaml");
  const TriadSimulationConfig c = loadTriadScenario(kScenarioDir + "north_vehicle_idle.yaml");
  ASSERT_EQ(c.positions.size(), 1u);
  EXPECT_EQ(c.positions[0].bodyToPlatter(), st.positions[0].bodyToPlatter());
  const std::vector<std::pair<double, double>> rests = restsOf(c.table_profile);
  ASSERT_EQ(rests.size(), 1u);
  EXPECT_EQ(rests[0].second, 300.0);
  EXPECT_FALSE(st.base_motion.enabled());
  const BaseMotionConfig& b = c.base_motion;
  EXPECT_TRUE(b.leans.empty());
  EXPECT_TRUE(b.knocks.empty());
  EXPECT_EQ(b.yaw_jitter.rms, 2.0e-5);
  EXPECT_EQ(b.yaw_jitter.low, 0.5);
  EXPECT_EQ(b.yaw_jitter.high, 5.0);
  EXPECT_EQ(b.vibration.rms, 0.05);
  EXPECT_EQ(b.vibration.low, 10.0);
  EXPECT_EQ(b.vibration.high, 40.0);
  ASSERT_EQ(b.sways.size(), 2u);
  EXPECT_EQ(b.sways[0].amplitude, 5.0e-5);
  EXPECT_EQ(b.sways[0].period, 1.7);
  EXPECT_EQ(b.sways[1].amplitude, 3.0e-5);
  EXPECT_EQ(b.sways[1].period, 0.9);
  // Roll about the vehicle's forward axis (the body's x, heading 0.0137 rad: almost North, not East),
  // pitch about its y, both level: their horizontal directions at the rest attitude.
  const TriadSimulator still(st);
  const Eigen::Matrix3d rest = still.motion().stateAt(0.0).body_to_enu;
  for (int k = 0; k < 2; ++k) {
    const Eigen::Vector3d level = Eigen::Vector3d(rest(0, k), rest(1, k), 0.0).normalized();
    EXPECT_LT((b.sways[k].axis - level).norm(), 1e-6) << k;
  }
  EXPECT_NEAR(std::atan2(b.sways[0].axis.x(), b.sways[0].axis.y()), 0.0137, 1e-4);
  // Its first 2 s against north_static.yaml's: the same noise draws, the base's motion added.
  TriadSimulator idle(c), calm(st);
  TriadSample a, s;
  double rate_squares = 0.0, force_squares = 0.0;
  const int n = 400;  // 200 Hz
  for (int k = 0; k < n; ++k) {
    ASSERT_TRUE(idle.next(&a));
    ASSERT_TRUE(calm.next(&s));
    rate_squares += (a.body.angular_velocity - s.body.angular_velocity).squaredNorm();
    force_squares += (a.accelerometer.specific_force - s.accelerometer.specific_force).squaredNorm();
  }
  const double rate_rms = std::sqrt(rate_squares / n), force_rms = std::sqrt(force_squares / n / 3.0);
  std::printf(
      "[ measured ] north_vehicle_idle.yaml, first 2 s: the base's rate %.2e rad/s rms, the accelerometer "
      "%.4f m/s^2 rms per axis off north_static.yaml\n",
      rate_rms, force_rms);
  EXPECT_GT(rate_rms, 1e-4);
  EXPECT_LT(rate_rms, 1e-3);
  EXPECT_GT(force_rms, 0.03);
  EXPECT_LT(force_rms, 0.08);
}

TEST(Scenarios, RejectsBadValuesByKey) {
  auto expectError = [](const std::string& yaml, const std::string& key) {
    try {
      SimulationConfig::parse(parse(yaml));
      ADD_FAILURE() << yaml;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), key) << e.what();
    }
  };
  const std::string profile = "turntable: {profile: [{type: dwell, duration: 1}]}\n";
  expectError("resonator: {samples_per_period: 4}\n" + profile, "resonator.samples_per_period");
  expectError("pickoff: {misplacement: [0, 0, 0]}\n" + profile, "pickoff.misplacement");
  expectError("pickoff: {amplitude_to_gap: 0.7}\n" + profile, "pickoff.amplitude_to_gap");
  expectError("resonator: {scale_factor: {orders: [3], mean: -0.5, cos: [0], sin: [0]}}\n" + profile,
              "resonator.scale_factor.orders[0]");
  expectError("seed: 1\n", "turntable.profile");
  expectError("time_scale: 10\n" + profile, "time_scale");  // node-only keys need the node's list
  EXPECT_NO_THROW(SimulationConfig::parse(parse("time_scale: 10\n" + profile), nodeOnlyScenarioKeys()));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
