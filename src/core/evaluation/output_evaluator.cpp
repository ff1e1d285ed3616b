#include "hrg_gyro/core/evaluation/output_evaluator.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/estimation/binned_rate_fit.h"
#include "hrg_gyro/core/model/harmonic_basis.h"

namespace hrg_gyro {
namespace core {

OutputEvaluator::OutputEvaluator(const EvaluationSettings& settings)
    : settings_(settings),
      detector_(settings.plateau),
      groups_(settings.bins, settings.window, settings.window_span, settings.k0, settings.orders.back(),
              settings.group_tolerance, settings.plateau.max_gap) {}

void OutputEvaluator::add(Nanoseconds stamp, double theta_mid, double alpha, double table_rate, double inertial_angle,
                          double inertial_rate) {
  if (!started_) {
    started_ = true;
    first_stamp_ = stamp;
    alpha0_ = alpha;
    truth0_ = inertial_angle;
  }
  last_stamp_ = stamp;
  ++samples_;
  if (block_n_ == 0) block_start_ = stamp;
  block_sum_ += (alpha - alpha0_) - (inertial_angle - truth0_);
  if (++block_n_ > 0 && toSeconds(stamp - block_start_) >= settings_.angle_error_window) {
    const double e = block_sum_ / static_cast<double>(block_n_);
    error_max_ = std::max(error_max_, std::abs(e));
    error_sq_ += e * e;
    error_last_ = e;
    ++blocks_;
    block_sum_ = 0.0;
    block_n_ = 0;
  }
  const PlateauState p = detector_.update(stamp, table_rate);
  if (p.settled && !p.is_static) groups_.add(stamp, theta_mid, alpha, p.id, p.rate, inertial_rate);
}

EvaluationResult OutputEvaluator::result() const {
  EvaluationResult r;
  r.samples = samples_;
  r.duration = toSeconds(last_stamp_ - first_stamp_);
  r.angle_error_max = error_max_;
  r.angle_error_rms = blocks_ ? std::sqrt(error_sq_ / blocks_) : 0.0;
  r.angle_error_final = error_last_;
  const auto order = groups_.byDuration();
  if (order.size() < 2) {
    r.reason = "the verification profile needs plateaus at two table rates";
    return r;
  }
  const RateGroup& g1 = groups_.groups()[order[0]];
  const RateGroup& g2 = groups_.groups()[order[1]];
  const BinnedTwoRateFit e = fitBinnedTwoRates(g1.rates(), g1.meanRate(), g2.rates(), g2.meanRate(), settings_.orders,
                                               settings_.orders, 0.25 * settings_.window);
  if (!e.ok) {
    r.reason = e.reason;
    return r;
  }
  r.relative_scale = e.k;
  r.residual_drift = e.d;
  r.scale_error_ppm = 1e6 * (e.k.mean - 1.0);
  // Peak of the fitted deviation and its 1-sigma there (coefficients treated as independent).
  HarmonicBasis basis(2, settings_.orders.back());
  double peak = 0.0, peak_sigma = 0.0;
  const int points = 64 * settings_.orders.back();
  for (int i = 0; i < points; ++i) {
    basis.evaluate(kPi * i / points);
    double dev = 0.0, var = 0.0;
    for (std::size_t j = 0; j < e.k.orders.size(); ++j) {
      const double c = basis.cosOf(e.k.orders[j]), s = basis.sinOf(e.k.orders[j]);
      dev += e.k.cos[j] * c + e.k.sin[j] * s;
      var += std::pow(e.k.cos_std[j] * c, 2) + std::pow(e.k.sin_std[j] * s, 2);
    }
    if (std::abs(dev) > peak) {
      peak = std::abs(dev);
      peak_sigma = std::sqrt(var);
    }
  }
  r.nonlinearity_ppm = 1e6 * peak / std::abs(e.k.mean);
  r.nonlinearity_sigma_ppm = 1e6 * peak_sigma / std::abs(e.k.mean);
  r.ok = true;
  return r;
}

}  // namespace core
}  // namespace hrg_gyro
