// Test support: a fast angle-level session (no pickoffs, no demodulation) -- the wave angle obeys
// d theta = K(theta) (Omega_table + Omega_E) dt + D(theta) dt, sampled at `rate_hz` with white
// noise -- fed into a calibration session together with the turntable states. K and D may depend
// on the resonator frequency, given as a function of time (a temperature ramp at angle level).
#pragma once

#include <functional>

#include "hrg_gyro/core/calibration/calibration_session.h"
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

inline CalibrationOutcome calibrateAngleLevel(const AngleLevelGyro& g, const TurntableProfile& profile,
                                              const CalibrationSettings& settings, const GyroParameters& prior,
                                              SessionCounters* counters = nullptr) {
  CalibrationSession session(settings, prior);
  runAngleLevel(g, profile, [&](Nanoseconds t, double angle, double rate, double theta, double frequency) {
    session.addTurntable(t, angle, rate);
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
