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

#include "hrg_gyro/core/calibration/triad/triad_calibration.h"
#include "hrg_gyro/core/model/earth_rate.h"
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

/// The triad the calibration's tests inject: each axis's K(theta) with orders 2 and 4 and D(theta)
/// with order 2, misalignments of tens to hundreds of microradians (rows: each axis's direction in
/// the body frame), white wave-angle noise.
inline AngleLevelTriad misalignedTriad() {
  AngleLevelTriad g;
  g.k[0] = HarmonicModel({2, 4}, -0.56, {-6e-4, 2e-3}, {4e-4, 0.0});
  g.k[1] = HarmonicModel({2, 4}, -0.561, {5e-4, -1.5e-3}, {-3e-4, 2e-4});
  g.k[2] = HarmonicModel({2, 4}, -0.559, {-4e-4, 1e-3}, {2e-4, -1e-4});
  g.d[0] = HarmonicModel({2}, 1e-5, {2e-5}, {-1e-5});
  g.d[1] = HarmonicModel({2}, -2e-5, {1e-5}, {1.5e-5});
  g.d[2] = HarmonicModel({2}, 5e-6, {-2e-5}, {5e-6});
  g.body_to_axis << 1.0, 1.2e-4, -8e-5, -6e-5, 1.0, 2.1e-4, 1.5e-4, -9e-5, 1.0;
  g.noise = 1.1e-5;
  return g;
}

/// What a triad calibration of an angle-level session takes besides the records.
struct AngleLevelTriadSettings {
  CalibrationSettings axis;              ///< stage 1: K orders 2 and 4, D order 2 (the harmonics injected)
  TriadCalibrationSettings triad;        ///< the table's azimuth
  std::array<GyroParameters, 3> priors;  ///< nothing calibrated, the site's latitude
};

inline AngleLevelTriadSettings settingsFor(const AngleLevelTriad& g) {
  AngleLevelTriadSettings s;
  s.axis.scale_factor_orders = {2, 4};
  s.axis.drift_orders = {2};
  s.triad.azimuth = g.azimuth;
  for (GyroParameters& p : s.priors) p.earth_rate.latitude = g.latitude;
  return s;
}

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
  const double horizontal = horizontalEarthRate(latitude);
  return Eigen::Vector3d(horizontal * std::cos(heading), horizontal * std::sin(heading), verticalEarthRate(latitude));
}

struct TriadSinks {
  std::function<void(Nanoseconds, double, double, std::uint32_t)> table;  ///< stamp, angle, rate, seq
  std::function<void(const FixtureRecord&)> fixture;
  std::function<void(int, Nanoseconds, double)> wave;  ///< axis, stamp, measured theta
};

/// One run of an angle-level triad session: the axes' angles, the table's and the clock, stepped
/// through the positions (runAngleLevelTriad).
class AngleLevelTriadRun {
 public:
  AngleLevelTriadRun(const AngleLevelTriad& g, const TriadSinks& sinks)
      : g_(g),
        sinks_(sinks),
        models_{{ModelPairEvaluator(g.k[0], g.d[0]), ModelPairEvaluator(g.k[1], g.d[1]),
                 ModelPairEvaluator(g.k[2], g.d[2])}},
        noise_(g.seed),
        h_(1.0 / g.rate_hz) {}

  void run(const std::vector<TriadPosition>& positions) {
    Eigen::Matrix3d previous = positions.front().trueBodyToTable();
    for (std::size_t p = 0; p < positions.size(); ++p) {
      const TriadPosition& pos = positions[p];
      const Eigen::Matrix3d r_true = pos.trueBodyToTable();
      FixtureRecord fixture;
      fixture.index = static_cast<std::uint32_t>(p);
      fixture.name = pos.name;
      fixture.body_to_table = Eigen::Quaterniond(pos.body_to_table);
      if (p > 0 && pos.move > 0.0) move(fixture, previous, r_true, pos.move);
      fixture.locked = true;
      logFixture(fixture);
      turnTable(fixture, r_true, pos.profile);
      previous = r_true;
    }
  }

 private:
  Nanoseconds stampOf(double time) const { return toNanoseconds(1.0 + time); }

  /// One RK4 step of the three axes under body rate omega(time) (rad/s, body frame).
  void step(const std::function<Eigen::Vector3d(double)>& omega) {
    auto rates = [&](double time, const std::array<double, 3>& th) {
      const Eigen::Vector3d w = g_.body_to_axis * omega(time);
      std::array<double, 3> r{};
      for (int i = 0; i < 3; ++i) {
        double k, d;
        models_[i].evaluate(th[i], NAN, &k, &d);
        r[i] = k * w(i) + d;
      }
      return r;
    };
    auto add = [](const std::array<double, 3>& a, const std::array<double, 3>& b, double f) {
      return std::array<double, 3>{{a[0] + f * b[0], a[1] + f * b[1], a[2] + f * b[2]}};
    };
    const double h = h_;
    const auto k1 = rates(t_, theta_), k2 = rates(t_ + h / 2, add(theta_, k1, h / 2)),
               k3 = rates(t_ + h / 2, add(theta_, k2, h / 2)), k4 = rates(t_ + h, add(theta_, k3, h));
    for (int i = 0; i < 3; ++i) theta_[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
  }

  /// The fixture's record now, at a change of its state.
  void logFixture(const FixtureRecord& fixture) {
    FixtureRecord f = fixture;
    f.stamp = stampOf(t_);
    last_fixture_ = f.stamp;
    sinks_.fixture(f);
  }

  /// The records of this instant: the fixture's once a second, the table's, each axis's angle.
  void emit(const FixtureRecord& fixture, double rate) {
    const Nanoseconds stamp = stampOf(t_);
    if (last_fixture_ == 0 || toSeconds(stamp - last_fixture_) >= 1.0) {
      FixtureRecord f = fixture;
      f.stamp = stamp;
      sinks_.fixture(f);
      last_fixture_ = stamp;
    }
    sinks_.table(stamp, table_angle_, rate, seq_++);
    for (int i = 0; i < 3; ++i) sinks_.wave(i, stamp, theta_[i] + g_.noise * noise_.next());
  }

  /// The operator turns the body at constant rate about the axis taking one orientation to the
  /// next, in `duration` s; the table rests and the fixture is logged released.
  void move(const FixtureRecord& fixture, const Eigen::Matrix3d& from, const Eigen::Matrix3d& to, double duration) {
    FixtureRecord moving = fixture;
    moving.locked = false;
    const Eigen::AngleAxisd turn(from.transpose() * to);
    const Eigen::Vector3d move_rate = turn.axis() * turn.angle() / duration;  // body frame
    const double start = t_;
    logFixture(moving);
    const long steps = static_cast<long>(std::round(duration * g_.rate_hz));
    for (long s = 0; s < steps; ++s) {
      emit(moving, 0.0);
      step([&](double time) {
        const double f = (time - start) / duration;
        const Eigen::Matrix3d r = from * Eigen::AngleAxisd(turn.angle() * f, turn.axis()).toRotationMatrix();
        return Eigen::Vector3d(r.transpose() * earthInPlatterFrame(g_.latitude, g_.azimuth, table_angle_) + move_rate);
      });
      t_ += h_;
    }
  }

  /// The position's table profile, the body in its true orientation `r_true`.
  void turnTable(const FixtureRecord& fixture, const Eigen::Matrix3d& r_true, const TurntableProfile& profile) {
    const double start = t_;
    const double angle0 = table_angle_;
    const long steps = static_cast<long>(profile.duration() * g_.rate_hz);
    for (long s = 0; s < steps; ++s) {
      double profile_angle, rate;
      profile.evaluate(t_ - start, &profile_angle, &rate);
      table_angle_ = angle0 + profile_angle;
      emit(fixture, rate);
      step([&](double time) {
        double a, w;
        profile.evaluate(time - start, &a, &w);
        return Eigen::Vector3d(r_true.transpose() * (w * Eigen::Vector3d::UnitZ() +
                                                     earthInPlatterFrame(g_.latitude, g_.azimuth, angle0 + a)));
      });
      t_ += h_;
    }
    double end_angle, end_rate;
    profile.evaluate(profile.duration(), &end_angle, &end_rate);
    table_angle_ = angle0 + end_angle;
  }

  const AngleLevelTriad& g_;
  const TriadSinks& sinks_;
  std::array<ModelPairEvaluator, 3> models_;
  GaussianNoise noise_;
  const double h_;
  std::array<double, 3> theta_{{0.2, 1.1, 2.3}};
  double table_angle_ = 0.0, t_ = 0.0;
  std::uint32_t seq_ = 0;
  Nanoseconds last_fixture_ = 0;
};

/// Runs the session of `positions` on `g` into `sinks`.
inline void runAngleLevelTriad(const AngleLevelTriad& g, const std::vector<TriadPosition>& positions,
                               const TriadSinks& sinks) {
  AngleLevelTriadRun(g, sinks).run(positions);
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

/// Feeds a TriadCalibration (`settings`, a nominal prior triad) with an angle-level triad session
/// and finishes it.
inline TriadOutcome calibrateAngleLevelTriad(const AngleLevelTriad& g, const std::vector<TriadPosition>& positions,
                                             const AngleLevelTriadSettings& settings) {
  return calibrateAngleLevelTriad(g, positions, settings.axis, settings.triad, settings.priors);
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
