// The body's motion on the table against the exact model: the Earth's and the table's rates through
// the position's orientation, the fixture error and the wobble as documented, and moves that carry the
// body from one orientation to the next with a rate consistent with its orientation.
#include "hrg_gyro/core/simulation/triad_motion.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {
namespace {

TriadSimulationConfig parseText(const std::string& text) {
  return TriadSimulationConfig::parse(YamlField(YAML::Load(text), ""));
}

/// Three positions: +z at rest then turning, -x turning after a move, a tilted one with an error.
std::string scenario(const std::string& table = "{latitude: 0.9, azimuth: 0.3}", const std::string& error = "") {
  return "triad:\n"
         "  axes: [{name: x}, {name: y}, {name: z}]\n"
         "  turntable: " +
         table +
         "\n"
         "  positions:\n"
         "    - {name: a, up: '+z', profile: [{type: dwell, duration: 5.0}, {type: rate, rate: 0.3, duration: 10.0}]}\n"
         "    - {name: b, up: '-x', move: 4.0, profile: [{type: rate, rate: -0.25, duration: 8.0}]}\n"
         "    - {name: c, body_to_table: {roll: 0.7854, pitch: 0.6155}, move: 6.0" +
         error + ", profile: [{type: dwell, duration: 2.0}]}\n";
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

/// The Earth's rate in the platter's frame at table angle phi, written out (not through TriadMotion).
Eigen::Vector3d earthInPlatter(const TriadSimulationConfig& c, double phi) {
  const double h = kEarthRotationRate * std::cos(c.turntable.latitude);
  const double az = c.turntable.azimuth;
  return Eigen::Vector3d(h * std::cos(az - phi), h * std::sin(az - phi),
                         kEarthRotationRate * std::sin(c.turntable.latitude));
}

TEST(TriadMotionTest, StaticPositionSeesTheEarthRateThroughItsOrientation) {
  const TriadSimulationConfig c = parseText(scenario());
  const TriadMotion motion(c);
  const TriadBodyState s = motion.stateAt(2.0);
  EXPECT_EQ(s.position, 0u);
  EXPECT_TRUE(s.locked);
  EXPECT_EQ(s.table_rate, 0.0);
  EXPECT_EQ(s.table_angle, 0.0);
  EXPECT_EQ(s.body_to_table, Eigen::Matrix3d::Identity());
  EXPECT_LT((s.angular_velocity - earthInPlatter(c, 0.0)).norm(), 1e-20);
  EXPECT_EQ(motion.angularVelocityAt(2.0), s.angular_velocity);
  // Position c at rest: R^T Rz(phi)^T omega_E0, phi the angle the table was left at.
  const double t = c.positions[2].start + 1.0;
  const TriadBodyState tilted = motion.stateAt(t);
  EXPECT_EQ(tilted.position, 2u);
  const Eigen::Matrix3d r = c.positions[2].nominal;
  EXPECT_LT((tilted.angular_velocity - r.transpose() * earthInPlatter(c, tilted.table_angle)).norm(), 1e-19);
  EXPECT_NEAR(tilted.angular_velocity.norm(), kEarthRotationRate, 1e-19);
}

TEST(TriadMotionTest, TurningTableAddsItsRateAlongTheTableAxis) {
  const TriadSimulationConfig c = parseText(scenario());
  const TriadMotion motion(c);
  for (const double t : {10.0, c.positions[1].start + 5.0}) {
    const TriadBodyState s = motion.stateAt(t);
    ASSERT_NE(s.table_rate, 0.0);
    const Eigen::Matrix3d r = c.positions[s.position].nominal;
    const Eigen::Vector3d expected =
        r.transpose() * (s.table_rate * Eigen::Vector3d::UnitZ() + earthInPlatter(c, s.table_angle));
    EXPECT_LT((s.angular_velocity - expected).norm(), 1e-17) << t;
  }
  // In -x the table turns the body about -x.
  const TriadBodyState down = motion.stateAt(c.positions[1].start + 5.0);
  EXPECT_NEAR(down.angular_velocity.x(), 0.25 - kEarthRotationRate * std::sin(0.9), 1e-17);
}

TEST(TriadMotionTest, FixtureErrorTiltsTheTableAxisInTheBody) {
  // An error (rx, ry, rz) about the platter's axes: in +z the table's rate enters along
  // Exp(error)^T e_z ~ (-ry, rx, 1); rz only turns the body about the table's axis.
  const TriadSimulationConfig c =
      parseText(scenario("{latitude: 0.9, azimuth: 0.3}", ", error: [2.0e-4, -3.0e-4, 5.0e-4]"));
  std::string text = scenario();
  text.replace(text.find("up: '+z',"), 9, "up: '+z', error: [2.0e-4, -3.0e-4, 5.0e-4],");
  const TriadSimulationConfig up = parseText(text);
  const TriadMotion motion(up);
  const TriadBodyState s = motion.stateAt(10.0);
  const Eigen::Matrix3d err = rotationFromVector(Eigen::Vector3d(2.0e-4, -3.0e-4, 5.0e-4));
  EXPECT_LT((s.body_to_table - err).cwiseAbs().maxCoeff(), 1e-16);
  const Eigen::Vector3d table_axis = err.transpose() * Eigen::Vector3d::UnitZ();
  EXPECT_NEAR(table_axis.x(), 3.0e-4, 2e-7);
  EXPECT_NEAR(table_axis.y(), 2.0e-4, 2e-7);
  const Eigen::Vector3d expected =
      err.transpose() * (0.3 * Eigen::Vector3d::UnitZ() + earthInPlatter(up, s.table_angle));
  EXPECT_LT((s.angular_velocity - expected).norm(), 1e-17);
  // The tilted position's error, likewise, on top of its nominal orientation.
  const TriadBodyState tilted = TriadMotion(c).stateAt(c.positions[2].start + 1.0);
  EXPECT_LT(
      (tilted.body_to_table - rotationFromVector(Eigen::Vector3d(2.0e-4, -3.0e-4, 5.0e-4)) * c.positions[2].nominal)
          .cwiseAbs()
          .maxCoeff(),
      1e-16);
}

TEST(TriadMotionTest, WobbleIsATiltCommonToEveryPosition) {
  // The platter's normal leans by 1 mrad towards its direction 0.4 rad: the body on it sees the
  // table's axis along W^T e_z, the same in the platter's frame for every position and table angle.
  const TriadSimulationConfig c =
      parseText(scenario("{latitude: 0.9, azimuth: 0.3, wobble: {amplitude: 1.0e-3, direction: 0.4}}"));
  const TriadMotion motion(c);
  const Eigen::Matrix3d w = c.turntable.wobble.platterToTable();
  for (const double t : {10.0, 12.5, c.positions[1].start + 5.0}) {
    const TriadBodyState s = motion.stateAt(t);
    const Eigen::Matrix3d r = c.positions[s.position].nominal;
    EXPECT_LT((s.body_to_table - w * r).cwiseAbs().maxCoeff(), 1e-16);
    EXPECT_LT((s.body_to_platter - r).cwiseAbs().maxCoeff(), 1e-16);
    const Eigen::Vector3d table_frame_rate = s.table_rate * Eigen::Vector3d::UnitZ() + earthInPlatter(c, s.table_angle);
    EXPECT_LT((s.angular_velocity - r.transpose() * w.transpose() * table_frame_rate).norm(), 1e-17) << t;
    EXPECT_LT((motion.tableFrameRateAt(t) - table_frame_rate).norm(), 1e-19) << "the table's own axis is not tilted";
  }
  // In +z the table's rate leaks into x and y by -sin(a) (cos d, sin d).
  const TriadBodyState s = motion.stateAt(10.0);
  const Eigen::Vector3d table_part = s.angular_velocity - w.transpose() * earthInPlatter(c, s.table_angle);
  EXPECT_NEAR(table_part.x() / 0.3, -std::sin(1e-3) * std::cos(0.4), 1e-15);
  EXPECT_NEAR(table_part.y() / 0.3, -std::sin(1e-3) * std::sin(0.4), 1e-15);
}

TEST(TriadMotionTest, MoveCarriesTheBodyFromOnePositionToTheNext) {
  // With fixture errors and wobble, so that every term is there: integrating the body's rate relative
  // to the (turning, inertially) table frame, d R/dt = R [omega_body]x - [omega_table]x R, through the
  // move from the previous position's true orientation must end in the next one's and pass through
  // the orientations the motion reports on the way.
  std::string text = scenario("{latitude: 0.9, azimuth: 0.3, wobble: {amplitude: 1.0e-3, direction: 0.4}}",
                              ", error: [1.0e-3, 2.0e-3, -1.5e-3]");
  text.replace(text.find("move: 4.0,"), 10, "move: 4.0, error: [-2.0e-3, 0.5e-3, 1.0e-3],");
  const TriadSimulationConfig c = parseText(text);
  const TriadMotion motion(c);
  for (std::size_t k = 1; k < c.positions.size(); ++k) {
    SCOPED_TRACE(k);
    const FixturePositionConfig& p = c.positions[k];
    EXPECT_FALSE(motion.stateAt(p.move_start + 0.5 * p.move).locked);
    EXPECT_EQ(motion.stateAt(p.move_start + 0.5 * p.move).position, k);
    EXPECT_TRUE(motion.stateAt(p.start).locked);
    Eigen::Matrix3d r = motion.stateAt(p.move_start).body_to_table;
    EXPECT_LT((r - c.turntable.wobble.platterToTable() * c.positions[k - 1].bodyToPlatter()).cwiseAbs().maxCoeff(),
              1e-15);
    auto derivative = [&](double t, const Eigen::Matrix3d& m) {
      return Eigen::Matrix3d(m * skew(motion.angularVelocityAt(t)) - skew(motion.tableFrameRateAt(t)) * m);
    };
    const int steps = 4000;
    const double h = p.move / steps;
    double worst_on_the_way = 0.0;
    for (int n = 0; n < steps; ++n) {
      const double t = p.move_start + n * h;
      const Eigen::Matrix3d k1 = derivative(t, r);
      const Eigen::Matrix3d k2 = derivative(t + h / 2, r + h / 2 * k1);
      const Eigen::Matrix3d k3 = derivative(t + h / 2, r + h / 2 * k2);
      const Eigen::Matrix3d k4 = derivative(t + h, r + h * k3);
      r += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      worst_on_the_way = std::max(worst_on_the_way, (r - motion.stateAt(t + h).body_to_table).cwiseAbs().maxCoeff());
    }
    const Eigen::Matrix3d expected = c.turntable.wobble.platterToTable() * p.bodyToPlatter();
    EXPECT_LT((r - expected).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_LT(worst_on_the_way, 1e-12);
    // At rest at both ends of the move: the body's rate is then the table frame's.
    for (const double t : {p.move_start, p.start}) {
      const TriadBodyState s = motion.stateAt(t);
      EXPECT_LT((s.angular_velocity - s.body_to_table.transpose() * motion.tableFrameRateAt(t)).norm(), 1e-18);
    }
  }
}

/// A base with every motion: a lean of 25 urad, a knock, a sway, yaw jitter and vibration.
const char* const kMovingBase =
    "  base_motion:\n"
    "    leans: [{time: 3.0, duration: 2.0, rotation: [2.0e-5, -1.5e-5, 0.0]}]\n"
    "    knocks: [{time: 12.0, rotation: [1.0e-5, 0.0, 2.0e-5]}]\n"
    "    sways: [{amplitude: 5.0e-5, period: 1.7, axis: [0.6, 0.8, 0.0]}]\n"
    "    yaw_jitter: {rms: 2.0e-5}\n"
    "    vibration: {rms: 0.05}\n";

// On a moving base the body's attitude is D C_nominal and its rate the still base's with the Earth's
// rate seen through D and D's own rate added; the table frame turns with D; what is relative to the
// base (table angle, body_to_table) does not move. Checked against the formula, against the table
// frame's rate written from its attitude D T0 Rz(phi), and against the attitude's derivative
// (C^T dC/dt = [omega_body - C^T Omega_enu]x, central differences).
TEST(TriadMotionTest, AMovingBaseTurnsTheBodyAndTheTableWithIt) {
  const TriadSimulationConfig still = parseText(scenario());
  const TriadSimulationConfig c = parseText(scenario() + kMovingBase);
  const TriadMotion moving(c), fixed(still);
  const BaseMotion base(c.base_motion, c.seed);
  const Eigen::Vector3d earth(0.0, kEarthRotationRate * std::cos(0.9), kEarthRotationRate * std::sin(0.9));
  const Eigen::Matrix3d table_zero = Eigen::AngleAxisd(kPi / 2 - 0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  // At rest, in the lean, turning, in the knock's ringing, in a move, in the tilted position.
  for (const double t : {2.0, 4.0, 10.0, 12.03, c.positions[1].move_start + 2.0, c.positions[2].start + 1.0}) {
    SCOPED_TRACE(t);
    const TriadBodyState s = moving.stateAt(t), n = fixed.stateAt(t);
    Eigen::Matrix3d d;
    Eigen::Vector3d w;
    base.stateAt(t, &d, &w);
    EXPECT_EQ(s.base_rotation, d);
    EXPECT_EQ(n.base_rotation, Eigen::Matrix3d::Identity());
    EXPECT_EQ(s.table_angle, n.table_angle);
    EXPECT_EQ(s.body_to_table, n.body_to_table);
    EXPECT_EQ(s.locked, n.locked);
    EXPECT_LT((s.body_to_enu - d * n.body_to_enu).cwiseAbs().maxCoeff(), 1e-16);
    const Eigen::Matrix3d ct = s.body_to_enu.transpose(), nt = n.body_to_enu.transpose();
    const Eigen::Vector3d expected = n.angular_velocity + (ct - nt) * earth + ct * w;
    // Rounding: 1e-18 rad/s of the Earth's rate, 2e-16 of the table's and the move's.
    const double rounding = 1e-18 + 2e-16 * s.angular_velocity.norm();
    EXPECT_LT((s.angular_velocity - expected).norm(), rounding);
    EXPECT_LT((moving.angularVelocityAt(t) - s.angular_velocity).norm(), rounding);
    const Eigen::Matrix3d table_to_enu = d * table_zero * Eigen::AngleAxisd(s.table_angle, Eigen::Vector3d::UnitZ());
    const Eigen::Vector3d table_rate = table_to_enu.transpose() * (earth + w) + s.table_rate * Eigen::Vector3d::UnitZ();
    EXPECT_LT((moving.tableFrameRateAt(t) - table_rate).norm(), 1e-18 + 2e-16 * table_rate.norm());
    const double h = 1e-5;
    const Eigen::Matrix3d dc = (moving.stateAt(t + h).body_to_enu - moving.stateAt(t - h).body_to_enu) / (2 * h);
    const Eigen::Matrix3d relative = ct * dc;
    const Eigen::Vector3d numeric = Eigen::Vector3d(relative(2, 1), relative(0, 2), relative(1, 0)) + ct * earth;
    EXPECT_LT((numeric - s.angular_velocity).norm(), 2e-10 + 1e-9 * s.angular_velocity.norm());
  }
  // An empty section is a still base: the still path, bit for bit.
  const TriadMotion empty(parseText(scenario() + "  base_motion: {}\n"));
  EXPECT_FALSE(empty.base().enabled());
  for (const double t : {2.0, 10.0, c.positions[1].move_start + 2.0}) {
    EXPECT_EQ(empty.stateAt(t).body_to_enu, fixed.stateAt(t).body_to_enu);
    EXPECT_EQ(empty.angularVelocityAt(t), fixed.angularVelocityAt(t));
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
