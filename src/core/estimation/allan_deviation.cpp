#include "hrg_gyro/core/estimation/allan_deviation.h"

#include <algorithm>
#include <cmath>

namespace hrg_gyro {
namespace core {
namespace {

constexpr std::uint64_t kMinClusters = 9;

// Longest run of consecutive curve points whose local log-log slope is within tol of `slope`.
NoiseReading readSlope(const std::vector<AllanPoint>& c, double slope, double tol, double coefficient_at_1s) {
  // Points of fewer than kMinClusters clusters scatter by more than ~25 %: they are plotted, not read.
  NoiseReading best;
  std::size_t best_len = 0;
  std::size_t usable = 0;
  while (usable < c.size() && c[usable].clusters >= kMinClusters) ++usable;
  for (std::size_t i = 0; i + 1 < usable;) {
    std::size_t j = i;
    while (j + 1 < usable) {
      const double s = std::log(c[j + 1].deviation / c[j].deviation) / std::log(c[j + 1].tau / c[j].tau);
      if (std::abs(s - slope) > tol) break;
      ++j;
    }
    if (j > i && j - i + 1 > best_len && c[j].tau / c[i].tau >= 3.0) {
      best_len = j - i + 1;
      // Least-squares intercept of log sigma = log A + slope log tau over the run.
      double sum = 0.0;
      for (std::size_t k = i; k <= j; ++k) sum += std::log(c[k].deviation) - slope * std::log(c[k].tau);
      best.identified = true;
      best.value = std::exp(sum / (j - i + 1)) * coefficient_at_1s;
      best.tau_min = c[i].tau;
      best.tau_max = c[j].tau;
    }
    i = std::max(j, i + 1);
  }
  return best;
}

}  // namespace

AllanResult allanDeviation(const std::vector<double>& angle, double tau0, int points_per_decade) {
  AllanResult r;
  const std::size_t n = angle.size();
  if (n < 5 || !(tau0 > 0.0)) return r;
  std::vector<std::size_t> ms;
  for (double e = 0.0;; e += 1.0 / points_per_decade) {
    const std::size_t m = static_cast<std::size_t>(std::round(std::pow(10.0, e)));
    if (2 * m >= n) break;
    if (ms.empty() || m != ms.back()) ms.push_back(m);
  }
  for (std::size_t m : ms) {
    const std::size_t terms = n - 2 * m;
    double sum = 0.0;
    for (std::size_t k = 0; k < terms; ++k) {
      const double d = angle[k + 2 * m] - 2.0 * angle[k + m] + angle[k];
      sum += d * d;
    }
    const double tau = m * tau0;
    AllanPoint p;
    p.tau = tau;
    p.deviation = std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(terms)));
    p.clusters = n / m;
    p.error = p.deviation / std::sqrt(2.0 * std::max<double>(1.0, static_cast<double>(n / m) - 1.0));
    r.curve.push_back(p);
  }
  // Readings: the coefficient turns the fitted amplitude at tau = 1 s into the noise parameter.
  r.angle_white_noise = readSlope(r.curve, -1.0, 0.15, 1.0 / std::sqrt(3.0));
  r.angle_random_walk = readSlope(r.curve, -0.5, 0.15, 1.0);
  // Bias instability: the flat bottom of the curve.
  NoiseReading flat = readSlope(r.curve, 0.0, 0.1, 1.0);
  if (flat.identified) {
    double lowest = INFINITY;
    for (const AllanPoint& p : r.curve) {
      if (p.tau >= flat.tau_min && p.tau <= flat.tau_max) lowest = std::min(lowest, p.deviation);
    }
    flat.value = lowest / 0.664;
  }
  r.bias_instability = flat;
  // The +1/2 line reaches sigma = K at tau = 3 s: K is sqrt(3) times its amplitude at 1 s.
  r.rate_random_walk = readSlope(r.curve, 0.5, 0.15, std::sqrt(3.0));
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
