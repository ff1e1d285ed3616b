// North-finding: an alignment of a 10 min window at 200 Hz (120,000 triad samples, as many
// accelerometer records; the indexed window also 100 Hz indexer records), from the first record fed to
// the result with its error budget. Part of hrg_gyro_core_bench (`make bench`).
#include <benchmark/benchmark.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "hrg_gyro/core/alignment/gyrocompass.h"
#include "hrg_gyro/core/alignment/local_level.h"
#include "hrg_gyro/core/simulation/base_motion.h"
#include "hrg_gyro/core/simulation/gaussian_noise.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kRate = 200.0, kSeconds = 600.0, kLatitude = 0.9;

struct Window {
  std::vector<TriadBodySample> gyro;
  std::vector<AccelerometerRecord> accelerometer;
  std::vector<IndexerRecord> indexer;

  // Records the triad's increment since `previous` (both integrated angles, rad) and the accelerometer's
  // reading at stamp t (s after the window's start at 10 s); returns the gyro sample.
  const TriadBodySample& record(double t, double h, const Eigen::Vector3d& measured, Eigen::Vector3d* previous,
                                const Eigen::Vector3d& specific_force) {
    TriadBodySample x;
    x.stamp = toNanoseconds(10.0 + t);
    x.dt = h;
    x.delta_angle = measured - *previous;
    x.angular_velocity = x.delta_angle / h;
    *previous = measured;
    gyro.push_back(x);
    accelerometer.push_back(AccelerometerRecord{x.stamp, specific_force});
    return gyro.back();
  }
};

// A mount at yaw 0.3 rad on a base that sways by 1e-4 rad with a 10 s period about East: the body's
// rate integrated over each sample by the midpoint rule on 8 steps (enough for a timing), the
// accelerometer reading gravity through the swaying attitude. The tracking estimator answers.
Window makeSwayingWindow() {
  Window w;
  GaussianNoise noise(2);
  BaseMotionConfig config;
  config.sways.push_back({1e-4, 10.0, Eigen::Vector3d::UnitX(), 0.0});
  const BaseMotion base(config, 2);
  const Eigen::Matrix3d mount = orientationFromEuler(EulerAngles{0.002, -0.001, 0.3}).toRotationMatrix();
  const double h = 1.0 / kRate, white = 4.9e-6 / 0.56;
  const long n = static_cast<long>(kSeconds * kRate);
  Eigen::Vector3d angle = Eigen::Vector3d::Zero(), previous = Eigen::Vector3d::Zero();
  for (long k = 1; k <= n + 1; ++k) {
    const double t = k * h;
    for (int j = 0; j < 8; ++j) {
      Eigen::Matrix3d d;
      Eigen::Vector3d rate;
      base.stateAt(t - h + (j + 0.5) * h / 8.0, &d, &rate);
      angle += (d * mount).transpose() * (earthRateEnu(kLatitude) + rate) * (h / 8.0);
    }
    const Eigen::Vector3d measured = angle + white * Eigen::Vector3d(noise.next(), noise.next(), noise.next());
    const Eigen::Vector3d force = (base.rotationAt(t) * mount).transpose() * Eigen::Vector3d(0, 0, kStandardGravity) +
                                  3.5e-3 * Eigen::Vector3d(noise.next(), noise.next(), noise.next());
    w.record(t, h, measured, &previous, force);
  }
  return w;
}

// A mount at yaw 0.3 rad; indexed: the body at 0 for the first half, then turned to pi in 2 s.
Window makeWindow(bool indexed) {
  Window w;
  GaussianNoise noise(1);
  const Eigen::Matrix3d mount = orientationFromEuler(EulerAngles{0.002, -0.001, 0.3}).toRotationMatrix();
  const Eigen::Vector3d earth = mount.transpose() * earthRateEnu(kLatitude);
  const Eigen::Vector3d gravity = mount.transpose() * Eigen::Vector3d(0, 0, kStandardGravity);
  const double h = 1.0 / kRate, white = 4.9e-6 / 0.56;
  const long n = static_cast<long>(kSeconds * kRate);
  Eigen::Vector3d angle = Eigen::Vector3d::Zero(), previous = Eigen::Vector3d::Zero();
  auto psiAt = [&](double t) {
    if (!indexed || t < 0.5 * kSeconds) return 0.0;
    return std::min(1.0, (t - 0.5 * kSeconds) / 2.0) * kPi;
  };
  for (long k = 1; k <= n + 1; ++k) {
    const double t = k * h, psi0 = psiAt(t - h), psi1 = psiAt(t);
    const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.5 * (psi0 + psi1), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    angle += turn.transpose() * earth * h + Eigen::Vector3d::UnitZ() * (psi1 - psi0);
    const Eigen::Vector3d measured = angle + white * Eigen::Vector3d(noise.next(), noise.next(), noise.next());
    const Eigen::Vector3d force =
        turn.transpose() * gravity + 2e-3 * Eigen::Vector3d(noise.next(), noise.next(), noise.next());
    const TriadBodySample& x = w.record(t, h, measured, &previous, force);
    if (indexed && k % 2 == 0) w.indexer.push_back(IndexerRecord{x.stamp, psi1, (psi1 - psi0) / h});
  }
  return w;
}

void BM_Alignment10MinuteWindow(benchmark::State& state) {
  // 0: static, 1: indexed, 2: static on a swaying base (the tracking estimator answers).
  const bool indexed = state.range(0) == 1, swaying = state.range(0) == 2;
  static const Window windows[3] = {makeWindow(false), makeWindow(true), makeSwayingWindow()};
  const Window& w = windows[state.range(0)];
  AlignmentSettings settings;
  settings.mode = indexed ? AlignmentMode::kIndexed : AlignmentMode::kStatic;
  settings.latitude = kLatitude;
  settings.duration = kSeconds;
  settings.noise.residual_bias = 1e-8;
  // The window's gyros have white angle noise and a bias only; its accelerometer no bias, mounted exactly.
  settings.noise.angle_random_walk = settings.noise.rate_random_walk = settings.noise.residual_drift_harmonics = 0.0;
  settings.level.accelerometer_bias_sigma = settings.level.accelerometer_mounting_sigma = 0.0;
  AlignmentResult result;
  for (auto _ : state) {
    Gyrocompass g(settings);
    for (const IndexerRecord& r : w.indexer) g.addIndexer(r);
    for (std::size_t k = 0; k < w.gyro.size(); ++k) {
      g.addTriad(w.gyro[k]);
      g.addAccelerometer(w.accelerometer[k]);
    }
    result = g.finish();
    // A copy: this Google Benchmark (1.7.1) with GCC, given the member itself, left 0 in it.
    double heading = result.heading;
    benchmark::DoNotOptimize(heading);
  }
  if (!result.accepted) state.SkipWithError(result.summary().c_str());
  state.SetItemsProcessed(static_cast<std::int64_t>(w.gyro.size()) * state.iterations());
  char label[160];
  std::snprintf(label, sizeof label, "%s, %zu triad samples (10 min at 200 Hz): %s, heading %.4f +- %.4f deg",
                indexed   ? "indexed, two positions"
                : swaying ? "static triad on a swaying base"
                          : "static triad",
                w.gyro.size() - 1, result.estimator.c_str(), result.heading, result.heading_sigma);
  state.SetLabel(label);
}
BENCHMARK(BM_Alignment10MinuteWindow)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
