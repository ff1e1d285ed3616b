#include "hrg_gyro/core/calibration/dual_rate_method.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "hrg_gyro/core/calibration/outcome_from_fits.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/earth_rate.h"

namespace hrg_gyro {
namespace core {

DualRateMethod::DualRateMethod(const CalibrationSettings& s, double k0)
    : settings_(s),
      groups_(s.bins, s.window, s.window_span, k0, maxFittedOrder(s.scale_factor_orders, s.drift_orders),
              s.group_tolerance, s.plateau.max_gap),
      regression_(s.scale_factor_orders, s.drift_orders, s.bins, s.bias_trend_order),
      chains_(s, maxFittedOrder(s.scale_factor_orders, s.drift_orders), k0) {}

void DualRateMethod::addSample(const PlateauSample& s) {
  // A non-finite angle would poison every sum of the regression: such a sample is not data.
  if (s.plateau.is_static || !std::isfinite(s.theta) || !std::isfinite(s.rotation_angle) ||
      !std::isfinite(s.rotation_rate))
    return;
  groups_.add(s.stamp, s.theta, s.theta, s.plateau.id, s.plateau.rate, s.rotation_rate);
  ++samples_;
  if (chains_.follow(s, &regression_)) {
    unwrap_ = 0.0;
    rate_integral_ = 0.0;
  } else {
    rate_integral_ += 0.5 * (s.rotation_rate + last_table_rate_) * chains_.sinceLast();
    // A controller may log its angle modulo 2 pi: unwrap it.
    const double step = s.rotation_angle + unwrap_ - last_table_angle_;
    if (step > kPi) unwrap_ -= 2.0 * kPi;
    if (step < -kPi) unwrap_ += 2.0 * kPi;
  }
  const double angle = s.rotation_angle + unwrap_;
  regression_.setAngleSmoothError(s.angle_smooth_error);
  // The logged rate's integral too, where the angle is logged: the regression weighs the two by
  // their noise (without an angle, the angle is that integral already).
  regression_.add(s.stamp, s.theta, angle, s.angle_logged ? rate_integral_ : NAN,
                  s.horizontal_slot < regression_.horizontalSlots() ? s.horizontal_slot : -1, s.horizontal_phase);
  angle_logged_ = s.angle_logged;
  last_table_angle_ = angle;
  last_table_rate_ = s.rotation_rate;
}

bool DualRateMethod::modelHorizontalEarthRate(int slots) {
  if (samples_ > 0) throw std::logic_error("dual-rate method: the horizontal Earth rate is modelled from the start");
  regression_ = IncrementRegression(settings_.scale_factor_orders, settings_.drift_orders, settings_.bins,
                                    settings_.bias_trend_order, slots);
  return true;
}

bool DualRateMethod::complete() const { return progress().fraction >= 1.0; }

CalibrationProgress DualRateMethod::progress() const {
  CalibrationProgress p;
  const auto order = groups_.byDuration();
  std::ostringstream s;
  s << "dual_rate: " << groups_.groups().size() << " rate group(s)";
  double worst = order.size() >= 2 ? 1.0 : 0.0;
  for (std::size_t i = 0; i < order.size() && i < 2; ++i) {
    const RateGroup& g = groups_.groups()[order[i]];
    const double cov = g.rates().coverage(minBinTime(g.meanRate()));
    worst = std::min(worst, cov);
    s << ", " << formatShort(g.meanRate()) << " rad/s: coverage " << formatShort(100 * cov) << " %";
  }
  p.fraction = order.size() >= 2 ? std::min(1.0, worst / settings_.gates.min_coverage) : 0.0;
  p.summary = s.str();
  return p;
}

void DualRateMethod::noteErrorBudget(const IncrementFit& e, CalibrationOutcome* o) const {
  auto largest = [&](const std::vector<double>& v) {
    double m = 0.0;
    for (std::size_t i = 1; i < v.size(); ++i) m = std::max(m, v[i]);
    return formatShort(1e6 * m / std::abs(e.k.mean));
  };
  o->notes.push_back(
      "K harmonic standard errors, ppm of |K0| (largest of each kind): statistical " + largest(e.budget.statistical) +
      " (white wave-angle noise alone " + largest(e.budget.angle_noise) + ", beyond it " +
      largest(e.budget.beyond_noise) + (e.walk.carried ? ", bias random walk " + largest(e.budget.bias_walk) : "") +
      "), Earth rate " + largest(e.budget.earth_rate) + ", basis-noise correction " + largest(e.budget.basis_noise) +
      "; phi from the " +
      (angle_logged_ ? (e.angle_weight >= 1.0 ? std::string("logged table angle")
                                              : "logged table angle weighted " + formatShort(e.angle_weight, 2) +
                                                    " against the logged rate's integral")
                     : std::string("integrated table rate")) +
      ", window " + formatShort(e.mean_window) + " s, angle noise " + formatShort(e.angle_noise) + " rad, " +
      std::to_string(e.increments) + " increments in " + std::to_string(e.blocks) + " blocks");
}

void DualRateMethod::gateBiasTrend(const IncrementFit& e, CalibrationOutcome* o) const {
  // A trend the session cannot tell from K0 leaves K0 to the trend's guess. The trend costs K0
  // precision in any session (how much is the inflation of its standard error); refused only when
  // it costs much (max_trend_inflation) and leaves K0 poorly known (max_trend_k0_std of |K0|).
  const QualityLimits& q = settings_.gates;
  const BiasTrendFit& t = e.trend;
  o->bias_trend = t;
  const double per_hour = 3600.0;
  const double k0_std = e.k.mean_std / std::abs(e.k.mean);
  const bool separable = t.k0_inflation <= q.max_trend_inflation || k0_std <= q.max_trend_k0_std;
  const std::string fitted = "bias trend " + formatShort(t.coefficients.front() * per_hour, 3) + " +- " +
                             formatShort(t.stds.front() * per_hour, 2) + " rad/s per hour (" +
                             formatShort(t.coefficients.front() * t.span, 3) + " rad/s over the " +
                             formatShort(t.span, 4) + " s of data)";
  const std::string confusion = "K0's standard error x" + formatShort(t.k0_inflation, 3) + " to " +
                                formatShort(k0_std * 1e6, 3) + " ppm, correlation " + formatShort(t.k0_correlation, 2);
  o->gate("bias_trend", separable, t.k0_inflation, q.max_trend_inflation,
          separable ? fitted + ", fitted with K and D (" + confusion + ")"
                    : "the session cannot separate a bias trend from K0 (" + confusion + ", limits x" +
                          formatShort(q.max_trend_inflation, 3) + " and " + formatShort(q.max_trend_k0_std * 1e6, 3) +
                          " ppm): order the plateau rates so that a linear trend cancels (+ - - + - + + -), or set "
                          "bias_trend_order: 0 if the bias is known to be stable");
}

void DualRateMethod::gateTableError(const IncrementFit& e, CalibrationOutcome* o) const {
  // The gate judges the table by its effect on K: what the data scatter beyond the white wave-angle
  // noise, all charged to the table angle (or the rate integral) as an upper estimate -- angle random
  // walk and drift the model lacks land there too.
  const QualityLimits& q = settings_.gates;
  double beyond = 0.0;
  for (std::size_t i = 1; i < e.budget.beyond_noise.size(); ++i) beyond = std::max(beyond, e.budget.beyond_noise[i]);
  beyond /= std::abs(e.k.mean);
  o->gate("table_error", beyond <= q.max_table_error, beyond, q.max_table_error,
          std::string(angle_logged_ ? "table angle" : "integrated table rate (no angle logged)") +
              " errors add at most " + formatShort(beyond * 1e6) +
              " ppm of |K0| to a K harmonic (scatter beyond the wave-angle noise)");
}

CalibrationOutcome DualRateMethod::finish(const GyroParameters& prior) const {
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  const auto order = groups_.byDuration();
  for (std::size_t i : order) {
    const RateGroup& g = groups_.groups()[i];
    o.plateaus.push_back(summarizeGroup(g, minBinTime(g.meanRate())));
  }
  o.samples = samples_;
  o.gate("samples", samples_ >= q.min_samples, static_cast<double>(samples_), static_cast<double>(q.min_samples),
         std::to_string(samples_) + " wave samples on moving plateaus");
  if (order.size() < 2) {
    o.gate("plateau_groups", false, static_cast<double>(order.size()), 2.0,
           "need plateaus at two distinct table rates, found " + std::to_string(order.size()));
    o.decide();
    return o;
  }
  const RateGroup& g1 = groups_.groups()[order[0]];
  const RateGroup& g2 = groups_.groups()[order[1]];
  const double w1 = g1.meanRate(), w2 = g2.meanRate();
  o.duration = g1.rates().totalTime() + g2.rates().totalTime();
  o.coverage = std::min(g1.rates().coverage(minBinTime(w1)), g2.rates().coverage(minBinTime(w2)));
  o.gate("coverage", o.coverage >= q.min_coverage, o.coverage, q.min_coverage,
         "theta bins covered by both plateaus: " + formatShort(100 * o.coverage) + " %");
  o.gate("rate_separation", std::abs(w1 - w2) >= q.min_rate_separation, std::abs(w1 - w2), q.min_rate_separation,
         "plateau rates " + formatShort(w1) + " and " + formatShort(w2) + " rad/s");
  // The Earth rate's uncertainty: the latitude taken as known to 0.01 degree.
  const double earth = prior.earth_rate.verticalRate();
  const double earth_std =
      prior.earth_rate.enabled ? std::abs(horizontalEarthRate(prior.earth_rate.latitude)) * 0.01 * kPi / 180 : 0.0;
  // One threshold for the bins of both groups: the longer of their windows' quarters.
  const IncrementFit e = regression_.solve(earth, earth_std, std::max(minBinTime(w1), minBinTime(w2)), q.max_condition);
  if (!e.ok) {
    o.gate("fit", false, 0.0, 0.0, e.reason);
    o.decide();
    return o;
  }
  o.binned = e.binned;
  o.bias_walk = e.walk;
  o.horizontal_earth = e.horizontal;
  noteErrorBudget(e, &o);    // stated in the report
  o.smoothing_factor = 1.0;  // nothing is smoothed: the increments are fitted through their exact integrals
  if (e.trend.order > 0) gateBiasTrend(e, &o);
  gateTableError(e, &o);
  // Paper-style bound per bin: K changing over one window, plus the angle noise of the two window
  // means at each end of a bin (drift cancels in this method).
  const double tau = std::max(g1.rates().effectiveWindow(), g2.rates().effectiveWindow());
  const double sigma = std::max(g1.rates().windowNoise(), g2.rates().windowNoise());
  o.error_bound = slopeBound(e.k) * std::abs(e.k.mean) * std::max(std::abs(w1), std::abs(w2)) * tau +
                  2.0 * std::sqrt(2.0) * sigma / (std::abs(w1 - w2) * tau);
  finishScaleFactorAndDrift(&o, e.k, e.d, prior, q);
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
