// The variance of one axis's compensated rate, as the processor reports it in its Imu message:
// either a configured value or measured online from the output's own white angle noise.
//
// White angle noise of variance s^2 per sample gives second differences of alpha of variance
// 6 s^2, and a per-sample rate (an angle difference over dt) of variance 2 s^2 / dt^2. The second
// differences are averaged (running mean, then exponential over ~1000 outputs); only three
// continuous alphas make one, but the estimate survives gaps and resets. Until 200 of them have
// been seen the initial variance stands. The processor node and the offline triad tool both run
// this object, so the triad's covariance offline is the live one bit for bit.
#pragma once

#include <cstdint>

namespace hrg_gyro {
namespace core {

struct RateNoiseSettings {
  /// (rad/s)^2. Positive: reported as given. Negative: measured. 0 is refused (a perfect gyro).
  double configured_variance = -1.0;
  /// (rad/s)^2, > 0: reported until the measured noise has settled.
  double initial_variance = 1e-4;
  /// Throws ConfigError (yaml_field.h) named after the processor's parameters
  /// (angular_velocity_variance, initial_angular_velocity_variance).
  void validate() const;
};

class RateNoiseEstimator {
 public:
  /// Second differences before the measured noise is trusted (1 s at 200 Hz).
  static constexpr std::uint64_t kSettledDifferences = 200;
  /// Floor of the measured variance, (1e-6 rad/s)^2: a noiseless input (a simulation without
  /// noise) must still not claim a perfect measurement, which filters read as infinitely certain.
  static constexpr double kMinimumVariance = 1e-12;

  explicit RateNoiseEstimator(const RateNoiseSettings& settings = RateNoiseSettings());

  /// One output of the processor: its integrated alpha (rad), dt (s) and flags (GyroOutput's).
  /// A gap or reset breaks the run of continuous alphas, and so does an output flagged PRECESSING
  /// (alpha then turns with the commanded rate, whose steps are no noise of the gyro's).
  void add(double alpha, double dt, std::uint8_t flags);
  /// The variance of the rate of the latest output, (rad/s)^2: never 0, never NaN.
  double variance() const;
  std::uint64_t secondDifferences() const { return second_differences_; }

 private:
  RateNoiseSettings settings_;
  double alpha1_ = 0.0, alpha2_ = 0.0, dt_last_ = 0.0, d2_variance_ = 0.0;
  int history_ = 0;  // continuous alphas held (0..2)
  std::uint64_t second_differences_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
