// Test support: a fast angle-level session (no pickoffs, no demodulation) -- the wave angle obeys
// d theta = K(theta) (Omega_table + Omega_E) dt + D(theta) dt, sampled at `rate_hz` with white
// noise -- fed into a calibration session together with the turntable states. K and D may depend
// on the resonator frequency, given as a function of time (a temperature ramp at angle level).
//
// runTableSession adds what a real rate table and its controller do (TableImperfections): a drive
// whose rate ripples, an encoder angle with noise and quantisation logged at its own rate, the rate
// logged as that angle differenced (or no angle at all), dropped wave samples and gaps; and angle
// random walk of the wave. The table angle and the wave angle are integrated together with RK4, so
// the injected K and D are met exactly whatever the ripple or the non-uniform sweep.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>

#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/model/earth_rate.h"
#include "hrg_gyro/core/model/model_pair_evaluator.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"
#include "hrg_gyro/core/simulation/turntable_profile.h"

namespace hrg_gyro {
namespace core {
namespace testing {

struct AngleLevelGyro {
  HarmonicModel k{-0.56};
  HarmonicModel d{0.0};
  double earth_rate = 0.0;  ///< rad/s
  double noise = 0.0;       ///< white angle noise per sample, rad
  double rate_noise = 0.0;  ///< noise on the reported table rate, rad/s
  double rate_hz = 1000.0;
  double theta0 = 0.2;
  std::uint64_t seed = 7;
  double angle_random_walk = 0.0;  ///< rad/sqrt(s) of wave angle (runTableSession only)
  /// The bias wanders (runTableSession only): D0 + bias_trend t + bias_random_walk W(t), t in s from
  /// the session start, W a standard Wiener process (its own seeded stream), held over each step.
  double bias_trend = 0.0;        ///< rad/s per s
  double bias_random_walk = 0.0;  ///< rad/s/sqrt(s)
  /// Resonator frequency (Hz) at t s from the start, where K and D are evaluated and which the
  /// samples report; empty: unknown (NaN).
  std::function<double(double)> frequency;
};

/// The reference gyro of the calibration tests (K0 = -0.56, our electrical convention): harmonics of
/// a few 1e-4 in K and a drift with a 2theta term, so that drift leaking into K would show.
inline AngleLevelGyro referenceGyro() {
  AngleLevelGyro g;
  g.k = HarmonicModel({2, 4}, -0.56, {-6e-4, 2e-3}, {4e-4, 0.0});
  g.d = HarmonicModel({2}, 1e-5, {2e-5}, {-1e-5});
  g.earth_rate = verticalEarthRate(0.9);
  return g;
}

/// White wave-angle noise per sample of the calibration tests' gyro at 1 kHz, rad.
constexpr double kNominalNoise = 1.1e-5;

/// referenceGyro() with K harmonics up to order 8 and the nominal wave noise: the gyro of the
/// table-session tests.
inline AngleLevelGyro nominalGyro(std::uint64_t seed) {
  AngleLevelGyro g = referenceGyro();
  g.k = HarmonicModel({2, 4, 6, 8}, -0.56, {-6e-4, 2e-3, 1e-4, -5e-5}, {4e-4, 0.0, -1e-4, 0.0});
  g.noise = kNominalNoise;
  g.seed = seed;
  return g;
}

/// The prior of the calibration tests: the nominal parameters at the reference gyro's latitude.
inline GyroParameters referencePrior() {
  GyroParameters p;
  p.earth_rate.latitude = 0.9;
  return p;
}

/// Calls sink(stamp, table_angle, table_rate_reported, theta_measured, frequency) for every sample.
inline void runAngleLevel(const AngleLevelGyro& g, const TurntableProfile& profile,
                          const std::function<void(Nanoseconds, double, double, double, double)>& sink) {
  ModelPairEvaluator models(g.k, g.d);
  GaussianNoise noise(g.seed);
  const double h = 1.0 / g.rate_hz;
  double theta = g.theta0;
  auto frequency = [&](double t) { return g.frequency ? g.frequency(t) : NAN; };
  auto f = [&](double t, double th) {
    double angle, rate, k, d;
    profile.evaluate(t, &angle, &rate);
    models.evaluate(th, frequency(t), &k, &d);
    return k * (rate + g.earth_rate) + d;
  };
  const long steps = static_cast<long>(profile.duration() * g.rate_hz);
  for (long i = 0; i < steps; ++i) {
    const double t = i * h;
    double angle, rate;
    profile.evaluate(t, &angle, &rate);
    sink(toNanoseconds(1.0 + t), angle, rate + g.rate_noise * noise.next(), theta + g.noise * noise.next(),
         frequency(t));
    const double k1 = f(t, theta), k2 = f(t + h / 2, theta + h / 2 * k1), k3 = f(t + h / 2, theta + h / 2 * k2),
                 k4 = f(t + h, theta + h * k3);
    theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
}

/// The same without the frequency: sink(stamp, table_angle, table_rate_reported, theta_measured).
inline void runAngleLevel(const AngleLevelGyro& g, const TurntableProfile& profile,
                          const std::function<void(Nanoseconds, double, double, double)>& sink) {
  runAngleLevel(g, profile,
                [&](Nanoseconds t, double angle, double rate, double theta, double) { sink(t, angle, rate, theta); });
}

/// What a real table and its logs add (runTableSession).
struct TableImperfections {
  double ripple = 0.0;            ///< relative amplitude of the drive's rate ripple, rate (1 + a sin 2 pi f t)
  double ripple_frequency = 0.0;  ///< Hz
  double encoder_noise = 0.0;     ///< rad, white noise of the logged angle
  double encoder_step = 0.0;      ///< rad, quantisation of the logged angle (0: none)
  double log_hz = 0.0;            ///< turntable records per s (0: one per wave sample); divides rate_hz
  bool rate_from_angle = false;   ///< the logged rate is the logged angle differenced between records
  bool angle_logged = true;       ///< false: the controller logs no angle (the field is NaN)
  /// The controller's own clock: each record stamped at its true time + clock_offset (+ clock_step
  /// from clock_step_at s on) + clock_jitter x N(0, 1), its own seeded stream; seq counts records.
  double clock_offset = 0.0;      ///< s, the table's stamps minus the gyro's
  double clock_jitter = 0.0;      ///< s, white
  double clock_step_at = 0.0;     ///< s from the start (0: no step) ...
  double clock_step = 0.0;        ///< ... where the offset changes by this much, s
  double clock_rate_error = 0.0;  ///< s per s: the controller's clock runs 1 + this times as fast
  double drop_fraction = 0.0;     ///< wave samples dropped at random
  double gap_period = 0.0;        ///< s: a gap in the wave stream every gap_period s (0: none) ...
  double gap_length = 0.0;        ///< ... lasting this long
};

/// A turntable record as the controller logs it.
struct TableRecord {
  Nanoseconds stamp = 0;  ///< on the controller's clock
  double angle = 0.0, rate = 0.0;
  std::uint32_t seq = 0;  ///< the controller's record count
  double time = 0.0;      ///< true time of the record, s from the start
};

/// The bias the gyro of runTableSession has at t s from the start, without its random walk.
inline double biasTrendAt(const AngleLevelGyro& g, double t) { return g.bias_trend * t; }

/// table_sink(record) per turntable record, wave_sink(stamp, theta, frequency) per wave sample, in
/// true time order (a record and a sample at the same true time: the record first).
inline void runTableSession(const AngleLevelGyro& g, const TableImperfections& table, const TurntableProfile& profile,
                            const std::function<void(const TableRecord&)>& table_sink,
                            const std::function<void(Nanoseconds, double, double)>& wave_sink) {
  ModelPairEvaluator models(g.k, g.d);
  GaussianNoise noise(g.seed), table_noise(g.seed ^ 0x9e3779b97f4a7c15ULL), drops(g.seed ^ 0x51ed27a3ULL);
  GaussianNoise bias_noise(g.seed ^ 0x2545f4914f6cdd1dULL), clock_noise(g.seed ^ 0x6a09e667f3bcc909ULL);
  double bias_walk = 0.0;
  std::uint32_t seq = 0;
  const double h = 1.0 / g.rate_hz;
  const long log_every = table.log_hz > 0.0 ? std::max(1L, std::lround(g.rate_hz / table.log_hz)) : 1;
  auto frequency = [&](double t) { return g.frequency ? g.frequency(t) : NAN; };
  auto tableRate = [&](double t) {
    double angle, rate;
    profile.evaluate(t, &angle, &rate);
    return table.ripple > 0.0 ? rate * (1.0 + table.ripple * std::sin(2.0 * kPi * table.ripple_frequency * t)) : rate;
  };
  auto thetaRate = [&](double t, double th, double table_rate) {
    double k, d;
    models.evaluate(th, frequency(t), &k, &d);
    return k * (table_rate + g.earth_rate) + d + biasTrendAt(g, t) + bias_walk;
  };
  double theta = g.theta0, phi = 0.0, logged_previous = 0.0;
  double unused_angle, rate0;
  profile.evaluate(0.0, &unused_angle, &rate0);
  bool first_record = true;
  double next_rate = tableRate(0.0);
  const long steps = static_cast<long>(profile.duration() * g.rate_hz);
  for (long i = 0; i < steps; ++i) {
    const double t = i * h;
    const Nanoseconds stamp = toNanoseconds(1.0 + t);
    if (i % log_every == 0) {
      double logged = phi + table.encoder_noise * table_noise.next();
      if (table.encoder_step > 0.0) logged = table.encoder_step * std::round(logged / table.encoder_step);
      double rate = tableRate(t) + g.rate_noise * table_noise.next();
      if (table.rate_from_angle) rate = first_record ? rate0 : (logged - logged_previous) / (log_every * h);
      TableRecord r;
      r.time = t;
      r.seq = seq++;
      double clock = table.clock_offset + table.clock_rate_error * t;
      if (table.clock_step_at > 0.0 && t >= table.clock_step_at) clock += table.clock_step;
      if (table.clock_jitter > 0.0) clock += table.clock_jitter * clock_noise.next();
      r.stamp = stamp + toNanoseconds(clock);
      r.angle = table.angle_logged ? logged : NAN;
      r.rate = rate;
      table_sink(r);
      logged_previous = logged;
      first_record = false;
    }
    const bool in_gap = table.gap_period > 0.0 && std::fmod(t, table.gap_period) > table.gap_period - table.gap_length;
    const bool dropped = table.drop_fraction > 0.0 && drops.uniform() < table.drop_fraction;
    const double measured = theta + g.noise * noise.next();
    if (!in_gap && !dropped) wave_sink(stamp, measured, frequency(t));
    // RK4 of (theta, phi) together: phi is the table angle actually turned.
    const double w1 = next_rate, w2 = tableRate(t + h / 2), w4 = tableRate(t + h);
    next_rate = w4;
    const double k1 = thetaRate(t, theta, w1), k2 = thetaRate(t + h / 2, theta + h / 2 * k1, w2),
                 k3 = thetaRate(t + h / 2, theta + h / 2 * k2, w2), k4 = thetaRate(t + h, theta + h * k3, w4);
    theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
    phi += h / 6 * (w1 + 4 * w2 + w4);
    if (g.angle_random_walk > 0.0) theta += g.angle_random_walk * std::sqrt(h) * noise.next();
    if (g.bias_random_walk > 0.0) bias_walk += g.bias_random_walk * std::sqrt(h) * bias_noise.next();
  }
}

/// The same with table_sink(stamp, angle, rate).
inline void runTableSession(const AngleLevelGyro& g, const TableImperfections& table, const TurntableProfile& profile,
                            const std::function<void(Nanoseconds, double, double)>& table_sink,
                            const std::function<void(Nanoseconds, double, double)>& wave_sink) {
  runTableSession(
      g, table, profile, [&](const TableRecord& r) { table_sink(r.stamp, r.angle, r.rate); }, wave_sink);
}

inline CalibrationOutcome calibrateTableSession(const AngleLevelGyro& g, const TableImperfections& table,
                                                const TurntableProfile& profile, const CalibrationSettings& settings,
                                                const GyroParameters& prior) {
  CalibrationSession session(settings, prior);
  runTableSession(
      g, table, profile, [&](const TableRecord& r) { session.addRotationRecord(r.stamp, r.angle, r.rate, r.seq); },
      [&](Nanoseconds t, double theta, double frequency) { session.addWave(t, theta, frequency); });
  return session.finish();
}

/// A dual-rate profile in the Thue-Morse order of its plateaus (w1 w2 w2 w1 w2 w1 w1 w2 ...): a
/// linear bias trend cancels over every four plateaus, a quadratic over every eight.
inline TurntableProfile balancedDualRateProfile(double w1, double w2, double duration, int plateaus) {
  TurntableProfile p;
  p.append(5.0, 0.0, 0.0, "start");
  for (int i = 0; i < plateaus; ++i) {
    const double w = __builtin_popcount(static_cast<unsigned>(i)) % 2 == 0 ? w1 : w2;
    const double from = p.finalRate();
    if (w != from) p.append(std::abs(w - from) / 0.5, from, w > from ? 0.5 : -0.5, "ramp");
    p.append(duration, w, 0.0, "plateau");
  }
  const double from = p.finalRate();
  p.append(std::abs(from) / 0.5, from, from > 0 ? -0.5 : 0.5, "ramp");
  p.append(25.0, 0.0, 0.0, "rest");
  return p;
}

/// Peak of |K_estimated(theta) - K_true(theta)| / |K0_true| over theta, ppm.
inline double peakErrorPpm(const HarmonicModel& estimated, const HarmonicModel& truth) {
  double peak = 0.0;
  for (int i = 0; i < 720; ++i) {
    const double theta = i * kPi / 720;
    peak = std::max(peak, std::abs(estimated(theta) - truth(theta)));
  }
  return 1e6 * peak / std::abs(truth.meanAt(NAN));
}

inline CalibrationOutcome calibrateAngleLevel(const AngleLevelGyro& g, const TurntableProfile& profile,
                                              const CalibrationSettings& settings, const GyroParameters& prior,
                                              SessionCounters* counters = nullptr) {
  CalibrationSession session(settings, prior);
  runAngleLevel(g, profile, [&](Nanoseconds t, double angle, double rate, double theta, double frequency) {
    session.addRotationRecord(t, angle, rate);
    session.addWave(t, theta, frequency);
  });
  if (counters) *counters = session.counters();
  return session.finish();
}

inline TurntableProfile dualRateProfile(double w1, double w2, double duration, int repeat = 1) {
  TurntableProfile p;
  p.append(5.0, 0.0, 0.0, "start");
  for (int r = 0; r < repeat; ++r) {
    for (double w : {w1, w2}) {
      const double from = p.finalRate();
      p.append(std::abs(w - from) / 0.5, from, w > from ? 0.5 : -0.5, "ramp");
      p.append(duration, w, 0.0, "plateau");
    }
  }
  const double from = p.finalRate();
  p.append(std::abs(from) / 0.5, from, from > 0 ? -0.5 : 0.5, "ramp");
  p.append(25.0, 0.0, 0.0, "rest");
  return p;
}

}  // namespace testing
}  // namespace core
}  // namespace hrg_gyro
