// The triad scenario: its conventions (A, the up positions, roll-pitch-yaw, azimuth, wobble), the
// session it builds from the positions, and every bad key refused by name.
#include "hrg_gyro/core/simulation/triad_simulation_config.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <string>
#include <utility>
#include <vector>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/triad_file.h"

namespace hrg_gyro {
namespace core {
namespace {

const char* const kAxes =
    "  axes:\n"
    "    - {name: x, misalignment: [2.0e-4, -1.5e-4], scale: 1.0e-4}\n"
    "    - {name: y, misalignment: [3.0e-4, 1.0e-4]}\n"
    "    - {name: z, misalignment: [-2.5e-4, 0.5e-4], scale: -2.0e-4}\n";

const char* const kPositions =
    "  positions:\n"
    "    - {name: z up, up: '+z', profile: [{type: dwell, duration: 2.0}]}\n"
    "    - {name: x down, up: '-x', move: 3.0, profile: [{type: rate, rate: 0.2, duration: 4.0}]}\n"
    "    - {name: tilted, body_to_table: {roll: 0.1, pitch: -0.2, yaw: 0.3}, move: 2.5,\n"
    "       profile: [{type: dwell, duration: 1.0}]}\n";

TriadSimulationConfig parseText(const std::string& text) {
  return TriadSimulationConfig::parse(YamlField(YAML::Load(text), ""));
}

std::string scenario(const std::string& extra = "") {
  return std::string("seed: 3\ntriad:\n  frame_id: fixture\n") + kAxes +
         "  turntable: {latitude: 0.9, azimuth: 0.3}\n" + kPositions + extra;
}

bool isRotation(const Eigen::Matrix3d& r) {
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-15 &&
         std::abs(r.determinant() - 1.0) < 1e-15;
}

TEST(TriadSimulationConfigTest, UpPositionsPutTheNamedBodyAxisAlongTheTableAxis) {
  const char* const ups[] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (const char* up : ups) {
    SCOPED_TRACE(up);
    Eigen::Matrix3d r;
    ASSERT_TRUE(rotationForUp(up, &r));
    EXPECT_TRUE(isRotation(r));
    const int axis = up[1] - 'x';
    const double sign = up[0] == '+' ? 1.0 : -1.0;
    // The table's axis in the body frame is +-the named axis; the next axis lies along the platter's x.
    EXPECT_EQ(r.transpose() * Eigen::Vector3d::UnitZ(), sign * Eigen::Vector3d::Unit(axis));
    EXPECT_EQ(r.col((axis + 1) % 3), Eigen::Vector3d::UnitX());
  }
  Eigen::Matrix3d r;
  EXPECT_TRUE(rotationForUp("+z", &r));
  EXPECT_EQ(r, Eigen::Matrix3d::Identity());
  EXPECT_TRUE(rotationForUp("-z", &r));
  EXPECT_EQ(r, Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal().toDenseMatrix());  // a half turn about x
  for (const char* bad : {"z", "+w", "up", "+zz", ""}) EXPECT_FALSE(rotationForUp(bad, &r)) << bad;
}

TEST(TriadSimulationConfigTest, RollPitchYawTurnsAboutXThenYThenZ) {
  const double roll = 0.1, pitch = -0.2, yaw = 0.3;
  const Eigen::Matrix3d r = rotationFromRollPitchYaw(roll, pitch, yaw);
  EXPECT_TRUE(isRotation(r));
  const Eigen::Matrix3d rx = rotationFromVector(roll * Eigen::Vector3d::UnitX());
  const Eigen::Matrix3d ry = rotationFromVector(pitch * Eigen::Vector3d::UnitY());
  const Eigen::Matrix3d rz = rotationFromVector(yaw * Eigen::Vector3d::UnitZ());
  EXPECT_LT((r - rz * ry * rx).cwiseAbs().maxCoeff(), 1e-15);
  // The verification scenario's tilt: roll 45 deg, then pitch atan(1/sqrt(2)) = 35.26 deg, puts the
  // table's axis at 54.74 deg from every body axis, so each axis senses 1/sqrt(3) of the table rate.
  const Eigen::Vector3d axis =
      rotationFromRollPitchYaw(kPi / 4, std::atan(1.0 / std::sqrt(2.0)), 0.0).transpose() * Eigen::Vector3d::UnitZ();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(std::abs(axis[i]), 1.0 / std::sqrt(3.0), 1e-15) << i;
}

TEST(TriadSimulationConfigTest, MisalignmentsFillTheRowsOfAInBodyAxisOrder) {
  const TriadSimulationConfig c = parseText(scenario());
  Eigen::Matrix3d expected;
  expected << 1.0 + 1.0e-4, 2.0e-4, -1.5e-4,  // x: [A_xy, A_xz]
      3.0e-4, 1.0, 1.0e-4,                    // y: [A_yx, A_yz]
      -2.5e-4, 0.5e-4, 1.0 - 2.0e-4;          // z: [A_zx, A_zy]
  EXPECT_EQ(c.bodyToAxis(), expected);
  // The triad file of a perfect calibration: M = A^-1, in the file's own convention, and a valid file.
  const TriadParameters t = c.injectedTriad();
  EXPECT_EQ(t.frame_id, "fixture");
  EXPECT_EQ(t.axes, (std::array<std::string, 3>{{"x", "y", "z"}}));
  EXPECT_LT((t.bodyToAxis() - expected).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_EQ(t.bias, Eigen::Vector3d::Zero());
  const TriadParameters reread = parseTriadParameters(YAML::Load(emitTriadParameters(t)));
  EXPECT_EQ(reread.axis_to_body, t.axis_to_body);
}

TEST(TriadSimulationConfigTest, EarthRateAndWobbleFollowTheirConventions) {
  TriadTurntableConfig t;
  t.latitude = 0.9;
  const double horizontal = kEarthRotationRate * std::cos(0.9), up = kEarthRotationRate * std::sin(0.9);
  // Zero mark to the North: the horizontal rate along x; to the East: along y (x East, y North).
  EXPECT_LT((t.earthRateInTableZero() - Eigen::Vector3d(horizontal, 0.0, up)).norm(), 1e-20);
  t.azimuth = kPi / 2;
  EXPECT_LT((t.earthRateInTableZero() - Eigen::Vector3d(0.0, horizontal, up)).norm(), 1e-20);
  t.azimuth = 0.7;
  EXPECT_NEAR(t.earthRateInTableZero().norm(), kEarthRotationRate, 1e-20);

  TableWobbleConfig w;
  EXPECT_EQ(w.platterToTable(), Eigen::Matrix3d::Identity());
  w.amplitude = 1e-3;
  w.direction = 0.4;
  const Eigen::Matrix3d tilt = w.platterToTable();
  EXPECT_TRUE(isRotation(tilt));
  // The platter's normal, in the table frame, leans by the amplitude towards the direction.
  const Eigen::Vector3d normal = tilt * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d expected(std::sin(1e-3) * std::cos(0.4), std::sin(1e-3) * std::sin(0.4), std::cos(1e-3));
  EXPECT_LT((normal - expected).norm(), 1e-16);
}

TEST(TriadSimulationConfigTest, SessionIsEachPositionsProfileAfterItsMove) {
  const TriadSimulationConfig c = parseText(scenario());
  ASSERT_EQ(c.positions.size(), 3u);
  const FixturePositionConfig &p0 = c.positions[0], &p1 = c.positions[1], &p2 = c.positions[2];
  EXPECT_EQ(p0.move_start, 0.0);
  EXPECT_EQ(p0.start, 0.0);
  EXPECT_NEAR(p0.end, 2.0, 1e-12);
  EXPECT_EQ(p1.move_start, p0.end);
  EXPECT_NEAR(p1.start, p0.end + 3.0, 1e-12);
  // A rate segment ramps up at 0.5 rad/s^2 (0.4 s), holds 4 s and the profile ramps down (0.4 s).
  EXPECT_NEAR(p1.end, p1.start + 4.8, 1e-12);
  EXPECT_NEAR(p2.start, p1.end + 2.5, 1e-12);
  EXPECT_NEAR(c.duration(), p2.end, 1e-12);
  EXPECT_NEAR(c.duration(), 2.0 + 3.0 + 4.8 + 2.5 + 1.0, 1e-12);
  // The table stands still through a move and keeps its angle; the labels name the position.
  double angle0, rate0, angle1, rate1;
  const std::string* label;
  c.table_profile.evaluate(p2.move_start + 0.1, &angle0, &rate0, &label);
  EXPECT_EQ(*label, "tilted/move");
  EXPECT_EQ(rate0, 0.0);
  c.table_profile.evaluate(p2.start - 0.1, &angle1, &rate1);
  EXPECT_EQ(angle1, angle0);
  EXPECT_NEAR(angle0, 0.2 * 4.4, 1e-12);  // the ramps' 0.08 rad and the 0.8 rad of the plateau
  c.table_profile.evaluate(p1.start + 2.0, &angle0, &rate0, &label);
  EXPECT_EQ(*label, "x down/rate_0");
  EXPECT_EQ(rate0, 0.2);
  // The positions' orientations, and no error unless given or drawn.
  Eigen::Matrix3d down_x;
  rotationForUp("-x", &down_x);
  EXPECT_EQ(p1.nominal, down_x);
  EXPECT_EQ(p2.nominal, rotationFromRollPitchYaw(0.1, -0.2, 0.3));
  for (const FixturePositionConfig& p : c.positions) EXPECT_EQ(p.error, Eigen::Vector3d::Zero());
}

TEST(TriadSimulationConfigTest, FixtureErrorsAreGivenOrDrawnFromTheirOwnStream) {
  const std::string base = scenario("  fixture_error_std: 1.0e-3\n");
  const TriadSimulationConfig drawn = parseText(base);
  for (const FixturePositionConfig& p : drawn.positions) {
    EXPECT_GT(p.error.norm(), 0.0);
    EXPECT_LT(p.error.cwiseAbs().maxCoeff(), 5e-3);  // 5 sigma
  }
  EXPECT_EQ(parseText(base).positions[2].error, drawn.positions[2].error) << "same seed, same errors";
  // Giving position 1 its error changes no other position's draw.
  std::string given = base;
  given.replace(given.find("move: 3.0,"), 10, "move: 3.0, error: [1.0e-4, -2.0e-4, 3.0e-4],");
  const TriadSimulationConfig mixed = parseText(given);
  EXPECT_EQ(mixed.positions[1].error, Eigen::Vector3d(1.0e-4, -2.0e-4, 3.0e-4));
  EXPECT_EQ(mixed.positions[0].error, drawn.positions[0].error);
  EXPECT_EQ(mixed.positions[2].error, drawn.positions[2].error);
  // Another seed draws the drawn errors again and keeps the given one.
  TriadSimulationConfig reseeded = mixed;
  reseeded.setSeed(4);
  EXPECT_EQ(reseeded.seed, 4u);
  EXPECT_EQ(reseeded.positions[1].error, mixed.positions[1].error);
  EXPECT_NE(reseeded.positions[0].error, mixed.positions[0].error);
  EXPECT_LT(reseeded.positions[0].error.cwiseAbs().maxCoeff(), 5e-3);
  EXPECT_LT((mixed.positions[1].bodyToPlatter() -
             rotationFromVector(Eigen::Vector3d(1.0e-4, -2.0e-4, 3.0e-4)) * mixed.positions[1].nominal)
                .cwiseAbs()
                .maxCoeff(),
            1e-16);
}

TEST(TriadSimulationConfigTest, AxisScenarioIsTheAxisGyroOnTheSessionsTable) {
  std::string text = scenario();
  text.replace(text.find("{name: y,"), 9, "{name: y, resonator: {initial_theta: 0.7, rate_noise: 1.0e-6},");
  const TriadSimulationConfig c = parseText(text);
  const SimulationConfig x = c.axisScenario(0), y = c.axisScenario(1), z = c.axisScenario(2);
  EXPECT_EQ(y.resonator.initial_theta, 0.7);
  EXPECT_EQ(y.resonator.rate_noise, 1.0e-6);
  EXPECT_EQ(x.resonator.initial_theta, 0.0);
  EXPECT_NE(x.seed, y.seed);
  EXPECT_NE(y.seed, z.seed);
  EXPECT_NE(x.seed, c.seed);
  EXPECT_EQ(x.start_time, c.start_time);
  EXPECT_EQ(x.profile.duration(), c.duration());
  EXPECT_FALSE(x.generator.enabled);
  EXPECT_EQ(x.ripple.amplitude, 0.0) << "the ripple is in the session's profile already";
}

TEST(TriadSimulationConfigTest, OnlyTriadDocumentsAreTriadScenarios) {
  EXPECT_TRUE(isTriadScenario(YAML::Load(scenario())));
  EXPECT_FALSE(isTriadScenario(YAML::Load("seed: 1\nturntable: {profile: [{type: dwell, duration: 1}]}\n")));
  EXPECT_FALSE(isTriadScenario(YAML::Load("[1, 2]")));
}

TEST(TriadSimulationConfigTest, AccelerometerIsOffUnlessGivenAndTakesItsNoiseAsGiven) {
  EXPECT_FALSE(parseText(scenario()).accelerometer.enabled);
  const TriadSimulationConfig c =
      parseText(scenario("  accelerometer: {frame_id: acc, bias: [1.0e-3, -2.0e-3, 3.0e-3], noise: 2.0e-3,\n"
                         "                  mounting: {roll: 0.1, pitch: -0.2, yaw: 0.3}}\n"));
  EXPECT_TRUE(c.accelerometer.enabled);
  EXPECT_EQ(c.accelerometer.frame_id, "acc");
  EXPECT_EQ(c.accelerometer.bias, Eigen::Vector3d(1.0e-3, -2.0e-3, 3.0e-3));
  EXPECT_EQ(c.accelerometer.noise, 2.0e-3);
  EXPECT_TRUE(c.accelerometer.accelerometer_to_body.isApprox(rotationFromRollPitchYaw(0.1, -0.2, 0.3), 1e-15));
  EXPECT_FALSE(parseText(scenario("  accelerometer: {enabled: false}\n")).accelerometer.enabled);
  // A density N: per sample of the output period dt, N / sqrt(dt) (1 kHz here: N sqrt(1000 Hz)).
  const TriadSimulationConfig d = parseText(scenario("  accelerometer: {noise_density: 1.0e-4}\n"));
  EXPECT_NEAR(d.outputPeriod(), 1e-3, 1e-15);
  EXPECT_NEAR(d.accelerometer.noise, 1.0e-4 * std::sqrt(1000.0), 1e-15);
}

// The accelerometer's own errors and the base's motion: none unless given, read as given.
TEST(TriadSimulationConfigTest, AccelerometerErrorsAndTheBaseMotionAreNoneUnlessGiven) {
  const TriadSimulationConfig plain = parseText(scenario("  accelerometer: {noise: 1.0e-3}\n"));
  const TriadAccelerometerConfig& p = plain.accelerometer;
  EXPECT_EQ(p.scale, Eigen::Vector3d::Zero());
  EXPECT_EQ(p.misalignment, Eigen::Vector3d::Zero());
  EXPECT_EQ(p.axis_signs, Eigen::Vector3d::Ones());
  EXPECT_EQ(p.convention, TriadAccelerometerConfig::Convention::kSpecificForce);
  EXPECT_EQ(p.quantum, 0.0);
  EXPECT_FALSE(plain.base_motion.enabled());
  const TriadSimulationConfig c = parseText(scenario(
      "  accelerometer: {scale: [1.0e-3, -2.0e-3, 0.0], misalignment: [1.0e-4, 0.0, -3.0e-4], axis_signs: [-1, 1, "
      "1], convention: gravity, quantum: 1.0e-3}\n"
      "  base_motion:\n"
      "    leans: [{time: 1.0, duration: 2.0, rotation: [2.5e-5, 0.0, 0.0]}]\n"
      "    sways: [{amplitude: 5.0e-5, period: 1.7, axis: [0.0, 1.0, 0.0]}]\n"
      "    vibration: {rms: 0.05, low: 10.0, high: 40.0}\n"));
  const TriadAccelerometerConfig& a = c.accelerometer;
  EXPECT_EQ(a.scale, Eigen::Vector3d(1.0e-3, -2.0e-3, 0.0));
  EXPECT_EQ(a.misalignment, Eigen::Vector3d(1.0e-4, 0.0, -3.0e-4));
  EXPECT_EQ(a.axis_signs, Eigen::Vector3d(-1.0, 1.0, 1.0));
  EXPECT_EQ(a.convention, TriadAccelerometerConfig::Convention::kGravity);
  EXPECT_EQ(a.quantum, 1.0e-3);
  ASSERT_TRUE(c.base_motion.enabled());
  ASSERT_EQ(c.base_motion.leans.size(), 1u);
  EXPECT_EQ(c.base_motion.leans[0].rotation, Eigen::Vector3d(2.5e-5, 0.0, 0.0));
  ASSERT_EQ(c.base_motion.sways.size(), 1u);
  EXPECT_EQ(c.base_motion.sways[0].period, 1.7);
  EXPECT_EQ(c.base_motion.vibration.rms, 0.05);
  EXPECT_EQ(c.base_motion.yaw_jitter.rms, 0.0);
}

// An axis's `dynamics` section is a single gyro's: the averaged resonator's K replaces the resonator's,
// its schedule reaches the axis's scenario, and the other axes keep the given K and D.
TEST(TriadSimulationConfigTest, AnAxisMayRunTheAveragedResonatorOnItsSchedule) {
  std::string text = scenario();
  text.replace(text.find("{name: y,"), 9,
               "{name: y, dynamics: {model: averaged, shell: {bryan_factor: 0.3}, commands: [{time: 1.0, rate: 0.2}, "
               "{time: 2.0, rate: -0.2}]},");
  const TriadSimulationConfig c = parseText(text);
  EXPECT_FALSE(c.axes[0].dynamics.averaged());
  ASSERT_TRUE(c.axes[1].dynamics.averaged());
  EXPECT_FALSE(c.axes[2].dynamics.averaged());
  EXPECT_EQ(c.axes[1].resonator.scale_factor, HarmonicModel(-0.6));
  EXPECT_EQ(c.axes[1].resonator.quadrature, 0.0);
  const SimulationConfig y = c.axisScenario(1);
  ASSERT_TRUE(y.dynamics.averaged());
  ASSERT_EQ(y.dynamics.commands.size(), 2u);
  EXPECT_EQ(y.dynamics.commands[1].time, 2.0);
  EXPECT_EQ(y.dynamics.commands[1].rate, -0.2);
  EXPECT_FALSE(c.axisScenario(0).dynamics.averaged());
}

// A scenario the parser must refuse, and the key it must name.
void expectError(const std::string& yaml, const std::string& key) {
  try {
    parseText(yaml);
    ADD_FAILURE() << "accepted: " << yaml;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
  }
}

// The good scenario with one piece of its text replaced.
std::string replaced(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

// Each edit of the good scenario (replace `from` by `to`) and the key that refuses it.
struct BadEdit {
  std::string from, to, key;
};

void expectErrors(const std::vector<BadEdit>& edits) {
  const std::string good = scenario();
  for (const BadEdit& e : edits) expectError(replaced(good, e.from, e.to), e.key);
}

// A section appended to the good triad section, and the key under `prefix` that refuses it.
void expectSectionErrors(const std::string& section, const std::vector<std::pair<std::string, std::string>>& cases) {
  const std::string prefix = "triad." + section;
  for (const auto& [value, key] : cases) {
    expectError(scenario() + "  " + section + ": " + value + "\n", prefix + (key.empty() ? "" : "." + key));
  }
}

TEST(TriadSimulationConfigTest, RejectsBadTopLevelAndTriadKeys) {
  const std::string good = scenario();
  EXPECT_NO_THROW(parseText(good));
  expectError("seed: 1\n", "triad");
  expectError(good + "resonator: {frequency: 5000}\n", "resonator");
  expectError(replaced(good, "seed: 3", "seed: -1"), "seed");
  expectError(good + "start_time: 0\n", "start_time");
  expectError(replaced(good, "frame_id: fixture", "frame_id: /fixture"), "triad.frame_id");
  expectError(replaced(good, "frame_id: fixture", "frame_id: fixture\n  wobble: 1"), "triad.wobble");
  expectError(good + "  fixture_error_std: 0.5\n", "triad.fixture_error_std");
  expectError(good + "  fixture_error_std: -1.0e-4\n", "triad.fixture_error_std");
}

TEST(TriadSimulationConfigTest, RejectsBadAccelerometerKeys) {
  const std::vector<std::pair<std::string, std::string>> accelerometer = {
      {"{gain: 1}", "gain"},
      {"1", ""},
      {"{bias: [0, 0]}", "bias"},
      {"{bias: [0, 2.0, 0]}", "bias[1]"},
      {"{noise: -1.0e-3}", "noise"},
      {"{noise: 1.0e-3, noise_density: 1.0e-4}", "noise_density"},
      {"{noise_density: 1.0}", "noise_density"},
      {"{frame_id: ' '}", "frame_id"},
      {"{mounting: {roll: .inf}}", "mounting.roll"},
      {"{mounting: {heading: 1}}", "mounting.heading"},
      {"{enabled: maybe}", "enabled"},
      {"{scale: [0, 0]}", "scale"},
      {"{scale: [0, 0.5, 0]}", "scale[1]"},
      {"{scale: [0, 0, .nan]}", "scale[2]"},
      {"{misalignment: [0.2, 0, 0]}", "misalignment[0]"},
      {"{misalignment: 1.0e-4}", "misalignment"},
      {"{axis_signs: [1, 0, 1]}", "axis_signs[1]"},
      {"{axis_signs: [1, 1, 0.5]}", "axis_signs[2]"},
      {"{axis_signs: [1, -1]}", "axis_signs"},
      {"{convention: up}", "convention"},
      {"{convention: [gravity]}", "convention"},
      {"{quantum: -1.0e-3}", "quantum"},
      {"{quantum: 2.0}", "quantum"},
      {"{quantum: .inf}", "quantum"}};
  expectSectionErrors("accelerometer", accelerometer);
}

// The base's motion, named as the file writes it (its own checks: BaseMotionTest).
TEST(TriadSimulationConfigTest, RejectsBadBaseMotionKeys) {
  const std::vector<std::pair<std::string, std::string>> base = {
      {"1", ""},
      {"{sway: []}", "sway"},
      {"{leans: [{time: 1.0, duration: 0.0, rotation: [0, 0, 1.0e-5]}]}", "leans[0].duration"},
      {"{leans: [{duration: 1.0, rotation: [0, 0, 1.0e-5]}]}", "leans[0].time"},
      {"{leans: [{time: 1.0, rotation: [0, 0.2, 0]}]}", "leans[0].rotation"},
      {"{knocks: [{time: 1.0, rotation: [0, 0, 1.0e-5], ring_decay: 0.0}]}", "knocks[0].ring_decay"},
      {"{sways: [{amplitude: 1.0e-4, period: 10.0, axis: [1.0, 1.0, 0.0]}]}", "sways[0].axis"},
      {"{sways: [{amplitude: 1.0e-4}]}", "sways[0].period"},
      {"{yaw_jitter: {rms: -1.0}}", "yaw_jitter.rms"},
      {"{vibration: {rms: 0.05, low: 40.0, high: 10.0}}", "vibration.low"},
      {"{vibration: {rms: 0.05, components: 0}}", "vibration.components"},
      {"{vibration: {rms: 0.05, band: 1}}", "vibration.band"}};
  expectSectionErrors("base_motion", base);
}

TEST(TriadSimulationConfigTest, RejectsBadAxisKeys) {
  expectErrors({
      {"    - {name: z, misalignment: [-2.5e-4, 0.5e-4], scale: -2.0e-4}\n", "", "triad.axes"},
      {"{name: y,", "{name: x,", "triad.axes[1].name"},
      {"{name: y,", "{name: 'y/1',", "triad.axes[1].name"},
      {"{name: y,", "{name: y, gain: 2,", "triad.axes[1].gain"},
      {"[3.0e-4, 1.0e-4]", "[3.0e-4]", "triad.axes[1].misalignment"},
      {"[3.0e-4, 1.0e-4]", "[3.0e-4, 0.2]", "triad.axes[1].misalignment[1]"},
      {"scale: -2.0e-4", "scale: 0.1", "triad.axes[2].scale"},
      {"{name: y,", "{name: y, resonator: {samples_per_period: 4},", "triad.axes[1].resonator.samples_per_period"},
      {"{name: y,", "{name: y, resonator: {frequency: 5001},", "triad.axes[1].resonator.frequency"},
      {"{name: y,", "{name: y, resonator: {periods_per_output: 25},", "triad.axes[1].resonator.periods_per_output"},
      {"{name: y,", "{name: y, pickoff: {amplitude_to_gap: 0.7},", "triad.axes[1].pickoff.amplitude_to_gap"},
      {"{name: y,", "{name: y, channels: {drop_probability: 2},", "triad.axes[1].channels.drop_probability"},
      {"{name: y,", "{name: y, dynamics: {model: averaged, shel: {}},", "triad.axes[1].dynamics.shel"},
      {"{name: y,", "{name: y, dynamics: {commands: [{time: 1.0, rate: 0.2}]},", "triad.axes[1].dynamics"},
      {"{name: y,",
       "{name: y, dynamics: {model: averaged}, resonator: {scale_factor: {orders: [2], mean: -0.5, cos: [0.0], "
       "sin: [0.0]}},",
       "triad.axes[1].resonator.scale_factor"},
      {"{name: y,", "{name: y, dynamics: {model: averaged}, resonator: {quadrature: 0.01},",
       "triad.axes[1].resonator.quadrature"},
  });
}

TEST(TriadSimulationConfigTest, RejectsBadTurntableKeys) {
  const std::string table = "turntable: {latitude: 0.9, azimuth: 0.3}";
  expectErrors({
      {table, "turntable: {latitude: 2.0}", "triad.turntable.latitude"},
      {table, "turntable: {azimuth: .nan}", "triad.turntable.azimuth"},
      {table, "turntable: {acceleration: 0}", "triad.turntable.acceleration"},
      {table, "turntable: {profile: []}", "triad.turntable.profile"},
      {table, "turntable: {wobble: {amplitude: 0.1}}", "triad.turntable.wobble.amplitude"},
      {table, "turntable: {wobble: {amplitude: 1.0e-4, phase: 1}}", "triad.turntable.wobble.phase"},
      {table, "turntable: {ripple: {amplitude: 0.01}}", "triad.turntable.ripple.frequency"},
      {table, "turntable: {log: {rate: -1}}", "triad.turntable.log.rate"},
  });
}

TEST(TriadSimulationConfigTest, RejectsBadPositionKeys) {
  expectErrors({
      {kPositions, "  positions: []\n", "triad.positions"},
      {"up: '-x'", "up: 'x'", "triad.positions[1].up"},
      {"up: '-x'", "up: '-x', body_to_table: {roll: 0}", "triad.positions[1].up"},
      {"{name: x down, up: '-x',", "{name: x down,", "triad.positions[1].up"},
      {"roll: 0.1,", "roll: 0.1, spin: 2,", "triad.positions[2].body_to_table.spin"},
      {"name: x down", "name: z up", "triad.positions[1].name"},
      {"name: x down", "name: ''", "triad.positions[1].name"},
      {"move: 3.0,", "move: 0,", "triad.positions[1].move"},
      {"move: 3.0,", "", "triad.positions[1].move"},
      {"up: '+z',", "up: '+z', move: 1.0,", "triad.positions[0].move"},
      {"move: 3.0,", "move: 3.0, error: [0, 0.2, 0],", "triad.positions[1].error[1]"},
      {"move: 3.0,", "move: 3.0, error: [0, 0],", "triad.positions[1].error"},
      {"move: 3.0,", "move: 3.0, speed: 1,", "triad.positions[1].speed"},
      {"[{type: dwell, duration: 2.0}]", "[{type: dwell}]", "triad.positions[0].profile[0].duration"},
      {", profile: [{type: dwell, duration: 2.0}]", "", "triad.positions[0].profile"},
  });
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
