#include "hrg_gyro/core/calibration/constant_rate_method.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/calibration/outcome_from_fits.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"

namespace hrg_gyro {
namespace core {

ConstantRateMethod::ConstantRateMethod(const CalibrationSettings& s, double k0)
    : settings_(s),
      groups_(s.bins, s.window, s.window_span, k0, maxFittedOrder(s.scale_factor_orders, s.drift_orders),
              s.group_tolerance, s.plateau.max_gap) {}

void ConstantRateMethod::closeDwell() {
  if (dwell_.samples() >= 3 && dwell_.duration() > 0.0) {
    const double w = dwell_.duration();
    rest_weighted_slope_ += w * dwell_.slope();
    rest_weight_ += w;
    rest_time_ += dwell_.duration();
    rest_noise_ = std::max(rest_noise_, dwell_.residualStd());
  }
  dwell_ = DwellFit();
}

void ConstantRateMethod::addSample(const PlateauSample& s) {
  ++samples_;
  if (s.plateau.is_static) {
    if (s.plateau.id != dwell_plateau_) {
      closeDwell();
      dwell_plateau_ = s.plateau.id;
    }
    dwell_.add(s.stamp, s.theta, s.rotation_angle);
    return;
  }
  groups_.add(s.stamp, s.theta, s.theta, s.plateau.id, s.plateau.rate, s.rotation_rate);
}

double ConstantRateMethod::dwellTime() const { return rest_time_ + dwell_.duration(); }

bool ConstantRateMethod::complete() const { return progress().fraction >= 1.0; }

CalibrationProgress ConstantRateMethod::progress() const {
  CalibrationProgress p;
  const auto order = groups_.byDuration();
  const double cov = order.empty() ? 0.0 : groups_.groups()[order[0]].rates().coverage(minBinTime());
  const double dwell = dwellTime();
  p.fraction =
      std::min(std::min(1.0, cov / settings_.gates.min_coverage),
               settings_.gates.min_dwell_time > 0 ? std::min(1.0, dwell / settings_.gates.min_dwell_time) : 1.0);
  p.summary = "constant_rate: coverage " + formatShort(100 * cov) + " %, rest data " + formatShort(dwell) + " s";
  return p;
}

CalibrationOutcome ConstantRateMethod::finish(const GyroParameters& prior) const {
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  o.samples = samples_;
  o.gate("samples", samples_ >= q.min_samples, static_cast<double>(samples_), static_cast<double>(q.min_samples),
         std::to_string(samples_) + " wave samples on plateaus");
  // Rest rate from every dwell including the open one.
  double wsum = rest_weight_, ssum = rest_weighted_slope_;
  if (dwell_.samples() >= 3 && dwell_.duration() > 0.0) {
    wsum += dwell_.duration();
    ssum += dwell_.duration() * dwell_.slope();
  }
  const double dwell = dwellTime();
  o.gate("dwell_time", dwell >= q.min_dwell_time, dwell, q.min_dwell_time,
         formatShort(dwell) + " s at rest to measure the rest rate K Omega_E + D");
  const auto order = groups_.byDuration();
  if (order.empty() || wsum <= 0.0) {
    o.gate("data", false, 0.0, 1.0, order.empty() ? "no constant-rate plateau" : "no dwell at rest");
    o.decide();
    return o;
  }
  const RateGroup& g = groups_.groups()[order[0]];
  for (std::size_t i : order) o.plateaus.push_back(summarizeGroup(groups_.groups()[i], minBinTime()));
  const double rest = ssum / wsum, w = g.meanRate();
  o.duration = g.rates().totalTime() + dwell;
  o.coverage = g.rates().coverage(minBinTime());
  o.gate("coverage", o.coverage >= q.min_coverage, o.coverage, q.min_coverage,
         "theta bins covered: " + formatShort(100 * o.coverage) + " %");
  o.gate("rate", std::abs(w) >= q.min_rate_separation, std::abs(w), q.min_rate_separation,
         "plateau rate " + formatShort(w) + " rad/s");
  const double noise = g.rateStd() / std::abs(w);
  o.gate("rate_noise", noise <= q.max_rate_noise, noise, q.max_rate_noise,
         "reported table rate scatters by " + formatShort(100 * noise) + " %");
  HarmonicFitResult fit = fitBinnedRates(g.rates(), settings_.scale_factor_orders, minBinTime());
  if (!fit.ok) {
    o.gate("fit", false, 0.0, 0.0, fit.reason);
    o.decide();
    return o;
  }
  o.smoothing_factor = fit.smallest_attenuation;
  // r(theta) = K(theta) (Omega + Omega_E) + D(theta) and r_rest = K(theta_d) Omega_E + D(theta_d).
  // Mean: K0 = (r0 - r_rest) / Omega. Harmonics: K_k = r_k / (Omega + Omega_E) -- the Earth rate is
  // a body rotation scaled by K (dividing by Omega alone, as the paper does, inflates them by
  // Omega_E / Omega). D(theta) - D(theta_d) still leaks into K by D_k / (Omega + Omega_E), the known
  // weakness of this method.
  const double earth = prior.earth_rate.verticalRate();
  HarmonicFitResult k = fit;
  k.mean = (fit.mean - rest) / w;
  k.mean_std = fit.mean_std / std::abs(w);
  for (std::size_t j = 0; j < k.orders.size(); ++j) {
    k.cos[j] /= w + earth;
    k.sin[j] /= w + earth;
    k.cos_std[j] /= std::abs(w + earth);
    k.sin_std[j] /= std::abs(w + earth);
  }
  k.residual_rms = fit.residual_rms / std::abs(w + earth);
  for (int b = 0; b < g.rates().binCount(); ++b) {
    if (g.rates().binTime(b) < minBinTime()) continue;
    o.binned.push_back(
        {g.rates().binCenter(b), k.mean + (g.rates().binRate(b) - fit.mean) / (w + earth), 0.0, g.rates().binTime(b)});
  }
  HarmonicFitResult d;
  d.ok = true;
  d.mean = rest - k.mean * earth;
  d.points = 1;
  o.notes.push_back(
      "constant_rate measures D only at the dwell angle: D(theta) harmonics are not separable from "
      "K(theta) and leak into it by D_k / Omega; the drift model written is the constant D0");
  const double tau = g.rates().effectiveWindow();
  o.error_bound = slopeBound(k) * std::abs(k.mean) * std::abs(w) * tau + std::abs(d.mean) / std::abs(w) +
                  2.0 * g.rates().windowNoise() / (std::abs(w) * tau);
  finishScaleFactorAndDrift(&o, k, d, prior, q);
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
