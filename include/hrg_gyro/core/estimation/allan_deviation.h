// Overlapping Allan deviation of a gyro's rate from its integrated angle (IEEE Std 952 style).
//
// With angle samples theta_k every tau0 (uniform), the overlapping Allan variance at
// tau = m tau0 is
//   sigma^2(tau) = sum_k (theta_{k+2m} - 2 theta_{k+m} + theta_k)^2 / (2 tau^2 (N - 2m)),
// computed on a logarithmic grid of m. The readings follow the standard slopes of a log-log plot:
//   slope -1    angle (quantisation) white noise Q:   sigma = sqrt(3) Q / tau
//   slope -1/2  angle random walk N:                  sigma = N / sqrt(tau)   (read at tau = 1 s)
//   slope  0    bias instability B:                   sigma_min = 0.664 B
//   slope +1/2  rate random walk K:                   sigma = K sqrt(tau / 3)  (read at tau = 3 s)
// A reading is reported only where the curve shows that slope (within tolerance) over at least a
// factor of 3 in tau; otherwise it is marked as not identified rather than guessed.
#pragma once

#include <cstdint>
#include <vector>

namespace hrg_gyro {
namespace core {

struct AllanPoint {
  double tau = 0.0;        ///< s
  double deviation = 0.0;  ///< rad/s
  double error = 0.0;      ///< 1-sigma of the deviation from the number of independent clusters
  std::uint64_t clusters = 0;
};

struct NoiseReading {
  bool identified = false;
  double value = 0.0;                   ///< Q (rad), N (rad/sqrt(s)), B (rad/s) or K (rad/s/sqrt(s))
  double tau_min = 0.0, tau_max = 0.0;  ///< s, range of the curve it was read from
};

struct AllanResult {
  std::vector<AllanPoint> curve;
  NoiseReading angle_white_noise;  ///< Q
  NoiseReading angle_random_walk;  ///< N
  NoiseReading bias_instability;   ///< B
  NoiseReading rate_random_walk;   ///< K
};

/// `angle` sampled every `tau0` seconds; `points_per_decade` of the tau grid.
AllanResult allanDeviation(const std::vector<double>& angle, double tau0, int points_per_decade = 8);

}  // namespace core
}  // namespace hrg_gyro
