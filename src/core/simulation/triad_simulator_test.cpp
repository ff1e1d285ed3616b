// The simulated triad against the exact model: each axis senses its row of A times the body's rate
// (at rest the Earth's rate, turning the table's rate through A and the orientation), integrates it
// through its own K and D, and shares the stamps with the others; the table, fixture and body logs;
// fixture errors and wobble as documented; determinism and independent noise.
#include "hrg_gyro/core/simulation/triad_simulator.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <string>

#include "core/testing/bit_fingerprint.h"
#include "core/testing/shipped_scenarios.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/signal/wave_estimator.h"

namespace hrg_gyro {
namespace core {
namespace {

TriadSimulationConfig parseText(const std::string& text) {
  return TriadSimulationConfig::parse(YamlField(YAML::Load(text), ""));
}

/// Each axis its own K(theta) and D(theta) (K_i = -0.56 + c_i cos 2theta, D_i = d_i + e_i sin 2theta).
const double kCos2[3] = {-2.0e-4, 1.5e-4, 3.0e-4}, kD0[3] = {1.0e-5, -2.0e-5, 0.5e-5},
             kSin2D[3] = {2.0e-5, 1.0e-5, -1.0e-5};

std::string axis(int i, const std::string& name, const std::string& misalignment, const std::string& extra = "") {
  return "    - {name: " + name + ", misalignment: " + misalignment + extra +
         ", resonator: {initial_theta: " + formatDouble(0.2 + i) + ", scale_factor: {orders: [2], mean: -0.56, cos: [" +
         formatDouble(kCos2[i]) + "], sin: [0.0]}, drift: {orders: [2], mean: " + formatDouble(kD0[i]) +
         ", cos: [0.0], sin: [" + formatDouble(kSin2D[i]) + "]}}}\n";
}

/// +z at rest, then turning; moved to -x, turning the other way; moved to a tilted position at rest.
std::string scenario(const std::string& table = "{latitude: 0.9, azimuth: 0.3}", const std::string& first = "",
                     const std::string& axis_extra = "") {
  return "seed: 5\n"
         "triad:\n"
         "  frame_id: fixture\n"
         "  axes:\n" +
         axis(0, "x", "[2.0e-4, -1.5e-4]", axis_extra) + axis(1, "y", "[3.0e-4, 1.0e-4]", axis_extra) +
         axis(2, "z", "[-2.5e-4, 0.5e-4]", axis_extra) + "  turntable: " + table +
         "\n"
         "  positions:\n"
         "    - {name: a, up: '+z'" +
         first +
         ", profile: [{type: dwell, duration: 5.0}, {type: rate, rate: 0.3, duration: 6.0}]}\n"
         "    - {name: b, up: '-x', move: 3.0, profile: [{type: rate, rate: -0.25, duration: 6.0}]}\n"
         "    - {name: c, body_to_table: {roll: 0.7854, pitch: 0.6155, yaw: 0.2}, move: 4.0,\n"
         "       profile: [{type: dwell, duration: 3.0}]}\n";
}

/// Every sample of the session. The samples' names and labels point into the simulator: keep it.
std::vector<TriadSample> runAll(TriadSimulator& sim) {
  std::vector<TriadSample> out;
  TriadSample s;
  while (sim.next(&s)) out.push_back(s);
  return out;
}

double timeOf(const TriadSimulationConfig& c, const TriadSample& s) { return toSeconds(s.stamp) - c.start_time; }

/// The first sample at or after t.
const TriadSample& sampleAt(const TriadSimulationConfig& c, const std::vector<TriadSample>& samples, double t) {
  for (const TriadSample& s : samples) {
    if (timeOf(c, s) >= t) return s;
  }
  return samples.back();
}

/// theta(t2) by RK4 of d theta/dt = K_i(theta) r(t) + D_i(theta) from theta(t1), written out here.
double integrateTheta(int i, double theta, double t1, double t2, const std::function<double(double)>& rate) {
  auto f = [&](double t, double th) {
    return (-0.56 + kCos2[i] * std::cos(2 * th)) * rate(t) + kD0[i] + kSin2D[i] * std::sin(2 * th);
  };
  const int n = 20000;
  const double h = (t2 - t1) / n;
  for (int k = 0; k < n; ++k) {
    const double t = t1 + k * h;
    const double k1 = f(t, theta), k2 = f(t + h / 2, theta + h / 2 * k1), k3 = f(t + h / 2, theta + h / 2 * k2),
                 k4 = f(t + h, theta + h * k3);
    theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return theta;
}

Eigen::Vector3d earthInPlatter(const TriadSimulationConfig& c, double phi) {
  const double h = kEarthRotationRate * std::cos(c.turntable.latitude), az = c.turntable.azimuth;
  return Eigen::Vector3d(h * std::cos(az - phi), h * std::sin(az - phi),
                         kEarthRotationRate * std::sin(c.turntable.latitude));
}

TEST(TriadSimulatorTest, AxesShareTheStampsAndSenseTheirRowOfA) {
  const TriadSimulationConfig c = parseText(scenario());
  const Eigen::Matrix3d a = c.bodyToAxis();
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  EXPECT_NEAR(samples.size() * c.outputPeriod(), c.duration(), c.outputPeriod());
  double worst_wave = 0.0;
  for (std::size_t n = 0; n < samples.size(); ++n) {
    const TriadSample& s = samples[n];
    ASSERT_EQ(s.index, n);
    for (int i = 0; i < 3; ++i) {
      const SimulationSample& x = s.axes[i];
      ASSERT_EQ(x.stamp, s.stamp);
      ASSERT_EQ(x.index, s.index);
      EXPECT_NEAR(x.truth.inertial_rate, a.row(i).dot(s.body.angular_velocity), 2e-16) << n << " axis " << i;
      EXPECT_TRUE(x.turntable.empty());
      WaveState w;
      ASSERT_EQ(estimateWave(x.z, WaveLimits{}, &w), WaveStatus::kOk);
      worst_wave = std::max(worst_wave, std::abs(wrapToPi(2.0 * (w.theta - x.truth.theta)) / 2.0));
    }
    // One table record with each sample, stamped like it, with the table's true state.
    ASSERT_EQ(s.turntable.size(), 1u);
    EXPECT_EQ(s.turntable[0].stamp, s.stamp);
    EXPECT_EQ(s.turntable[0].angle, s.axes[0].truth.table_angle);
    EXPECT_EQ(s.turntable[0].rate, s.axes[0].truth.table_rate);
  }
  // Ideal pickoffs: the channels carry each axis's own theta, up to the demodulation's rotation term
  // theta rate sin(2 tau) / (2 w): 7e-6 rad while the operator turns the body at 1.4 rad/s.
  EXPECT_LT(worst_wave, 1e-5);
  EXPECT_EQ(*samples[0].axes[0].truth.segment, "a/dwell_0");
}

TEST(TriadSimulatorTest, StaticPositionGivesEachAxisItsProjectionOfTheEarthRate) {
  const TriadSimulationConfig c = parseText(scenario());
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  const Eigen::Matrix3d a = c.bodyToAxis();
  // Position a (+z) at rest, and position c (tilted) at rest at the angle the table was left at.
  for (const auto& [t1, t2] : {std::pair<double, double>{0.5, 4.5}, {c.positions[2].start + 0.2, c.duration() - 0.2}}) {
    const TriadSample &s1 = sampleAt(c, samples, t1), &s2 = sampleAt(c, samples, t2);
    const double dt = timeOf(c, s2) - timeOf(c, s1);
    const Eigen::Matrix3d r = c.positions[s1.body.position].nominal;
    const Eigen::Vector3d earth = r.transpose() * earthInPlatter(c, s1.axes[0].truth.table_angle);
    for (int i = 0; i < 3; ++i) {
      SCOPED_TRACE(i);
      const double rate = a.row(i).dot(earth);
      EXPECT_NEAR(s1.axes[i].truth.inertial_rate, rate, 1e-19);
      // Exact but for the rounding of the angles since the start (up to 2 rad here).
      EXPECT_NEAR(s2.axes[i].truth.inertial_angle - s1.axes[i].truth.inertial_angle, rate * dt, 1e-15);
      // theta follows K_i(theta) A_i . R^T omega_E + D_i(theta), integrated here independently.
      const double theta2 =
          integrateTheta(i, s1.axes[i].truth.theta, timeOf(c, s1), timeOf(c, s2), [&](double) { return rate; });
      EXPECT_NEAR(s2.axes[i].truth.theta, theta2, 1e-12);
    }
  }
}

TEST(TriadSimulatorTest, TurningPositionGivesTheTableRateThroughAAndTheOrientation) {
  const TriadSimulationConfig c = parseText(scenario());
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  const Eigen::Matrix3d a = c.bodyToAxis();
  // The plateaus of a (+z, 0.3 rad/s) and b (-x, -0.25 rad/s), away from the ramps.
  for (const auto& [t1, t2, rate] : {std::tuple<double, double, double>{6.0, 11.0, 0.3},
                                     {c.positions[1].start + 1.0, c.positions[1].start + 6.0, -0.25}}) {
    const TriadSample &s1 = sampleAt(c, samples, t1), &s2 = sampleAt(c, samples, t2);
    ASSERT_EQ(s1.axes[0].truth.table_rate, rate);
    ASSERT_EQ(s2.axes[0].truth.table_rate, rate);
    const double tt1 = timeOf(c, s1), tt2 = timeOf(c, s2);
    const double phi1 = s1.axes[0].truth.table_angle, phi2 = s2.axes[0].truth.table_angle;
    EXPECT_NEAR(phi2 - phi1, rate * (tt2 - tt1), 1e-12);
    // The exact integral over the plateau: the table's angle along the table axis, the Earth's rate
    // turning in the platter's frame (closed form for a constant rate), through R and A.
    const double h = kEarthRotationRate * std::cos(c.turntable.latitude), az = c.turntable.azimuth;
    const Eigen::Vector3d integral(-h / rate * (std::sin(az - phi2) - std::sin(az - phi1)),
                                   h / rate * (std::cos(az - phi2) - std::cos(az - phi1)),
                                   (phi2 - phi1) + kEarthRotationRate * std::sin(c.turntable.latitude) * (tt2 - tt1));
    const Eigen::Matrix3d r = c.positions[s1.body.position].nominal;
    for (int i = 0; i < 3; ++i) {
      SCOPED_TRACE(i);
      const double expected = a.row(i).dot(r.transpose() * integral);
      EXPECT_NEAR(s2.axes[i].truth.inertial_angle - s1.axes[i].truth.inertial_angle, expected, 1e-12);
      auto sensed = [&](double t) {
        const double phi = phi1 + rate * (t - tt1);
        return a.row(i).dot(r.transpose() * (rate * Eigen::Vector3d::UnitZ() + earthInPlatter(c, phi)));
      };
      EXPECT_NEAR(s2.axes[i].truth.theta, integrateTheta(i, s1.axes[i].truth.theta, tt1, tt2, sensed), 1e-10);
    }
  }
}

TEST(TriadSimulatorTest, FixtureIsLoggedOnEveryChangeAndEverySecondAndTheMoveTurnsTheBody) {
  const TriadSimulationConfig c = parseText(scenario());
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  ASSERT_TRUE(samples[0].fixture_logged);
  double last_logged = timeOf(c, samples[0]);
  int changes = 0;
  for (std::size_t n = 1; n < samples.size(); ++n) {
    const TriadSample &s = samples[n], &previous = samples[n - 1];
    const bool changed = s.fixture.index != previous.fixture.index || s.fixture.locked != previous.fixture.locked;
    if (changed) {
      ++changes;
      EXPECT_TRUE(s.fixture_logged) << n;
    }
    const double t = timeOf(c, s);
    if (s.fixture_logged) {
      EXPECT_TRUE(changed || t - last_logged > 1.0 - c.outputPeriod()) << n;
      last_logged = t;
    }
    EXPECT_LT(t - last_logged, 1.0) << n;
    EXPECT_EQ(s.fixture.index, s.body.position);
    const FixturePositionConfig& p = c.positions[s.fixture.index];
    EXPECT_EQ(*s.fixture.name, p.name);
    EXPECT_LT(s.fixture.body_to_table.angularDistance(Eigen::Quaterniond(p.nominal)), 1e-15);
    // Unlocked exactly while the body is moved into the position.
    EXPECT_EQ(s.fixture.locked, !(t >= p.move_start && t < p.start)) << n;
  }
  EXPECT_EQ(changes, 4);  // two moves: unlocked into b, locked in b, unlocked into c, locked in c
  // The body's orientation: the position's, then turning through the move, then the next one's.
  for (std::size_t k = 1; k < c.positions.size(); ++k) {
    const FixturePositionConfig& p = c.positions[k];
    const Eigen::Quaterniond before(c.positions[k - 1].nominal), after(p.nominal);
    const TriadSample& mid = sampleAt(c, samples, p.move_start + 0.5 * p.move);
    EXPECT_GT(mid.body.body_to_table.angularDistance(before), 0.1);
    EXPECT_GT(mid.body.body_to_table.angularDistance(after), 0.1);
    EXPECT_GT(mid.body.angular_velocity.norm(), 0.1) << "the operator turns the body";
    EXPECT_LT(sampleAt(c, samples, p.start).body.body_to_table.angularDistance(after), 1e-15);
    EXPECT_LT(sampleAt(c, samples, p.move_start - 0.01).body.body_to_table.angularDistance(before), 1e-15);
  }
}

TEST(TriadSimulatorTest, FixtureErrorAndWobbleEnterTheCrossAxisResponsesAsDocumented) {
  // At the pole the Earth's rate lies along the table's axis: each axis's response to the table is
  // then A_i . R_true^T e_z per rad of inertial table angle. Position a (+z) is off by a small
  // rotation (rx, ry) and the platter wobbles; a second +z position follows, upside down (-z).
  const std::string table = "{latitude: 1.5707963267948966, wobble: {amplitude: 1.0e-4, direction: 0.4}}";
  std::string text = scenario(table, ", error: [1.2e-4, 2.0e-4, 0.0]");
  text.replace(text.find("up: '-x'"), 8, "up: '-z'");
  const TriadSimulationConfig c = parseText(text);
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  const Eigen::Matrix3d a = c.bodyToAxis();
  auto response = [&](double t1, double t2, int i) {
    const TriadSample &s1 = sampleAt(c, samples, t1), &s2 = sampleAt(c, samples, t2);
    const double inertial_table = s2.axes[i].truth.table_angle - s1.axes[i].truth.table_angle +
                                  kEarthRotationRate * (timeOf(c, s2) - timeOf(c, s1));
    const double exact = a.row(i).dot(s1.body.body_to_table.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ());
    EXPECT_NEAR((s2.axes[i].truth.inertial_angle - s1.axes[i].truth.inertial_angle) / inertial_table, exact, 1e-12);
    return exact;
  };
  const double up_x = response(6.0, 11.0, 0),
               down_x = response(c.positions[1].start + 1.0, c.positions[1].start + 6.0, 0);
  const double up_y = response(6.0, 11.0, 1),
               down_y = response(c.positions[1].start + 1.0, c.positions[1].start + 6.0, 1);
  // To first order (the second order is below 1e-7 here): the error shifts the cross-axis responses
  // of its own position by (-ry, +rx); the wobble, a tilt fixed in the platter, by -a (cos d, sin d)
  // in the platter's x and y. Flipping to -z (a half turn about the platter's x) reverses the body's y
  // but not its x: the half-difference of up and down keeps A_xz off by half the error and free of
  // the wobble, but A_yz off by half the error and by the wobble's y part in full.
  const double wobble = 1.0e-4, d = 0.4, rx = 1.2e-4, ry = 2.0e-4;
  EXPECT_NEAR(up_x, a(0, 2) - ry - wobble * std::cos(d), 1e-7);
  EXPECT_NEAR(down_x, -a(0, 2) - wobble * std::cos(d), 1e-7);
  EXPECT_NEAR(up_y, a(1, 2) + rx - wobble * std::sin(d), 1e-7);
  EXPECT_NEAR(down_y, -a(1, 2) + wobble * std::sin(d), 1e-7);
  EXPECT_NEAR(0.5 * (up_x - down_x), a(0, 2) - 0.5 * ry, 1e-7);
  EXPECT_NEAR(0.5 * (up_y - down_y), a(1, 2) + 0.5 * rx - wobble * std::sin(d), 1e-7);
}

TEST(TriadSimulatorTest, SameSeedSameSessionAndEachAxisItsOwnNoise) {
  const std::string noisy = ", pickoff: {noise: 2.0e-4}";
  const TriadSimulationConfig c =
      parseText(scenario("{latitude: 0.9, log: {rate: 100, angle_noise: 2.0e-6}}", "", noisy));
  TriadSimulator sim_first(c), sim_again(c);
  const std::vector<TriadSample> first = runAll(sim_first), again = runAll(sim_again);
  ASSERT_EQ(first.size(), again.size());
  std::size_t records = 0;
  for (std::size_t n = 0; n < first.size(); ++n) {
    for (int i = 0; i < 3; ++i) ASSERT_EQ(first[n].axes[i].z, again[n].axes[i].z);
    records += first[n].turntable.size();
    ASSERT_EQ(first[n].turntable.size(), again[n].turntable.size());
    for (std::size_t k = 0; k < first[n].turntable.size(); ++k) {
      EXPECT_EQ(first[n].turntable[k].angle, again[n].turntable[k].angle);
    }
  }
  // The table at its own rate: a record every 10 ms from the start, up to the last sample's centre.
  EXPECT_EQ(records, static_cast<std::size_t>(std::floor(timeOf(c, first.back()) * 100.0)) + 1);
  // The axes' noise is their own: the channel noise of the three axes is uncorrelated.
  const TriadSimulationConfig quiet = parseText(scenario("{latitude: 0.9, log: {rate: 100, angle_noise: 2.0e-6}}"));
  TriadSimulator sim_clean(quiet);
  const std::vector<TriadSample> clean = runAll(sim_clean);
  double sum_xy = 0.0, sum_xx = 0.0, sum_yy = 0.0;
  for (std::size_t n = 0; n < first.size(); ++n) {
    const double nx = first[n].axes[0].z[0] - clean[n].axes[0].z[0], ny = first[n].axes[1].z[0] - clean[n].axes[1].z[0];
    sum_xy += nx * ny;
    sum_xx += nx * nx;
    sum_yy += ny * ny;
  }
  // 27 000 samples: an uncorrelated pair's coefficient is below 5 / sqrt(n) = 0.03.
  EXPECT_LT(std::abs(sum_xy / std::sqrt(sum_xx * sum_yy)), 0.03);
  EXPECT_GT(sum_xx, 0.0);
  // The noise changes no truth and no table record.
  EXPECT_EQ(first.back().axes[2].truth.inertial_angle, clean.back().axes[2].truth.inertial_angle);
}

TEST(TriadSimulatorTest, TrueAttitudeAndAnExactAccelerometerFollowTheTableAndThePositions) {
  const double az = 0.3;
  const TriadSimulationConfig c =
      parseText(scenario("{latitude: 0.9, azimuth: 0.3}\n  accelerometer: {bias: [0, 0, 0], noise: 0}"));
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  const double g = 9.80665;
  const Eigen::Matrix3d tilted = rotationFromRollPitchYaw(0.7854, 0.6155, 0.2);
  for (const TriadSample& s : samples) {
    ASSERT_TRUE(s.accelerometer.present);
    const Eigen::Vector3d f = s.accelerometer.specific_force;
    EXPECT_NEAR(f.norm(), g, 1e-12);
    const Eigen::Matrix3d c_true = s.body.body_to_enu.toRotationMatrix();
    // The true up, (0, 0, 1) in ENU, seen in the body: what the accelerometer points along.
    EXPECT_LT((f / g - c_true.transpose() * Eigen::Vector3d::UnitZ()).norm(), 1e-12);
    const double phi = s.axes[0].truth.table_angle;
    if (s.body.position == 0) {
      // +z up on the platter: body z up, body x at the platter's x, az - phi from North towards East.
      EXPECT_LT((f - Eigen::Vector3d(0, 0, g)).norm(), 1e-12);
      EXPECT_LT((c_true.col(0) - Eigen::Vector3d(std::sin(az - phi), std::cos(az - phi), 0)).norm(), 1e-12);
    } else if (s.fixture.locked && s.body.position == 1) {
      // -x up: body x down, body y along the platter's x.
      EXPECT_LT((f - Eigen::Vector3d(-g, 0, 0)).norm(), 1e-12);
      EXPECT_LT((c_true.col(1) - Eigen::Vector3d(std::sin(az - phi), std::cos(az - phi), 0)).norm(), 1e-12);
    } else if (s.fixture.locked && s.body.position == 2) {
      EXPECT_LT((f - tilted.transpose() * Eigen::Vector3d(0, 0, g)).norm(), 1e-12);
    }
  }
  // The heading a navigator reads in the first position at table angle 0: the azimuth.
  const Eigen::Matrix3d first = samples.front().body.body_to_enu.toRotationMatrix();
  EXPECT_NEAR(std::atan2(first(0, 0), first(1, 0)), az, 1e-12);
}

TEST(TriadSimulatorTest, AccelerometerAddsItsBiasAndNoiseInItsMountedFrameFromItsOwnStream) {
  const std::string table =
      "{latitude: 0.9, azimuth: 0.3}\n  accelerometer: {frame_id: acc, bias: [1.0e-3, -2.0e-3, 3.0e-3], noise: "
      "2.0e-3, mounting: {roll: 0.1, pitch: -0.2, yaw: 0.3}}";
  const TriadSimulationConfig c = parseText(scenario(table, "", ", pickoff: {noise: 2.0e-4}"));
  const Eigen::Matrix3d mounting = rotationFromRollPitchYaw(0.1, -0.2, 0.3);
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
  for (const TriadSample& s : samples) {
    const Eigen::Vector3d exact =
        mounting.transpose() * s.body.body_to_enu.toRotationMatrix().transpose() * Eigen::Vector3d(0.0, 0.0, 9.80665);
    const Eigen::Vector3d e = s.accelerometer.specific_force - exact;
    sum += e;
    sum2 += e.cwiseProduct(e);
  }
  const double n = static_cast<double>(samples.size());
  const Eigen::Vector3d mean = sum / n;
  for (int j = 0; j < 3; ++j) {
    EXPECT_NEAR(mean[j], c.accelerometer.bias[j], 5.0 * 2.0e-3 / std::sqrt(n)) << j;
    const double sd = std::sqrt(sum2[j] / n - mean[j] * mean[j]);
    EXPECT_NEAR(sd / 2.0e-3, 1.0, 0.03) << j;  // 5400 samples: the sd within 1 %, 1 sigma
  }
  // Its noise is its own stream: the gyros' channels are those of the scenario without it.
  const TriadSimulationConfig without =
      parseText(scenario("{latitude: 0.9, azimuth: 0.3}", "", ", pickoff: {noise: 2.0e-4}"));
  TriadSimulator sim_without(without);
  const std::vector<TriadSample> plain = runAll(sim_without);
  ASSERT_EQ(plain.size(), samples.size());
  for (std::size_t k = 0; k < plain.size(); ++k) {
    EXPECT_FALSE(plain[k].accelerometer.present);
    for (int i = 0; i < 3; ++i) ASSERT_EQ(plain[k].axes[i].z, samples[k].axes[i].z);
  }
}

/// Everything a triad sample carries, into the fingerprint: any changed bit changes it.
void fingerprint(testing::BitFingerprint* f, const TriadSample& s) {
  f->add(s.index), f->add(s.stamp);
  for (const SimulationSample& a : s.axes) {
    f->add(a.index), f->add(a.stamp), f->add(a.channels_delivered);
    for (int j = 0; j < 4; ++j) f->add(a.z[j]);
    f->add(a.truth.theta), f->add(a.truth.table_angle), f->add(a.truth.table_rate), f->add(a.truth.inertial_angle);
    f->add(a.truth.inertial_rate);
  }
  for (const TurntableLogRecord& r : s.turntable) {
    f->add(r.index), f->add(r.time), f->add(r.stamp), f->add(r.angle), f->add(r.rate);
  }
  f->add(s.fixture.index), f->add(s.fixture.locked), f->add(s.fixture_logged), f->add(s.fixture.body_to_table);
  f->add(s.body.angular_velocity), f->add(s.body.body_to_table), f->add(s.body.body_to_enu);
  f->add(s.body.position), f->add(s.accelerometer.present), f->add(s.accelerometer.specific_force);
}

// A scenario that gives none of the base's or the accelerometer's newer keys is what it was before
// them, bit for bit: the hashes were recorded on the simulator before triad.base_motion existed.
// The test scenario with every older feature (fixture error, wobble, table log, pickoff noise, an
// accelerometer with bias, noise and mounting), and the first 10 s of north_static.yaml.
TEST(TriadSimulatorTest, AScenarioWithoutTheNewKeysKeepsItsFingerprint) {
  const std::string accelerometer =
      "{latitude: 0.9, azimuth: 0.3, wobble: {amplitude: 1.0e-4, direction: 0.4}, log: {rate: 100, angle_noise: "
      "2.0e-6}}\n  accelerometer: {bias: [1.0e-3, -2.0e-3, 3.0e-3], noise: 2.0e-3, mounting: {roll: 0.1, pitch: "
      "-0.2, yaw: 0.3}}";
  const TriadSimulationConfig c =
      parseText(scenario(accelerometer, ", error: [1.2e-4, 2.0e-4, -0.5e-4]", ", pickoff: {noise: 2.0e-4}"));
  TriadSimulator sim(c);
  testing::BitFingerprint f;
  TriadSample s;
  while (sim.next(&s)) fingerprint(&f, s);
  const TriadSimulationConfig shipped = TriadSimulationConfig::load(testing::shippedScenarioPath("north_static.yaml"));
  TriadSimulator sim_shipped(shipped);
  testing::BitFingerprint g;
  for (int n = 0; n < 2000 && sim_shipped.next(&s); ++n) fingerprint(&g, s);
  std::printf("[ measured ] fingerprints 0x%016llx 0x%016llx\n", static_cast<unsigned long long>(f.value()),
              static_cast<unsigned long long>(g.value()));
  EXPECT_EQ(f.value(), 0xfcf41c37d63cc5d2ULL);
  EXPECT_EQ(g.value(), 0x43101a7023afb2c7ULL);
}

// ---- A base that moves (triad.base_motion) and the accelerometer's own errors ----

/// One tilted position at rest for `duration` s, the base and the accelerometer given by `extra`.
std::string restScenario(const std::string& extra, double duration) {
  return "seed: 5\n"
         "triad:\n"
         "  axes:\n" +
         axis(0, "x", "[2.0e-4, -1.5e-4]") + axis(1, "y", "[3.0e-4, 1.0e-4]") + axis(2, "z", "[-2.5e-4, 0.5e-4]") +
         "  turntable: {latitude: 0.9, azimuth: 0.3}\n"
         "  positions:\n"
         "    - {name: rest, body_to_table: {roll: 0.3, pitch: -0.2, yaw: 0.4}, profile: [{type: dwell, duration: " +
         formatDouble(duration) + "}]}\n" + extra;
}

/// The centre of a sample's window as the simulator computes it (the stamp is rounded to the ns).
double centreOf(const TriadSimulationConfig& c, const TriadSample& s) { return (s.index + 0.5) * c.outputPeriod(); }

/// The rest position's attitude on a still base, written out: Rz(pi/2 - azimuth) R.
Eigen::Matrix3d restAttitude() {
  return Eigen::AngleAxisd(kPi / 2 - 0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix() *
         rotationFromRollPitchYaw(0.3, -0.2, 0.4);
}

Eigen::Vector3d earthInEnu() {
  return Eigen::Vector3d(0.0, kEarthRotationRate * std::cos(0.9), kEarthRotationRate * std::sin(0.9));
}

/// The integral over [t1, t2] of D^T Omega_enu, D = Exp(theta(t) n) about a fixed axis n, to second
/// order in theta: Omega dt - (n x Omega) int theta + (n x (n x Omega)) int theta^2 / 2.
Eigen::Vector3d earthThroughBase(const Eigen::Vector3d& n, double dt, double theta, double theta2_half) {
  const Eigen::Vector3d earth = earthInEnu();
  return earth * dt - n.cross(earth) * theta + n.cross(n.cross(earth)) * theta2_half;
}

// A lean of 25 urad: each axis integrates A_i C_nominal^T (r + int D^T Omega), the lean's rotation in
// full (about a fixed axis, D^T w = w) and the Earth's rate seen through the leaning base; the truth's
// attitude is D(t) C_nominal before, during and after it.
TEST(TriadSimulatorTest, ALeanOfTheBaseIsSensedAsItsRotationAndCarriedByTheTruth) {
  const Eigen::Vector3d r(2.0e-5, -1.5e-5, 0.0);
  const TriadSimulationConfig c = parseText(
      restScenario("  base_motion: {leans: [{time: 2.0, duration: 2.0, rotation: [2.0e-5, -1.5e-5, 0.0]}]}\n", 6.0));
  TriadSimulator sim(c);
  const std::vector<TriadSample> samples = runAll(sim);
  const Eigen::Matrix3d a = c.bodyToAxis(), nominal = restAttitude();
  const TriadSample &s1 = sampleAt(c, samples, 1.0), &s2 = sampleAt(c, samples, 5.0);
  const double t1 = centreOf(c, s1), t2 = centreOf(c, s2), size = r.norm();
  // The raised cosine s(u) over the lean: int s = T / 2, int s^2 = 3 T / 8; whole after it.
  const double theta = size * (1.0 + (t2 - 4.0)), theta2_half = 0.5 * size * size * (0.75 + (t2 - 4.0));
  const Eigen::Vector3d integral = nominal.transpose() * (r + earthThroughBase(r / size, t2 - t1, theta, theta2_half));
  double worst = 0.0;
  Eigen::Vector3d beyond_earth;
  for (int i = 0; i < 3; ++i) {
    const double sensed = s2.axes[i].truth.inertial_angle - s1.axes[i].truth.inertial_angle;
    EXPECT_NEAR(sensed, a.row(i).dot(integral), 1e-12) << i;
    worst = std::max(worst, std::abs(sensed - a.row(i).dot(integral)));
    beyond_earth[i] = sensed - a.row(i).dot(nominal.transpose() * earthInEnu()) * (t2 - t1);
  }
  // What a still base would not give (its Earth's share alone): the lean's rotation through A, but
  // for the Earth's rate the lean turns (r x Omega, 3.6e-9 rad over the lean and the second after).
  EXPECT_NEAR(beyond_earth.norm(), (a * nominal.transpose() * r).norm(), 1e-8);
  std::printf("[ measured ] a lean of 25 urad: sensed angles within %.2e rad of the closed form\n", worst);
  // The truth: C_nominal before, Exp(s(u) r) C_nominal in the lean, Exp(r) C_nominal after.
  EXPECT_LT(s1.body.body_to_enu.angularDistance(Eigen::Quaterniond(nominal)), 2e-15);
  const TriadSample& mid = sampleAt(c, samples, 3.3);
  const double u = (centreOf(c, mid) - 2.0) / 2.0;
  const Eigen::Quaterniond leaning(rotationFromVector((0.5 - 0.5 * std::cos(kPi * u)) * r) * nominal);
  EXPECT_LT(mid.body.body_to_enu.angularDistance(leaning), 2e-15);
  EXPECT_LT(samples.back().body.body_to_enu.angularDistance(Eigen::Quaterniond(rotationFromVector(r) * nominal)),
            2e-15);
  EXPECT_EQ(samples.back().body.body_to_table.coeffs(), s1.body.body_to_table.coeffs()) << "relative to the base";
}

// A sway: the body integrates its angle's change about its axis and the Earth's rate through it. A
// knock: its step, and a ringing whose rate steps by ring x size x 2 pi ring_frequency at its time,
// which a resonator period's RK4 stages (and Simpson's rule on them) resolve only to that step times
// T / 6 (7.5e-8 rad here); its closed form otherwise, and the truth after it D = Exp(rotation).
TEST(TriadSimulatorTest, ASwayAndAKnockOfTheBaseAreSensedAsTheirRotations) {
  const Eigen::Matrix3d nominal = restAttitude();
  {
    const double amplitude = 3.0e-5, period = 0.9, phase = 0.4;
    const Eigen::Vector3d n = Eigen::Vector3d(1.0, -2.0, 0.5).normalized();
    const TriadSimulationConfig c = parseText(
        restScenario("  base_motion: {sways: [{amplitude: 3.0e-5, period: 0.9, phase: 0.4, axis: [" +
                         formatDouble(n.x()) + ", " + formatDouble(n.y()) + ", " + formatDouble(n.z()) + "]}]}\n",
                     5.0));
    TriadSimulator sim(c);
    const std::vector<TriadSample> samples = runAll(sim);
    const TriadSample &s1 = sampleAt(c, samples, 0.5), &s2 = sampleAt(c, samples, 4.7);
    const double t1 = centreOf(c, s1), t2 = centreOf(c, s2), w = kTwoPi / period;
    const double p1 = w * t1 + phase, p2 = w * t2 + phase;
    const double theta = amplitude / w * (std::cos(p1) - std::cos(p2));
    const double theta2_half =
        0.25 * amplitude * amplitude * ((t2 - t1) - (std::sin(2.0 * p2) - std::sin(2.0 * p1)) / (2.0 * w));
    const Eigen::Vector3d integral = nominal.transpose() * (n * amplitude * (std::sin(p2) - std::sin(p1)) +
                                                            earthThroughBase(n, t2 - t1, theta, theta2_half));
    double worst = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double sensed = s2.axes[i].truth.inertial_angle - s1.axes[i].truth.inertial_angle;
      EXPECT_NEAR(sensed, c.bodyToAxis().row(i).dot(integral), 1e-12) << i;
      worst = std::max(worst, std::abs(sensed - c.bodyToAxis().row(i).dot(integral)));
    }
    std::printf("[ measured ] a sway of 30 urad: sensed angles within %.2e rad of the closed form\n", worst);
    const Eigen::Quaterniond swayed(rotationFromVector(amplitude * std::sin(p2) * n) * nominal);
    EXPECT_LT(s2.body.body_to_enu.angularDistance(swayed), 2e-15);
  }
  {
    const Eigen::Vector3d k(1.0e-5, 0.0, 2.0e-5);
    const double ring = 2.0, f = 8.0, decay = 0.15, size = k.norm(), w = kTwoPi * f;
    const TriadSimulationConfig c =
        parseText(restScenario("  base_motion: {knocks: [{time: 2.0, rotation: [1.0e-5, 0.0, 2.0e-5]}]}\n", 7.0));
    ASSERT_EQ(c.base_motion.knocks[0].ring, ring);
    ASSERT_EQ(c.base_motion.knocks[0].ring_frequency, f);
    ASSERT_EQ(c.base_motion.knocks[0].ring_decay, decay);
    TriadSimulator sim(c);
    const std::vector<TriadSample> samples = runAll(sim);
    // From before the knock to 30 decay times after it (the ringing e^-30 of its size: gone).
    const TriadSample &s1 = sampleAt(c, samples, 1.0), &s2 = sampleAt(c, samples, 6.5);
    const double t1 = centreOf(c, s1), t2 = centreOf(c, s2);
    // int theta: the step's raised cosine over 0.05 s (half of it), then whole; the ringing's integral
    // a w / (w^2 + 1 / decay^2). The second order: the step's alone (the ringing's is 1e-15 rad).
    const double theta = size * (0.025 + (t2 - 2.05)) + ring * size * w / (w * w + 1.0 / (decay * decay));
    const double theta2_half = 0.5 * size * size * (0.05 * 0.375 + (t2 - 2.05));
    const Eigen::Vector3d integral =
        nominal.transpose() * (k + earthThroughBase(k / size, t2 - t1, theta, theta2_half));
    const double resolved = ring * size * w * (1.0 / c.axes[0].resonator.frequency) / 6.0;
    double worst = 0.0;
    for (int i = 0; i < 3; ++i) {
      const double sensed = s2.axes[i].truth.inertial_angle - s1.axes[i].truth.inertial_angle;
      EXPECT_NEAR(sensed, c.bodyToAxis().row(i).dot(integral), resolved + 1e-12) << i;
      worst = std::max(worst, std::abs(sensed - c.bodyToAxis().row(i).dot(integral)));
    }
    std::printf("[ measured ] a knock of 22 urad: sensed angles within %.2e rad of the closed form (bound %.2e)\n",
                worst, resolved);
    EXPECT_LT(s2.body.body_to_enu.angularDistance(Eigen::Quaterniond(rotationFromVector(k) * nominal)), 2e-15);
    EXPECT_GT(sampleAt(c, samples, 2.06).body.angular_velocity.norm(), 1e-4) << "it rings";
  }
}

/// Every sample of a rest scenario with the given accelerometer section (and base). Their names and
/// labels point into the simulator, gone on return: the tests here read neither.
std::vector<TriadSample> accelerometerRun(const std::string& accelerometer, const std::string& base = "") {
  TriadSimulator sim(parseText(restScenario("  accelerometer: " + accelerometer + "\n" + base, 1.0)));
  return runAll(sim);
}

// Each fault of the accelerometer does what its key says, in the documented order, on what a perfect
// one reads, f0 = (C R)^T (0, 0, g), C the truth's attitude (the base leaning in it).
TEST(TriadSimulatorTest, TheAccelerometerReadsWhatEachConventionAndFaultSays) {
  const double g = 9.80665;
  const std::string mounting = "mounting: {roll: 0.1, pitch: -0.2, yaw: 0.3}";
  const std::string lean = "  base_motion: {leans: [{time: 0.2, duration: 0.5, rotation: [0.0, 3.0e-3, 0.0]}]}\n";
  const Eigen::Matrix3d r = rotationFromRollPitchYaw(0.1, -0.2, 0.3);
  const Eigen::Vector3d s(2.0e-3, -1.0e-3, 5.0e-4), rho(1.0e-3, -2.0e-3, 3.0e-3), b(1.0e-3, -2.0e-3, 3.0e-3);
  const Eigen::Matrix3d misaligned = rotationFromVector(rho).transpose();
  auto run = [&](const std::string& faults) { return accelerometerRun("{" + faults + mounting + "}", lean); };
  const std::vector<TriadSample> perfect = run(""), gravity = run("convention: gravity, "),
                                 flipped = run("axis_signs: [-1, 1, 1], "),
                                 scaled = run("scale: [2.0e-3, -1.0e-3, 5.0e-4], "),
                                 turned = run("misalignment: [1.0e-3, -2.0e-3, 3.0e-3], "),
                                 quantised = run("quantum: 0.01, bias: [1.0e-3, -2.0e-3, 3.0e-3], ");
  const std::vector<TriadSample> all =
      run("misalignment: [1.0e-3, -2.0e-3, 3.0e-3], scale: [2.0e-3, -1.0e-3, 5.0e-4], axis_signs: [-1, 1, 1], "
          "convention: gravity, bias: [1.0e-3, -2.0e-3, 3.0e-3], ");
  ASSERT_EQ(perfect.size(), all.size());
  double leaned = 0.0;
  for (std::size_t n = 0; n < perfect.size(); ++n) {
    SCOPED_TRACE(n);
    const Eigen::Matrix3d c = perfect[n].body.body_to_enu.toRotationMatrix();
    const Eigen::Vector3d f0 = (c * r).transpose() * Eigen::Vector3d(0.0, 0.0, g);
    EXPECT_LT((perfect[n].accelerometer.specific_force - f0).norm(), 1e-12);
    leaned = std::max(leaned, (f0 - (restAttitude() * r).transpose() * Eigen::Vector3d(0.0, 0.0, g)).norm());
    // gravity: -g up; axis_signs -1: x reversed alone; scale and misalignment as defined.
    const Eigen::Vector3d up = (c * r).transpose() * Eigen::Vector3d::UnitZ();
    EXPECT_NEAR(gravity[n].accelerometer.specific_force.dot(up), -g, 1e-12);
    EXPECT_LT((gravity[n].accelerometer.specific_force + f0).norm(), 1e-12);
    EXPECT_LT((flipped[n].accelerometer.specific_force - Eigen::Vector3d(-f0.x(), f0.y(), f0.z())).norm(), 1e-12);
    EXPECT_LT((scaled[n].accelerometer.specific_force - (Eigen::Vector3d::Ones() + s).cwiseProduct(f0)).norm(), 1e-12);
    EXPECT_LT((turned[n].accelerometer.specific_force - misaligned * f0).norm(), 1e-12);
    // Quantised last, after the bias: multiples of 0.01 within half of it of f0 + b.
    for (int j = 0; j < 3; ++j) {
      const double q = quantised[n].accelerometer.specific_force[j];
      EXPECT_NEAR(q / 0.01, std::round(q / 0.01), 1e-9) << j;
      EXPECT_LE(std::abs(q - (f0[j] + b[j])), 0.005 + 1e-12) << j;
    }
    // All of them: misalignment, scale, signs, convention, then the bias.
    const Eigen::Vector3d signs(-1.0, 1.0, 1.0);
    const Eigen::Vector3d expected =
        -signs.cwiseProduct((Eigen::Vector3d::Ones() + s).cwiseProduct(misaligned * f0)) + b;
    EXPECT_LT((all[n].accelerometer.specific_force - expected).norm(), 1e-12);
  }
  // The lean of 3 mrad reaches it through the truth's attitude: 2 g sin(1.5e-3) = 0.029 m/s^2.
  EXPECT_NEAR(leaned, g * 2.0 * std::sin(1.5e-3), 1e-6);
}

// The base's vibration is a linear acceleration: the accelerometer reads its mean over each sample,
// through the attitude, and the gyros read nothing of it (every channel and truth bit for bit those
// of the still base).
TEST(TriadSimulatorTest, TheVibrationReachesTheAccelerometerAndNotTheGyros) {
  const std::string accelerometer = "  accelerometer: {mounting: {roll: 0.1, pitch: -0.2, yaw: 0.3}}\n";
  const TriadSimulationConfig c =
      parseText(restScenario(accelerometer + "  base_motion: {vibration: {rms: 0.05, low: 10.0, high: 40.0}}\n", 3.0));
  const TriadSimulationConfig still = parseText(restScenario(accelerometer, 3.0));
  TriadSimulator sim(c), sim_still(still);
  const std::vector<TriadSample> shaken = runAll(sim), calm = runAll(sim_still);
  ASSERT_EQ(shaken.size(), calm.size());
  const BaseMotion base(c.base_motion, c.seed);
  const Eigen::Matrix3d r = rotationFromRollPitchYaw(0.1, -0.2, 0.3);
  double squares = 0.0, largest = 0.0;
  for (std::size_t n = 0; n < shaken.size(); ++n) {
    for (int i = 0; i < 3; ++i) {
      ASSERT_EQ(shaken[n].axes[i].z, calm[n].axes[i].z) << n;
      ASSERT_EQ(shaken[n].axes[i].truth.theta, calm[n].axes[i].truth.theta) << n;
      ASSERT_EQ(shaken[n].axes[i].truth.inertial_angle, calm[n].axes[i].truth.inertial_angle) << n;
    }
    ASSERT_EQ(shaken[n].body.angular_velocity, calm[n].body.angular_velocity) << n;
    ASSERT_EQ(shaken[n].body.body_to_enu.coeffs(), calm[n].body.body_to_enu.coeffs()) << n;
    const Eigen::Vector3d mean = base.meanAccelerationOver(n * c.outputPeriod(), (n + 1) * c.outputPeriod());
    const Eigen::Matrix3d attitude = calm[n].body.body_to_enu.toRotationMatrix() * r;
    const Eigen::Vector3d read = shaken[n].accelerometer.specific_force - calm[n].accelerometer.specific_force;
    EXPECT_LT((read - attitude.transpose() * mean).norm(), 1e-12) << n;
    squares += read.squaredNorm();
    largest = std::max(largest, read.cwiseAbs().maxCoeff());
  }
  const double rms = std::sqrt(squares / shaken.size() / 3.0);
  std::printf("[ measured ] vibration read by the accelerometer: %.4f m/s^2 rms per axis, largest %.4f\n", rms,
              largest);
  EXPECT_NEAR(rms, 0.05, 0.015);  // 20 sinusoids over 3 s
  EXPECT_GT(largest, 0.05);
}

// An axis may run the averaged resonator: it senses the same A_x . omega_body as the harmonic axis
// (its truth bit for bit the same), its wave turns at K0 r + D(theta) plus the commanded rate of its
// schedule, and the other axes are those of the scenario without it, bit for bit.
TEST(TriadSimulatorTest, AnAveragedAxisSensesItsRowOfAAndTurnsOnItsSchedule) {
  const std::string harmonic_x = axis(0, "x", "[2.0e-4, -1.5e-4]");
  const std::string averaged_x =
      "    - {name: x, misalignment: [2.0e-4, -1.5e-4], resonator: {initial_theta: 0.2, drift: {orders: [2], mean: "
      "1.0e-5, cos: [0.0], sin: [2.0e-5]}}, dynamics: {model: averaged, commands: [{time: 1.0, rate: 0.3}, {time: "
      "7.0, rate: -0.3}]}}\n";
  std::string text = scenario();
  const TriadSimulationConfig harmonic = parseText(text);
  text.replace(text.find(harmonic_x), harmonic_x.size(), averaged_x);
  const TriadSimulationConfig c = parseText(text);
  ASSERT_TRUE(c.axes[0].dynamics.averaged());
  TriadSimulator sim_h(harmonic), sim_a(c);
  const std::vector<TriadSample> h = runAll(sim_h), a = runAll(sim_a);
  ASSERT_EQ(h.size(), a.size());
  for (std::size_t n = 0; n < a.size(); ++n) {
    ASSERT_EQ(a[n].stamp, h[n].stamp);
    EXPECT_EQ(a[n].axes[0].truth.inertial_rate, h[n].axes[0].truth.inertial_rate) << n;
    EXPECT_EQ(a[n].axes[0].truth.inertial_angle, h[n].axes[0].truth.inertial_angle) << n;
    for (int i = 1; i < 3; ++i) {
      ASSERT_EQ(a[n].axes[i].z, h[n].axes[i].z) << n;
      EXPECT_EQ(a[n].axes[i].precession.commands, 0u);
    }
  }
  // At rest in position a, precessed at +0.3 rad/s: theta by RK4 of -0.56 r + D(theta) + 0.3 here.
  const TriadSample &s1 = sampleAt(c, a, 1.5), &s2 = sampleAt(c, a, 4.5);
  const double r = s1.axes[0].truth.inertial_rate;
  EXPECT_EQ(s1.axes[0].precession.rate, 0.3);
  EXPECT_EQ(s1.axes[0].precession.commands, 1u);
  double theta = s1.axes[0].truth.theta;
  const int steps = 20000;
  const double dt = (timeOf(c, s2) - timeOf(c, s1)) / steps;
  auto f = [&](double th) { return -0.56 * r + 1.0e-5 + 2.0e-5 * std::sin(2 * th) + 0.3; };
  for (int k = 0; k < steps; ++k) {
    const double k1 = f(theta), k2 = f(theta + dt / 2 * k1), k3 = f(theta + dt / 2 * k2), k4 = f(theta + dt * k3);
    theta += dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  std::printf("[ measured ] averaged axis at rest, precessed: theta %.12f, predicted %.12f\n", s2.axes[0].truth.theta,
              theta);
  EXPECT_NEAR(s2.axes[0].truth.theta, theta, 1e-7);
  const TriadSample& s3 = sampleAt(c, a, 8.0);
  EXPECT_EQ(s3.axes[0].precession.rate, -0.3);
  EXPECT_EQ(s3.axes[0].precession.commands, 2u);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
