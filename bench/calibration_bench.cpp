// Calibration throughput and memory on a long session: HOURS of wave and turntable samples at RATE
// Hz (default 24 h at 1 kHz = 86.4 M samples each) fed into the dual-rate CalibrationSession, the
// object `hrg_bag calibrate` and the calibrator node use. The streams are synthesised in-process
// (theta integrated through an injected K(theta), D(theta) with white angle noise): simulating them
// at signal level would take the simulator an hour, and a bag of them would be ~15 GB. Prints the
// wall time, the session throughput and the peak RSS at each 1/8 of the session (flat memory), then
// the outcome and its agreement with the injected model.
//   hrg_gyro_calibration_bench [HOURS] [RATE]
#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

using namespace hrg_gyro::core;

namespace {

double peakRssMiB() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss / 1024.0;  // kB on Linux
}

}  // namespace

int main(int argc, char** argv) {
  const double hours = argc > 1 ? std::atof(argv[1]) : 24.0;
  const double rate = argc > 2 ? std::atof(argv[2]) : 1000.0;
  if (!(hours > 0.0) || !(rate >= 100.0)) {
    std::fprintf(stderr, "usage: hrg_gyro_calibration_bench [HOURS > 0] [RATE >= 100 Hz]\n");
    return 2;
  }
  const double dt = 1.0 / rate, duration = hours * 3600.0;
  const auto samples = static_cast<long long>(duration * rate);
  // Injected model: K0 -0.56 with 2 and 4 theta terms, D with a 2 theta term.
  const HarmonicModel k({2, 4}, -0.56, {-2e-4, 1e-4}, {1.5e-4, 0.0});
  const HarmonicModel d({2}, 1e-5, {2e-5}, {-1e-5});
  GyroParameters prior;
  prior.earth_rate.enabled = true;
  prior.earth_rate.latitude = 0.9;
  const double earth = prior.earth_rate.verticalRate();
  CalibrationSettings settings;
  settings.auto_finish_idle = 0.0;
  CalibrationSession session(settings, prior);

  // Table: +-0.05 rad/s plateaus of 226 s (a 2 pi sweep of theta) joined by 0.2 s ramps.
  const double plateau = 226.0, ramp = 0.2, omega = 0.05;
  GaussianNoise noise(7);
  double theta = 0.2, angle = 0.0;
  const auto start = std::chrono::steady_clock::now();
  std::printf("calibration_bench: %.1f h at %.0f Hz = %lld samples per stream, dual_rate session\n", hours, rate,
              samples);
  std::printf("  %-10s %-12s %-14s %s\n", "session", "wall (s)", "samples/s", "peak RSS (MiB)");
  for (long long i = 0; i < samples; ++i) {
    const double t = i * dt;
    const double phase = std::fmod(t, 2.0 * (plateau + ramp));
    const double sign = phase < plateau + ramp ? 1.0 : -1.0;
    const double into = std::fmod(phase, plateau + ramp);
    const double table = into < ramp ? sign * omega * (2.0 * into / ramp - 1.0) : sign * omega;
    angle += table * dt;
    theta += (k(theta) * (table + earth) + d(theta)) * dt;
    const Nanoseconds stamp = toNanoseconds(1.0 + t);
    session.addRotationRecord(stamp, angle, table);
    session.addWave(stamp, theta + 1e-6 * noise.next(), 5000.0);
    if ((i + 1) % (samples / 8) == 0) {
      const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::printf("  %6.1f h   %-12.1f %-14.3g %.1f\n", (t + dt) / 3600.0, wall, (i + 1) / wall, peakRssMiB());
      std::fflush(stdout);
    }
  }
  const auto fit_start = std::chrono::steady_clock::now();
  const CalibrationOutcome o = session.finish();
  const double fit = std::chrono::duration<double>(std::chrono::steady_clock::now() - fit_start).count();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const HarmonicModel& kf = o.parameters.scale_factor;
  double worst = 0.0;
  for (int j = 0; j < 360; ++j) {
    const double th = M_PI * j / 360.0;
    worst = std::max(worst, std::abs(kf(th) - k(th)) / 0.56);
  }
  std::printf("outcome: %s%s%s; K error vs injected %.3f ppm peak; fit %.3f s\n", o.accepted ? "ACCEPTED" : "REFUSED",
              o.accepted ? "" : ": ", o.accepted ? "" : o.reason.c_str(), 1e6 * worst, fit);
  std::printf("total: %.1f s wall, %.3g samples/s per stream, peak RSS %.1f MiB\n", wall, samples / wall, peakRssMiB());
  return o.accepted ? 0 : 1;
}
