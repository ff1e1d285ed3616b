// Test support: an angle-level generator of north-finding sessions (no pickoffs, no demodulation),
// written apart from the signal-level simulator and from the alignment's own code, so that they cannot
// share a mistake of frames or signs. It models:
//
//  - the site: latitude, ENU, the Earth's rate Omega (0, cos lat, sin lat);
//  - a mount at a true attitude (roll, pitch, yaw; body -> ENU, C = Rz Ry Rx): the triad's body in the
//    static and sweep modes, the indexer's zero frame in the indexed mode (the body on its platform
//    through body_to_platform, turned about the platform's z by the indexer's true angle);
//  - an indexer: positions held for a dwell and joined by moves at a constant rate, or continuous
//    rotation; each position's true angle off the logged one by its own error; the log at 100 Hz with
//    encoder noise;
//  - the triad's body axes as the combiner delivers them (the calibrated M taken as exact): each
//    body axis's angle increment is the exact integral of the body's inertial rate about it, plus the
//    residual bias a table calibration leaves, D(theta)'s residual harmonic at the axis's wave angle
//    (electrical, divided by K0), an optional angle random walk and bias random walk, and white angle
//    noise on the integrated angle (8.8e-6 rad of body angle per 200 Hz sample: the shipped gyro's
//    4.9e-6 rad of electrical theta over |K0| = 0.56);
//  - the sweep: each axis's wave turned by a commanded virtual rate (+rate and -rate segments of
//    whole turns after a settle), executed with a gain G_v (and an optional order-2 harmonic of it);
//    each axis's compensated output then carries G_v psi_cmd / K0, and its precession state record
//    (rate in force, commanded angle at the sample's centre) comes with it;
//  - one gyro with its sensitive axis in the platform frame (the indexed mode's single gyro);
//  - an accelerometer on the mount (its mounting rotation, bias and white noise), and what users get
//    wrong with one: its scale and misalignment, an axis reversed, gravity (-g up) reported instead
//    of the specific force, quantised records;
//  - a base that moves (simulation/base_motion.h: leans, knocks, sways, yaw jitter, vibration): the
//    mount turned by D(t) in ENU, the body's inertial rate C^T (Omega + w_D) + the platform's turn
//    integrated over each sample by Simpson's rule (16 panels), the accelerometer reading the
//    vibration's mean over its sample. Without motion the closed forms above, bit for bit as before.
//
// What a table calibration leaves, the defaults of the tests: a residual body bias of 1e-8 rad/s per
// axis (the triad calibration's body bias standard error, 0.9 to 1.3e-8 rad/s on the documented session,
// docs/triad_calibration.md), and an order-2 residual of D of 8e-9 rad/s (electrical), the term the
// triad calibration's first stage leaves in D when it ignores the horizontal Earth rate a slightly
// tilted axis senses (4e-9 to 8e-9 rad/s measured).
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <functional>
#include <vector>

#include "hrg_gyro/core/alignment/gyrocompass.h"
#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
#include "hrg_gyro/core/simulation/base_motion.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace testing {

/// The wave's shipped white angle noise per 200 Hz sample, in body angle (4.9e-6 rad / 0.56).
constexpr double kShippedBodyAngleNoise = 4.9e-6 / 0.56;

struct IndexerStop {
  double angle = 0.0;   ///< rad, logged (commanded) angle of the position
  double error = 0.0;   ///< rad, the true angle less the logged one
  double dwell = 60.0;  ///< s at rest
};

struct MountScenario {
  double latitude = 0.9;
  EulerAngles mount{0.0, 0.0, 0.3};  ///< true attitude of the body (or the indexer's zero frame)
  double rate_hz = 200.0;
  double start = 100.0;     ///< s, the stamp where the session starts
  double duration = 120.0;  ///< s of gyro samples (static, sweep; the indexed mode: its plan's)

  // The triad's body axes.
  double white_noise = kShippedBodyAngleNoise;                                     ///< rad of body angle per sample
  double angle_random_walk = 0.0;                                                  ///< rad/sqrt(s)
  double rate_random_walk = 0.0;                                                   ///< rad/s/sqrt(s)
  Eigen::Vector3d residual_bias = Eigen::Vector3d::Zero();                         ///< rad/s, body
  double scale_factor = -0.56;                                                     ///< K0
  std::array<double, 3> drift_cos2{{0.0, 0.0, 0.0}}, drift_sin2{{0.0, 0.0, 0.0}};  ///< rad/s, electrical
  std::array<double, 3> wave_angle{{0.2, 1.1, 2.3}};                               ///< rad, theta at the start

  // The indexer (indexed mode).
  bool indexed = false;
  bool continuous = false;
  double continuous_rate = 0.05;  ///< rad/s
  std::vector<IndexerStop> stops;
  double move_rate = 0.5;       ///< rad/s between positions
  double encoder_noise = 1e-6;  ///< rad per record
  Eigen::Matrix3d body_to_platform = Eigen::Matrix3d::Identity();
  bool single_gyro = false;
  Eigen::Vector3d gyro_axis = Eigen::Vector3d::UnitX();  ///< platform frame

  // The sweep.
  bool sweep = false;
  double sweep_rate = 0.2;   ///< rad/s, electrical
  double sweep_turns = 2.0;  ///< whole turns per segment after the settle
  double sweep_settle = 2.0;
  double sweep_rest = 5.0;
  std::vector<int> sweep_directions{1, -1, -1, 1};
  double virtual_gain = 1.0 + 3e-4;  ///< G_v
  double virtual_gain_cos2 = 0.0;    ///< relative order-2 harmonic of G_v

  // The accelerometer.
  bool accelerometer = true;
  Eigen::Quaterniond accelerometer_to_body = Eigen::Quaterniond::Identity();
  Eigen::Vector3d accelerometer_bias = Eigen::Vector3d::Zero();          ///< m/s^2
  double accelerometer_noise = 2e-3;                                     ///< m/s^2 per sample
  Eigen::Vector3d accelerometer_scale = Eigen::Vector3d::Zero();         ///< relative, per axis
  Eigen::Vector3d accelerometer_misalignment = Eigen::Vector3d::Zero();  ///< rad, rotation vector of its axes
  Eigen::Vector3d accelerometer_signs = Eigen::Vector3d::Ones();         ///< -1: that axis reversed
  bool accelerometer_reports_gravity = false;                            ///< -g up instead of the specific force
  double accelerometer_quantum = 0.0;                                    ///< m/s^2 (0: none)

  // The base under the mount (the indexer's base in the indexed mode).
  BaseMotionConfig base_motion;

  std::uint64_t seed = 1;

  /// s the sweep's plan lasts (rest + segments).
  double sweepDuration() const {
    return sweep_rest +
           static_cast<double>(sweep_directions.size()) * (sweep_settle + sweep_turns * kTwoPi / sweep_rate);
  }
  /// s the indexer's plan lasts.
  double indexerDuration() const {
    if (continuous) return duration;
    double t = 0.0;
    for (std::size_t p = 0; p < stops.size(); ++p) {
      if (p > 0) t += std::abs(stops[p].angle - stops[p - 1].angle) / move_rate;
      t += stops[p].dwell;
    }
    return t;
  }
  double length() const { return sweep ? sweepDuration() : indexed ? indexerDuration() : duration; }
};

struct MountSinks {
  std::function<void(const TriadBodySample&)> triad;
  std::function<void(const AxisOutput&)> axis;                     ///< the single gyro
  std::function<void(std::size_t, const AxisOutput&)> sweep_axis;  ///< each axis, sweep
  std::function<void(std::size_t, const PrecessionStateRecord&)> precession;
  std::function<void(const IndexerRecord&)> indexer;
  std::function<void(const AccelerometerRecord&)> accelerometer;
};

/// The indexer's logged angle, true angle and rate at time t (s from the session's start).
inline void indexerAngle(const MountScenario& s, double t, double* logged, double* truth, double* rate) {
  if (s.continuous) {
    *logged = *truth = s.continuous_rate * t;
    *rate = s.continuous_rate;
    return;
  }
  double begin = 0.0;
  for (std::size_t p = 0; p < s.stops.size(); ++p) {
    if (p > 0) {
      const double move = std::abs(s.stops[p].angle - s.stops[p - 1].angle) / s.move_rate;
      if (t < begin + move) {
        const double f = (t - begin) / move;
        *logged = s.stops[p - 1].angle + f * (s.stops[p].angle - s.stops[p - 1].angle);
        *truth = *logged + s.stops[p - 1].error + f * (s.stops[p].error - s.stops[p - 1].error);
        *rate = (s.stops[p].angle > s.stops[p - 1].angle ? 1.0 : -1.0) * s.move_rate;
        return;
      }
      begin += move;
    }
    if (t < begin + s.stops[p].dwell || p + 1 == s.stops.size()) {
      *logged = s.stops[p].angle;
      *truth = s.stops[p].angle + s.stops[p].error;
      *rate = 0.0;
      return;
    }
    begin += s.stops[p].dwell;
  }
  *logged = *truth = *rate = 0.0;
}

/// The sweep's commanded rate and angle at t (s from the session's start).
inline void commandedPrecession(const MountScenario& s, double t, double* rate, double* angle) {
  const double segment = s.sweep_settle + s.sweep_turns * kTwoPi / s.sweep_rate;
  *rate = 0.0;
  *angle = 0.0;
  double begin = s.sweep_rest;
  for (int direction : s.sweep_directions) {
    const double w = direction * s.sweep_rate;
    if (t < begin) return;
    if (t < begin + segment) {
      *rate = w;
      *angle += w * (t - begin);
      return;
    }
    *angle += w * segment;
    begin += segment;
  }
}

/// The sweep's records of one sample: each axis's output (flagged while a rate is commanded) and its
/// driver's precession state (the commanded angle at the sample's centre, the rate at its end).
inline void emitSweepSample(const MountScenario& s, const MountSinks& sinks, const TriadBodySample& triad, double t_b,
                            double cmd_rate) {
  const double h = 1.0 / s.rate_hz;
  for (std::size_t i = 0; i < 3; ++i) {
    AxisOutput out;
    out.stamp = triad.stamp;
    out.dt = h;
    out.dalpha = triad.delta_angle(static_cast<int>(i));
    out.flags = cmd_rate != 0.0 ? kFlagPrecessing : 0;
    PrecessionStateRecord state;
    state.stamp = triad.stamp;
    state.rate = cmd_rate;
    double centre_rate, centre_angle;
    commandedPrecession(s, t_b - 0.5 * h, &centre_rate, &centre_angle);
    state.angle = centre_angle;
    if (sinks.precession) sinks.precession(i, state);
    if (sinks.sweep_axis) sinks.sweep_axis(i, out);
  }
}

/// The accelerometer's record at platform angle `psi`: the specific force (`g0`: gravity in the mount
/// frame, the base still; `f_mount`: what the moving base gives, in the mount frame) seen through the
/// platform and the body, then its mounting, misalignment, scale, axis signs, convention, bias, noise
/// and quantisation, in that order.
inline AccelerometerRecord accelerometerSample(const MountScenario& s, Nanoseconds stamp, double psi,
                                               const Eigen::Vector3d& f_mount, GaussianNoise* noise) {
  const Eigen::Matrix3d body_to_mount =
      Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix() * s.body_to_platform;
  AccelerometerRecord r;
  r.stamp = stamp;
  Eigen::Vector3d f = s.accelerometer_to_body.toRotationMatrix().transpose() * (body_to_mount.transpose() * f_mount);
  if (s.accelerometer_misalignment.norm() > 0.0) {
    f = rotationVectorToQuaternion(s.accelerometer_misalignment).toRotationMatrix().transpose() * f;
  }
  f = (Eigen::Vector3d::Ones() + s.accelerometer_scale).cwiseProduct(f).cwiseProduct(s.accelerometer_signs);
  if (s.accelerometer_reports_gravity) f = -f;
  r.specific_force = f + s.accelerometer_bias;
  for (int i = 0; i < 3; ++i) r.specific_force(i) += s.accelerometer_noise * noise->next();
  if (s.accelerometer_quantum > 0.0) {
    for (int i = 0; i < 3; ++i) {
      r.specific_force(i) = s.accelerometer_quantum * std::round(r.specific_force(i) / s.accelerometer_quantum);
    }
  }
  return r;
}

/// The mount at time t (s from the session's start) on a moving base: D(t) mount, -> ENU.
inline Eigen::Matrix3d movedMount(const MountScenario& s, const BaseMotion& base, double t) {
  return base.rotationAt(t) * orientationFromEuler(s.mount).toRotationMatrix();
}

/// The inertial rate of the platform frame (the mount's, static) on a moving base, in that frame.
inline Eigen::Vector3d movingPlatformRate(const MountScenario& s, const BaseMotion& base, double t) {
  Eigen::Matrix3d d;
  Eigen::Vector3d w;
  base.stateAt(t, &d, &w);
  double logged, psi = 0.0, rate = 0.0;
  if (s.indexed) indexerAngle(s, t, &logged, &psi, &rate);
  const Eigen::Matrix3d platform = d * orientationFromEuler(s.mount).toRotationMatrix() *
                                   Eigen::AngleAxisd(psi, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return platform.transpose() * (earthRateEnu(s.latitude) + w) + Eigen::Vector3d::UnitZ() * rate;
}

/// Its integral over [a, b]: Simpson's rule on 16 panels.
inline Eigen::Vector3d movingPlatformIncrement(const MountScenario& s, const BaseMotion& base, double a, double b) {
  constexpr int kPanels = 16;
  const double h = (b - a) / kPanels;
  Eigen::Vector3d sum = movingPlatformRate(s, base, a) + movingPlatformRate(s, base, b);
  for (int k = 1; k < kPanels; ++k) sum += (k % 2 ? 4.0 : 2.0) * movingPlatformRate(s, base, a + k * h);
  return sum * h / 3.0;
}

/// The true attitude (-> ENU) at `stamp` of the frame the alignment reports: the body (static,
/// sweep) or the indexer's zero frame (indexed), the base's motion included.
inline Eigen::Matrix3d trueFrameAt(const MountScenario& s, Nanoseconds stamp) {
  const BaseMotion base(s.base_motion, s.seed);
  return movedMount(s, base, toSeconds(stamp) - s.start);
}

/// The platform's inertial angle increment over the h s that end at t (s), in the platform frame: the
/// Earth's rate (w0, in the mount frame) seen through the platform turning from psi_a to psi_b, and
/// that turn; on a moving base, the base's rate too (by quadrature).
inline Eigen::Vector3d platformIncrement(const MountScenario& s, const BaseMotion& base, const Eigen::Vector3d& w0,
                                         double t, double h, double psi_a, double psi_b) {
  if (base.enabled()) return movingPlatformIncrement(s, base, t - h, t);
  const double middle = 0.5 * (psi_a + psi_b), sinc_half = h * sinc(0.5 * (psi_b - psi_a));
  const double ic = sinc_half * std::cos(middle), is = sinc_half * std::sin(middle);
  const Eigen::Vector3d earth_platform(ic * w0.x() + is * w0.y(), -is * w0.x() + ic * w0.y(), h * w0.z());
  return earth_platform + Eigen::Vector3d::UnitZ() * (psi_b - psi_a);
}

/// The specific force on the mount over [a, b] on a moving base, in the mount frame: gravity through
/// the mount's attitude at b, plus the vibration's mean over the interval.
inline Eigen::Vector3d mountSpecificForce(const MountScenario& s, const BaseMotion& base, double a, double b) {
  return movedMount(s, base, b).transpose() *
         (Eigen::Vector3d(0.0, 0.0, kStandardGravity) + base.meanAccelerationOver(a, b));
}

/// Runs the session into the sinks, sample by sample in stamp order.
inline void runMountScenario(const MountScenario& s, const MountSinks& sinks) {
  GaussianNoise noise(s.seed);
  const BaseMotion base(s.base_motion, s.seed);
  const double h = 1.0 / s.rate_hz;
  const Eigen::Matrix3d mount = orientationFromEuler(s.mount).toRotationMatrix();
  const Eigen::Vector3d w0 = mount.transpose() * earthRateEnu(s.latitude);  // in the mount (platform zero) frame
  const Eigen::Vector3d g0 = mount.transpose() * Eigen::Vector3d(0.0, 0.0, kStandardGravity);
  const Eigen::Matrix3d& b = s.body_to_platform;
  const long samples = static_cast<long>(std::llround(s.length() * s.rate_hz));
  std::array<double, 3> truth{{0.0, 0.0, 0.0}}, measured_previous{{0.0, 0.0, 0.0}}, walk{{0.0, 0.0, 0.0}};
  std::array<double, 3> bias_walk{{0.0, 0.0, 0.0}}, theta = s.wave_angle, psi_cmd_previous{{0.0, 0.0, 0.0}};
  double single_truth = 0.0, single_previous = 0.0;
  double logged_a, psi_a, rate_a;
  indexerAngle(s, 0.0, &logged_a, &psi_a, &rate_a);
  if (!s.indexed) psi_a = 0.0;
  for (int i = 0; i < 3; ++i) measured_previous[i] = s.white_noise * noise.next();
  single_previous = s.white_noise * noise.next();
  for (long k = 1; k <= samples; ++k) {
    const double t_b = k * h;
    const Nanoseconds stamp = toNanoseconds(s.start + t_b);
    double logged_b = 0.0, psi_b = 0.0, rate_b = 0.0;
    if (s.indexed) indexerAngle(s, t_b, &logged_b, &psi_b, &rate_b);
    const Eigen::Vector3d platform_increment = platformIncrement(s, base, w0, t_b, h, psi_a, psi_b);
    const Eigen::Vector3d body_increment = b.transpose() * platform_increment;
    double cmd_rate = 0.0, cmd_angle = 0.0;
    if (s.sweep) commandedPrecession(s, t_b, &cmd_rate, &cmd_angle);
    TriadBodySample triad;
    triad.stamp = stamp;
    triad.dt = h;
    for (int i = 0; i < 3; ++i) {
      // The wave: K0 times the body's angle, the commanded turn (G_v), the residual drift.
      const double d_cmd = cmd_angle - psi_cmd_previous[i];
      const double theta_mid = theta[i] + 0.5 * (s.scale_factor * body_increment(i) + s.virtual_gain * d_cmd);
      const double theta_next = theta[i] + s.scale_factor * body_increment(i) + s.virtual_gain * d_cmd;
      const double mid2 = theta[i] + theta_next, k2 = h * sinc(theta_next - theta[i]);
      const double c2 = k2 * std::cos(mid2), s2 = k2 * std::sin(mid2);
      const double drift = (s.drift_cos2[i] * c2 + s.drift_sin2[i] * s2) / s.scale_factor;
      const double gain = s.virtual_gain * (1.0 + s.virtual_gain_cos2 * std::cos(2.0 * theta_mid));
      theta[i] = theta_next;
      psi_cmd_previous[i] = cmd_angle;
      if (s.rate_random_walk > 0.0) bias_walk[i] += s.rate_random_walk * std::sqrt(h) * noise.next();
      if (s.angle_random_walk > 0.0) walk[i] += s.angle_random_walk * std::sqrt(h) * noise.next();
      truth[i] += body_increment(i) + (s.residual_bias(i) + bias_walk[i]) * h + drift + gain * d_cmd / s.scale_factor;
      const double measured = truth[i] + walk[i] + s.white_noise * noise.next();
      triad.delta_angle(i) = measured - measured_previous[i];
      measured_previous[i] = measured;
    }
    triad.angular_velocity = triad.delta_angle / h;
    if (s.sweep) {
      emitSweepSample(s, sinks, triad, t_b, cmd_rate);
    } else if (s.single_gyro) {
      const Eigen::Vector3d& d = s.gyro_axis;
      single_truth += d.dot(platform_increment) + s.residual_bias.x() * h;
      const double measured = single_truth + s.white_noise * noise.next();
      AxisOutput out;
      out.stamp = stamp;
      out.dt = h;
      out.dalpha = measured - single_previous;
      single_previous = measured;
      if (sinks.axis) sinks.axis(out);
    } else if (sinks.triad) {
      sinks.triad(triad);
    }
    if (s.indexed && (k % 2 == 0) && sinks.indexer) {
      IndexerRecord r;
      r.stamp = stamp;
      r.angle = logged_b + s.encoder_noise * noise.next();
      r.rate = rate_b;
      sinks.indexer(r);
    }
    if (s.accelerometer && sinks.accelerometer) {
      const Eigen::Vector3d f_mount = base.enabled() ? mountSpecificForce(s, base, t_b - h, t_b) : g0;
      sinks.accelerometer(accelerometerSample(s, stamp, psi_b, f_mount, &noise));
    }
    psi_a = psi_b;
  }
}

/// Every noise term and level sigma a test left unset, set to what this generator puts in unless the
/// scenario says otherwise: none. (The settings' own defaults leave them unset, and the gyrocompass
/// refuses to start without them.)
inline void setUnsetTermsToNone(AlignmentSettings* a) {
  GyroNoiseModel& n = a->noise;
  for (double* term : {&n.angle_random_walk, &n.rate_random_walk, &n.residual_bias, &n.residual_drift_harmonics}) {
    if (std::isnan(*term)) *term = 0.0;
  }
  LevelSettings& l = a->level;
  for (double* term : {&l.roll_sigma, &l.pitch_sigma, &l.accelerometer_bias_sigma, &l.accelerometer_mounting_sigma}) {
    if (std::isnan(*term)) *term = 0.0;
  }
}

/// Sinks that feed a Gyrocompass (and, once it is complete, `after` with the triad's samples).
inline MountSinks gyrocompassSinks(Gyrocompass* g, std::function<void(const TriadBodySample&)> after = nullptr) {
  MountSinks k;
  k.triad = [g, after](const TriadBodySample& x) {
    if (!g->complete()) {
      g->addTriad(x);
      if (!g->complete() || x.stamp <= g->windowEnd()) return;  // taken, or the window's last
    }
    if (after) after(x);
  };
  k.axis = [g](const AxisOutput& x) { g->addAxis(x); };
  k.sweep_axis = [g](std::size_t i, const AxisOutput& x) { g->addSweepAxis(i, x); };
  k.precession = [g](std::size_t i, const PrecessionStateRecord& x) { g->addPrecession(i, x); };
  k.indexer = [g](const IndexerRecord& x) { g->addIndexer(x); };
  k.accelerometer = [g](const AccelerometerRecord& x) { g->addAccelerometer(x); };
  return k;
}

/// The alignment of a scenario: settings' latitude and duration as the scenario's unless set.
inline AlignmentResult alignScenario(const AlignmentSettings& settings, const MountScenario& s) {
  AlignmentSettings complete = settings;
  setUnsetTermsToNone(&complete);
  Gyrocompass g(complete);
  runMountScenario(s, gyrocompassSinks(&g));
  return g.finish();
}

/// The heading error, rad, wrapped: estimate less truth (the frame at the window's end; the mount's
/// own attitude when the base is still).
inline double yawError(const AlignmentResult& r, const MountScenario& s) {
  if (!s.base_motion.enabled()) return wrapToPi(r.attitude.yaw - s.mount.yaw);
  return wrapToPi(r.attitude.yaw - eulerFromOrientation(Eigen::Quaterniond(trueFrameAt(s, r.last_sample))).yaw);
}

/// Two positions 180 deg apart, `dwell` s each.
inline std::vector<IndexerStop> twoPositions(double dwell) { return {{0.0, 0.0, dwell}, {kPi, 0.0, dwell}}; }
/// Four positions 90 deg apart.
inline std::vector<IndexerStop> fourPositions(double dwell) {
  return {{0.0, 0.0, dwell}, {0.5 * kPi, 0.0, dwell}, {kPi, 0.0, dwell}, {1.5 * kPi, 0.0, dwell}};
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
