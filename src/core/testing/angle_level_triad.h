// Test support: a fast angle-level triad (no pickoffs, no demodulation) in a fixture on a single-axis
// rate table, written apart from the signal-level simulator so that the two cannot share a mistake.
// Each axis's wave angle obeys d theta_i = K_i(theta_i) (A_i . omega_body) dt + D_i(theta_i) dt with
// omega_body = R^T (Omega_table e_z + omega_earth_platter(table angle)), R the fixture's true
// body-to-table rotation (the plan's times a small error), integrated by RK4 at `rate_hz`; between
// positions the body turns smoothly to the next orientation in `move` s with the table at rest, the
// fixture logged unlocked. Sinks get every table record, every fixture record (on change and every
// second) and every axis's measured wave angle (white noise added), in time order.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/triad_calibration.h"
#include "hrg_gyro/core/model/model_pair_evaluator.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"
#include "hrg_gyro/core/simulation/turntable_profile.h"

namespace hrg_gyro {
namespace core {
namespace testing {

struct TriadPosition {
  std::string name;
  Eigen::Matrix3d body_to_table = Eigen::Matrix3d::Identity();  ///< the plan's
  Eigen::Vector3d error = Eigen::Vector3d::Zero();              ///< rad, small rotation about body axes
  TurntableProfile profile;
  double move = 10.0;  ///< s to turn the body into this position (the first: none)

  Eigen::Matrix3d trueBodyToTable() const {
    const double angle = error.norm();
    if (angle == 0.0) return body_to_table;
    return body_to_table * Eigen::AngleAxisd(angle, error / angle).toRotationMatrix();
  }
};

struct AngleLevelTriad {
  std::array<HarmonicModel, 3> k{{HarmonicModel(-0.56), HarmonicModel(-0.56), HarmonicModel(-0.56)}};
  std::array<HarmonicModel, 3> d{{HarmonicModel(0.0), HarmonicModel(0.0), HarmonicModel(0.0)}};
  Eigen::Matrix3d body_to_axis = Eigen::Matrix3d::Identity();  ///< A: rows the axes' directions
  double latitude = 0.9, azimuth = 0.3;                        ///< rad
  double noise = 0.0;                                          ///< white wave-angle noise per sample, rad
  double rate_hz = 1000.0;
  std::uint64_t seed = 5;
};

/// The axis-up/down rotation of the plan: body axis `axis` (0..2) along +z (sign +1) or -z of the table.
inline Eigen::Matrix3d axisAlongTable(int axis, int sign) {
  // Rotations taking body e_axis to sign * table z.
  if (axis == 2)
    return sign > 0 ? Eigen::Matrix3d::Identity() : Eigen::AngleAxisd(kPi, Eigen::Vector3d::UnitX()).toRotationMatrix();
  if (axis == 0) return Eigen::AngleAxisd(-sign * kPi / 2, Eigen::Vector3d::UnitY()).toRotationMatrix();
  return Eigen::AngleAxisd(sign * kPi / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
}

inline Eigen::Vector3d earthInPlatterFrame(double latitude, double azimuth, double table_angle) {
  const double heading = azimuth - table_angle;
  const double horizontal = kEarthRotationRate * std::cos(latitude);
  return Eigen::Vector3d(horizontal * std::cos(heading), horizontal * std::sin(heading),
                         kEarthRotationRate * std::sin(latitude));
}

struct TriadSinks {
  std::function<void(Nanoseconds, double, double, std::uint32_t)> table;  ///< stamp, angle, rate, seq
  std::function<void(const FixtureRecord&)> fixture;
  std::function<void(int, Nanoseconds, double)> wave;  ///< axis, stamp, measured theta
};

inline void runAngleLevelTriad(const AngleLevelTriad& g, const std::vector<TriadPosition>& positions,
                               const TriadSinks& sinks) {
  std::array<ModelPairEvaluator, 3> models{
      {ModelPairEvaluator(g.k[0], g.d[0]), ModelPairEvaluator(g.k[1], g.d[1]), ModelPairEvaluator(g.k[2], g.d[2])}};
  GaussianNoise noise(g.seed);
  const double h = 1.0 / g.rate_hz;
  std::array<double, 3> theta{{0.2, 1.1, 2.3}};
  double table_angle = 0.0, t = 0.0;
  std::uint32_t seq = 0;
  Nanoseconds last_fixture = 0;
  auto stampOf = [](double time) { return toNanoseconds(1.0 + time); };
  // One RK4 step of the three axes under body rate omega(time) (rad/s, body frame).
  auto step = [&](const std::function<Eigen::Vector3d(double)>& omega) {
    auto rates = [&](double time, const std::array<double, 3>& th) {
      const Eigen::Vector3d w = g.body_to_axis * omega(time);
      std::array<double, 3> r{};
      for (int i = 0; i < 3; ++i) {
        double k, d;
        models[i].evaluate(th[i], NAN, &k, &d);
        r[i] = k * w(i) + d;
      }
      return r;
    };
    auto add = [](const std::array<double, 3>& a, const std::array<double, 3>& b, double f) {
      return std::array<double, 3>{{a[0] + f * b[0], a[1] + f * b[1], a[2] + f * b[2]}};
    };
    const auto k1 = rates(t, theta), k2 = rates(t + h / 2, add(theta, k1, h / 2)),
               k3 = rates(t + h / 2, add(theta, k2, h / 2)), k4 = rates(t + h, add(theta, k3, h));
    for (int i = 0; i < 3; ++i) theta[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  };
  auto emit = [&](const FixtureRecord& fixture, double rate) {
    const Nanoseconds stamp = stampOf(t);
    if (last_fixture == 0 || toSeconds(stamp - last_fixture) >= 1.0) {
      FixtureRecord f = fixture;
      f.stamp = stamp;
      sinks.fixture(f);
      last_fixture = stamp;
    }
    sinks.table(stamp, table_angle, rate, seq++);
    for (int i = 0; i < 3; ++i) sinks.wave(i, stamp, theta[i] + g.noise * noise.next());
  };
  Eigen::Matrix3d previous = positions.front().trueBodyToTable();
  for (std::size_t p = 0; p < positions.size(); ++p) {
    const TriadPosition& pos = positions[p];
    const Eigen::Matrix3d r_true = pos.trueBodyToTable();
    FixtureRecord fixture;
    fixture.index = static_cast<std::uint32_t>(p);
    fixture.name = pos.name;
    fixture.body_to_table = Eigen::Quaterniond(pos.body_to_table);
    if (p > 0 && pos.move > 0.0) {
      // The operator turns the body at constant rate about the axis taking one orientation to the
      // next; the table rests.
      FixtureRecord moving = fixture;
      moving.locked = false;
      const Eigen::AngleAxisd turn(previous.transpose() * r_true);
      const Eigen::Vector3d move_rate = turn.axis() * turn.angle() / pos.move;  // body frame
      const double start = t;
      sinks.fixture([&] {
        FixtureRecord f = moving;
        f.stamp = stampOf(t);
        last_fixture = f.stamp;
        return f;
      }());
      const long steps = static_cast<long>(std::round(pos.move * g.rate_hz));
      for (long s = 0; s < steps; ++s) {
        emit(moving, 0.0);
        step([&](double time) {
          const double f = (time - start) / pos.move;
          const Eigen::Matrix3d r = previous * Eigen::AngleAxisd(turn.angle() * f, turn.axis()).toRotationMatrix();
          return Eigen::Vector3d(r.transpose() * earthInPlatterFrame(g.latitude, g.azimuth, table_angle) + move_rate);
        });
        t += h;
      }
    }
    fixture.locked = true;
    sinks.fixture([&] {
      FixtureRecord f = fixture;
      f.stamp = stampOf(t);
      last_fixture = f.stamp;
      return f;
    }());
    const double start = t;
    const double angle0 = table_angle;
    const long steps = static_cast<long>(pos.profile.duration() * g.rate_hz);
    for (long s = 0; s < steps; ++s) {
      double profile_angle, rate;
      pos.profile.evaluate(t - start, &profile_angle, &rate);
      table_angle = angle0 + profile_angle;
      emit(fixture, rate);
      step([&](double time) {
        double a, w;
        pos.profile.evaluate(time - start, &a, &w);
        return Eigen::Vector3d(r_true.transpose() *
                               (w * Eigen::Vector3d::UnitZ() + earthInPlatterFrame(g.latitude, g.azimuth, angle0 + a)));
      });
      t += h;
    }
    double end_angle, end_rate;
    pos.profile.evaluate(pos.profile.duration(), &end_angle, &end_rate);
    table_angle = angle0 + end_angle;
    previous = r_true;
  }
}

/// Feeds a TriadCalibration with an angle-level triad session and finishes it.
inline TriadOutcome calibrateAngleLevelTriad(const AngleLevelTriad& g, const std::vector<TriadPosition>& positions,
                                             const CalibrationSettings& axis_settings,
                                             const TriadCalibrationSettings& settings,
                                             const std::array<GyroParameters, 3>& priors) {
  TriadCalibration calibration(axis_settings, settings, priors, TriadParameters());
  TriadSinks sinks;
  sinks.table = [&](Nanoseconds stamp, double angle, double rate, std::uint32_t seq) {
    calibration.addTurntable(stamp, angle, rate, seq);
  };
  sinks.fixture = [&](const FixtureRecord& f) { calibration.addFixture(f); };
  sinks.wave = [&](int axis, Nanoseconds stamp, double theta) { calibration.addWave(axis, stamp, theta); };
  runAngleLevelTriad(g, positions, sinks);
  return calibration.finish();
}

/// The six positions +z, -z, +x, -x, +y, -y, each with dual-rate plateaus at +-rate and a rest.
inline std::vector<TriadPosition> sixPositions(double rate, double plateau, int pairs, double rest) {
  std::vector<TriadPosition> out;
  const std::pair<int, int> order[] = {{2, 1}, {2, -1}, {0, 1}, {0, -1}, {1, 1}, {1, -1}};
  for (const auto& [axis, sign] : order) {
    TriadPosition p;
    p.name = std::string(sign > 0 ? "+" : "-") + "xyz"[axis];
    p.body_to_table = axisAlongTable(axis, sign);
    p.profile.append(rest, 0.0, 0.0, "rest");
    for (int r = 0; r < pairs; ++r) {
      for (const double w : {rate, -rate}) {
        const double from = p.profile.finalRate();
        p.profile.append(std::abs(w - from) / 0.5, from, w > from ? 0.5 : -0.5, "ramp");
        p.profile.append(plateau, w, 0.0, "plateau");
      }
    }
    const double from = p.profile.finalRate();
    p.profile.append(std::abs(from) / 0.5, from, from > 0 ? -0.5 : 0.5, "ramp");
    p.profile.append(5.0, 0.0, 0.0, "settle");
    out.push_back(p);
  }
  return out;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
