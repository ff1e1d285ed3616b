#include "hrg_gyro/core/calibration/calibration_methods.h"

#include <algorithm>
#include <cmath>
#include <ctime>
#include <sstream>

#include "hrg_gyro/core/calibration/field_method.h"
#include "hrg_gyro/core/calibration/thermal_method.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

/// Upper bound of |dK/dtheta| for a fitted model: sum_k k sqrt(a_k^2 + b_k^2).
double slopeBound(const HarmonicFitResult& f) {
  double s = 0.0;
  for (std::size_t j = 0; j < f.orders.size(); ++j) s += f.orders[j] * std::hypot(f.cos[j], f.sin[j]);
  return s;
}

double maxHarmonicStd(const HarmonicFitResult& f) {
  double m = 0.0;
  for (std::size_t j = 0; j < f.orders.size(); ++j) m = std::max({m, f.cos_std[j], f.sin_std[j]});
  return m;
}

/// The gates every K(theta) estimate must pass, and the parameter update.
void finishModel(CalibrationOutcome* o, const HarmonicFitResult& k, const HarmonicFitResult& d,
                 const GyroParameters& prior, const QualityLimits& q) {
  o->scale_factor = {k};
  o->drift = {d};
  const double k0 = k.mean, k0_prior = prior.scale_factor.meanAt(NAN);
  o->gate("fit_condition", k.condition_number <= q.max_condition, k.condition_number, q.max_condition,
          "harmonic fit condition number " + formatShort(k.condition_number));
  o->gate("k0_sign", k0 < 0.0, k0, 0.0, "estimated K0 = " + formatShort(k0) + " must be negative");
  const double change = std::abs(k0 - k0_prior) / std::abs(k0_prior);
  o->gate("k0_change", change <= q.max_k0_change, change, q.max_k0_change,
          "K0 moved by " + formatShort(100 * change) + " % from the prior " + formatShort(k0_prior));
  const double residual = k.residual_rms / std::abs(k0);
  o->gate("residual", residual <= q.max_relative_residual, residual, q.max_relative_residual,
          "rms of the binned K about the fit is " + formatShort(residual) + " of |K0|");
  const double hstd = maxHarmonicStd(k) / std::abs(k0);
  o->gate("harmonic_std", hstd <= q.max_harmonic_std, hstd, q.max_harmonic_std,
          "largest K harmonic standard error is " + formatShort(hstd * 1e6) + " ppm of |K0|");
  const HarmonicModel k_model = toModel(k);
  o->nonlinearity_ppm = 1e6 * k_model.peakDeviation() / std::abs(k0);
  o->parameters = prior;
  o->parameters.scale_factor = k_model;
  o->parameters.drift = toModel(d);
  o->parameters.calibration.method = ParameterOrigin::calibratedBy(o->method);
  o->parameters.calibration.time = utcNow();
  o->decide();
}

GroupSummary summarize(const RateGroup& g, double min_bin_time) {
  GroupSummary s;
  s.rate = g.meanRate();
  s.rate_std = g.rateStd();
  s.duration = g.rates().totalTime();
  s.samples = g.rates().samples();
  s.coverage = g.rates().coverage(min_bin_time);
  s.turns = g.rates().thetaSwept() / kPi;
  return s;
}

}  // namespace

std::unique_ptr<CalibrationMethod> makeCalibrationMethod(const CalibrationSettings& s, const GyroParameters& prior) {
  const double k0 = std::abs(prior.scale_factor.meanAt(NAN));
  switch (s.method) {
    case CalibrationMethodKind::kDualRate:
      return std::make_unique<DualRateMethod>(s, k0);
    case CalibrationMethodKind::kConstantRate:
      return std::make_unique<ConstantRateMethod>(s, k0);
    case CalibrationMethodKind::kStep:
      return std::make_unique<StepMethod>(s);
    case CalibrationMethodKind::kCorrectionMatrix:
      return std::make_unique<CorrectionMatrixMethod>(s);
    case CalibrationMethodKind::kTriad:
      throw std::invalid_argument(
          "the triad method calibrates three axes at once: give it a triad session (hrg_bag calibrate --method triad "
          "on a bag with the three axes' channels and the fixture's positions, or the calibrator in triad mode)");
    case CalibrationMethodKind::kThermal:
      return std::make_unique<ThermalMethod>(s, k0);
    case CalibrationMethodKind::kField:
      return std::make_unique<FieldMethod>(s);
  }
  throw std::invalid_argument("calibration method out of range");
}

// ------------------------------------------------------------------------------------------------
namespace {}  // namespace

DualRateMethod::DualRateMethod(const CalibrationSettings& s, double k0)
    : settings_(s),
      k0_(k0),
      groups_(s.bins, s.window, s.window_span, k0, maxFittedOrder(s.scale_factor_orders, s.drift_orders),
              s.group_tolerance, s.plateau.max_gap),
      regression_(s.scale_factor_orders, s.drift_orders, s.bins, s.bias_trend_order) {}

double DualRateMethod::windowFor(double table_rate) const {
  // The regression is exact for any window; the window only sets how much of each harmonic the
  // increments keep. The highest order's phase may advance at most 1 rad per window (the increments
  // then keep >= 92 % of it), and the wave angle at most window_span; `window` is the upper bound.
  const int top = maxFittedOrder(settings_.scale_factor_orders, settings_.drift_orders);
  const double sweep = std::abs(k0_ * table_rate);
  const double span = std::min(settings_.window_span, top > 0 ? 1.0 / top : settings_.window_span);
  return sweep > 0.0 ? std::min(settings_.window, span / sweep) : settings_.window;
}

void DualRateMethod::addSample(const PlateauSample& s) {
  // A non-finite angle would poison every sum of the regression: such a sample is not data.
  if (s.plateau.is_static || !std::isfinite(s.theta) || !std::isfinite(s.rotation_angle) ||
      !std::isfinite(s.rotation_rate))
    return;
  groups_.add(s.stamp, s.theta, s.theta, s.plateau.id, s.plateau.rate, s.rotation_rate);
  ++samples_;
  const bool gap = in_chain_ && toSeconds(s.stamp - last_stamp_) > settings_.plateau.max_gap;
  if (!in_chain_ || s.plateau.id != chain_plateau_ || gap || s.stamp <= last_stamp_) {
    const int group = regressionGroupOf(&group_rates_, s.plateau.rate, settings_.group_tolerance);
    regression_.startChain(group, windowFor(s.plateau.rate));
    in_chain_ = true;
    chain_plateau_ = s.plateau.id;
    unwrap_ = 0.0;
    rate_integral_ = 0.0;
  } else {
    rate_integral_ += 0.5 * (s.rotation_rate + last_table_rate_) * toSeconds(s.stamp - last_stamp_);
    // A controller may log its angle modulo 2 pi: unwrap it.
    const double step = s.rotation_angle + unwrap_ - last_table_angle_;
    if (step > kPi) unwrap_ -= 2.0 * kPi;
    if (step < -kPi) unwrap_ += 2.0 * kPi;
  }
  const double angle = s.rotation_angle + unwrap_;
  regression_.setAngleSmoothError(s.angle_smooth_error);
  // The logged rate's integral too, where the angle is logged: the regression weighs the two by
  // their noise (without an angle, the angle is that integral already).
  regression_.add(s.stamp, s.theta, angle, s.angle_logged ? rate_integral_ : NAN);
  angle_logged_ = s.angle_logged;
  last_stamp_ = s.stamp;
  last_table_angle_ = angle;
  last_table_rate_ = s.rotation_rate;
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

CalibrationOutcome DualRateMethod::finish(const GyroParameters& prior) const {
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  const auto order = groups_.byDuration();
  for (std::size_t i : order) {
    const RateGroup& g = groups_.groups()[i];
    o.plateaus.push_back(summarize(g, minBinTime(g.meanRate())));
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
  const double earth_std = prior.earth_rate.enabled
                               ? kEarthRotationRate * std::abs(std::cos(prior.earth_rate.latitude)) * 0.01 * kPi / 180
                               : 0.0;
  // One threshold for the bins of both groups: the longer of their windows' quarters.
  const IncrementFit e = regression_.solve(earth, earth_std, std::max(minBinTime(w1), minBinTime(w2)), q.max_condition);
  if (!e.ok) {
    o.gate("fit", false, 0.0, 0.0, e.reason);
    o.decide();
    return o;
  }
  o.binned = e.binned;
  // The error budget of the K harmonics (largest term of each kind), stated in the report.
  auto largest = [&](const std::vector<double>& v) {
    double m = 0.0;
    for (std::size_t i = 1; i < v.size(); ++i) m = std::max(m, v[i]);
    return formatShort(1e6 * m / std::abs(e.k.mean));
  };
  o.notes.push_back("K harmonic standard errors, ppm of |K0| (largest of each kind): statistical " +
                    largest(e.budget.statistical) + " (white wave-angle noise alone " + largest(e.budget.angle_noise) +
                    ", beyond it " + largest(e.budget.beyond_noise) + "), Earth rate " + largest(e.budget.earth_rate) +
                    ", basis-noise correction " + largest(e.budget.basis_noise) + "; phi from the " +
                    (angle_logged_
                         ? (e.angle_weight >= 1.0 ? std::string("logged table angle")
                                                  : "logged table angle weighted " + formatShort(e.angle_weight, 2) +
                                                        " against the logged rate's integral")
                         : std::string("integrated table rate")) +
                    ", window " + formatShort(e.mean_window) + " s, angle noise " + formatShort(e.angle_noise) +
                    " rad, " + std::to_string(e.increments) + " increments in " + std::to_string(e.blocks) + " blocks");
  o.smoothing_factor = 1.0;  // nothing is smoothed: the increments are fitted through their exact integrals
  if (e.trend.order > 0) {
    // A trend the session cannot tell from K0 leaves K0 to the trend's guess. The trend costs K0
    // precision in any session (how much is the inflation of its standard error); refused only when
    // it costs much (max_trend_inflation) and leaves K0 poorly known (max_trend_k0_std of |K0|).
    const BiasTrendFit& t = e.trend;
    o.bias_trend = t;
    const double per_hour = 3600.0;
    const double k0_std = e.k.mean_std / std::abs(e.k.mean);
    const bool separable = t.k0_inflation <= q.max_trend_inflation || k0_std <= q.max_trend_k0_std;
    const std::string fitted = "bias trend " + formatShort(t.coefficients.front() * per_hour, 3) + " +- " +
                               formatShort(t.stds.front() * per_hour, 2) + " rad/s per hour (" +
                               formatShort(t.coefficients.front() * t.span, 3) + " rad/s over the " +
                               formatShort(t.span, 4) + " s of data)";
    const std::string confusion = "K0's standard error x" + formatShort(t.k0_inflation, 3) + " to " +
                                  formatShort(k0_std * 1e6, 3) + " ppm, correlation " +
                                  formatShort(t.k0_correlation, 2);
    o.gate("bias_trend", separable, t.k0_inflation, q.max_trend_inflation,
           separable ? fitted + ", fitted with K and D (" + confusion + ")"
                     : "the session cannot separate a bias trend from K0 (" + confusion + ", limits x" +
                           formatShort(q.max_trend_inflation, 3) + " and " + formatShort(q.max_trend_k0_std * 1e6, 3) +
                           " ppm): order the plateau rates so that a linear trend cancels (+ - - + - + + -), or set "
                           "bias_trend_order: 0 if the bias is known to be stable");
  }
  // The gate judges the table by its effect on K: what the data scatter beyond the white wave-angle
  // noise, all charged to the table angle (or the rate integral) as an upper estimate -- angle random
  // walk and drift the model lacks land there too.
  double beyond = 0.0;
  for (std::size_t i = 1; i < e.budget.beyond_noise.size(); ++i) beyond = std::max(beyond, e.budget.beyond_noise[i]);
  beyond /= std::abs(e.k.mean);
  o.gate("table_error", beyond <= q.max_table_error, beyond, q.max_table_error,
         std::string(angle_logged_ ? "table angle" : "integrated table rate (no angle logged)") +
             " errors add at most " + formatShort(beyond * 1e6) +
             " ppm of |K0| to a K harmonic (scatter beyond the wave-angle noise)");
  // Paper-style bound per bin: K changing over one window, plus the angle noise of the two window
  // means at each end of a bin (drift cancels in this method).
  const double tau = std::max(g1.rates().effectiveWindow(), g2.rates().effectiveWindow());
  const double sigma = std::max(g1.rates().windowNoise(), g2.rates().windowNoise());
  o.error_bound = slopeBound(e.k) * std::abs(e.k.mean) * std::max(std::abs(w1), std::abs(w2)) * tau +
                  2.0 * std::sqrt(2.0) * sigma / (std::abs(w1 - w2) * tau);
  finishModel(&o, e.k, e.d, prior, q);
  return o;
}

// ------------------------------------------------------------------------------------------------
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
  for (std::size_t i : order) o.plateaus.push_back(summarize(groups_.groups()[i], minBinTime()));
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
  finishModel(&o, k, d, prior, q);
  return o;
}

// ------------------------------------------------------------------------------------------------
StepMethod::StepMethod(const CalibrationSettings& s)
    : settings_(s), steps_(s.bins), dwells_(s.bins), swept_(4 * s.bins, false) {}

void StepMethod::pair(const DwellFit& before, const DwellFit& after) {
  const double dalpha = after.meanTableAngle() - before.meanTableAngle();
  if (std::abs(dalpha) < 1e-3) return;  // a pause, not a step
  // Bridge the motion only: from the last sample at rest before it to the instant the table
  // stopped, each end taken from its dwell's line (the next dwell's slope covers its own settling,
  // so the mean rest rate is applied only while the angle actually moves).
  const double theta1 = before.valueAt(before.end()), theta2 = after.valueAt(after.restSince());
  const double tau = toSeconds(after.restSince() - before.end());
  const double rest = 0.5 * (before.slope() + after.slope());
  const double k = (theta2 - theta1 - rest * tau) / dalpha;
  const double mid = positiveModulo(0.5 * (theta1 + theta2), kPi), span = std::abs(theta2 - theta1);
  int b = static_cast<int>(mid / kPi * steps_.size());
  b = std::min(b, static_cast<int>(steps_.size()) - 1);
  steps_[b].k_sum += k;
  steps_[b].theta_sum += mid;
  steps_[b].span_sum += span;
  steps_[b].count += 1.0;
  ++step_count_;
  step_angle_sum_ += std::abs(dalpha);
  step_time_sum_ += tau;
  const double end_noise = before.residualStd() * 2.0 / std::sqrt(std::max<double>(1.0, before.samples()));
  endpoint_noise_sq_ = std::max(endpoint_noise_sq_, end_noise * end_noise);
  // Mark the swept angle for the coverage measure.
  const int n = static_cast<int>(swept_.size());
  const double lo = std::min(theta1, theta2);
  for (double th = lo; th <= lo + span && th <= lo + kPi; th += kPi / n) {
    swept_[std::min(n - 1, static_cast<int>(positiveModulo(th, kPi) / kPi * n))] = true;
  }
}

void StepMethod::closeDwell() {
  if (current_.samples() < 3) {
    current_ = DwellFit();
    return;
  }
  if (has_previous_) pair(previous_, current_);
  const int b = std::min(static_cast<int>(dwells_.size()) - 1,
                         static_cast<int>(positiveModulo(current_.meanTheta(), kPi) / kPi * dwells_.size()));
  dwells_[b].rate_sum += current_.slope();
  dwells_[b].theta_sum += positiveModulo(current_.meanTheta(), kPi);
  dwells_[b].count += 1.0;
  dwell_time_ += current_.duration();
  previous_ = current_;
  has_previous_ = true;
  current_ = DwellFit();
}

void StepMethod::addSample(const PlateauSample& s) {
  if (!s.plateau.is_static) return;  // only the dwells: the moves are bridged by their ends
  ++samples_;
  if (s.plateau.id != current_plateau_) {
    closeDwell();
    current_plateau_ = s.plateau.id;
    current_.setRestSince(s.plateau.start);
  }
  current_.add(s.stamp, s.theta, s.rotation_angle);
}

double StepMethod::coverage() const {
  return static_cast<double>(std::count(swept_.begin(), swept_.end(), true)) / swept_.size();
}

bool StepMethod::complete() const { return progress().fraction >= 1.0; }

CalibrationProgress StepMethod::progress() const {
  CalibrationProgress p;
  p.fraction = std::min(std::min(1.0, static_cast<double>(step_count_) / settings_.gates.min_steps),
                        std::min(1.0, coverage() / settings_.gates.min_coverage));
  p.summary = "step: " + std::to_string(step_count_) + " steps, theta coverage " + formatShort(100 * coverage()) + " %";
  return p;
}

CalibrationOutcome StepMethod::finish(const GyroParameters& prior) const {
  // Include the dwell still open at the end of the data.
  StepMethod m = *this;
  m.closeDwell();
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  o.samples = m.samples_;
  o.duration = m.dwell_time_ + m.step_time_sum_;
  o.coverage = m.coverage();
  o.gate("steps", m.step_count_ >= q.min_steps, m.step_count_, q.min_steps,
         std::to_string(m.step_count_) + " steps between dwells");
  o.gate("coverage", o.coverage >= q.min_coverage, o.coverage, q.min_coverage,
         "theta swept by the steps: " + formatShort(100 * o.coverage) + " %");
  o.gate("samples", m.samples_ >= q.min_samples, static_cast<double>(m.samples_), static_cast<double>(q.min_samples),
         std::to_string(m.samples_) + " wave samples at rest");
  std::vector<FitPoint> kp;
  for (std::size_t b = 0; b < m.steps_.size(); ++b) {
    const StepBin& s = m.steps_[b];
    if (s.count <= 0.0) continue;
    kp.push_back({s.theta_sum / s.count, s.k_sum / s.count, s.count, s.span_sum / s.count, {}});
    o.binned.push_back({kp.back().theta, kp.back().value, 0.0, s.count});
  }
  HarmonicFitResult k = fitHarmonics(kp, settings_.scale_factor_orders, {}, INFINITY);
  if (!k.ok) {
    o.gate("fit", false, 0.0, 0.0, k.reason);
    o.decide();
    return o;
  }
  o.smoothing_factor = k.smallest_attenuation;
  // Rest rates at the dwell angles give D(theta) = rate - K(theta) Omega_E.
  const HarmonicModel k_model = toModel(k);
  const double earth = prior.earth_rate.verticalRate();
  std::vector<FitPoint> dp;
  for (std::size_t b = 0; b < m.dwells_.size(); ++b) {
    const DwellBin& d = m.dwells_[b];
    if (d.count <= 0.0) continue;
    const double th = d.theta_sum / d.count;
    dp.push_back({th, d.rate_sum / d.count - k_model(th) * earth, d.count, 0.0, {}});
  }
  HarmonicFitResult d = fitHarmonics(dp, settings_.drift_orders, {}, INFINITY);
  if (!d.ok) {
    // Too few dwells for the harmonics: keep the mean drift only.
    double sum = 0.0, w = 0.0;
    for (const FitPoint& p : dp) {
      sum += p.value * p.weight;
      w += p.weight;
    }
    d = HarmonicFitResult();
    d.ok = true;
    d.mean = w > 0 ? sum / w : 0.0;
    d.points = dp.size();
    o.notes.push_back("too few dwells for D(theta) harmonics: the drift model written is the mean rest drift");
  }
  const double mean_step = m.step_count_ ? m.step_angle_sum_ / m.step_count_ : 0.0;
  const double mean_tau = m.step_count_ ? m.step_time_sum_ / m.step_count_ : 0.0;
  double dmax = std::abs(d.mean);
  for (std::size_t j = 0; j < d.orders.size(); ++j) dmax += std::hypot(d.cos[j], d.sin[j]);
  if (mean_step > 0.0) {
    o.error_bound = slopeBound(k) * std::abs(k.mean) * mean_step + dmax * mean_tau / mean_step +
                    2.0 * std::sqrt(m.endpoint_noise_sq_) / mean_step;
  }
  finishModel(&o, k, d, prior, q);
  return o;
}

// ------------------------------------------------------------------------------------------------
void CorrectionMatrixMethod::addGeneratorPair(const ChannelVector& raw, const ChannelVector& reference) {
  estimator_.add(raw, reference);
  reference_energy_ += reference.squaredNorm();
}

bool CorrectionMatrixMethod::complete() const {
  return estimator_.pairs() >= settings_.gates.min_pairs && estimator_.solve(settings_.gates.max_p_condition).ok;
}

CalibrationProgress CorrectionMatrixMethod::progress() const {
  CalibrationProgress p;
  p.fraction = complete() ? 1.0 : std::min(0.99, static_cast<double>(estimator_.pairs()) / settings_.gates.min_pairs);
  p.summary = "correction_matrix: " + std::to_string(estimator_.pairs()) + " generator pairs";
  return p;
}

CalibrationOutcome CorrectionMatrixMethod::finish(const GyroParameters& prior) const {
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  o.samples = estimator_.pairs();
  o.has_correction = true;
  o.correction = estimator_.solve(INFINITY);
  o.gate("pairs", estimator_.pairs() >= q.min_pairs, static_cast<double>(estimator_.pairs()),
         static_cast<double>(q.min_pairs), std::to_string(estimator_.pairs()) + " generator samples");
  o.gate("condition", o.correction.condition_number <= q.max_p_condition, o.correction.condition_number,
         q.max_p_condition,
         "generator sweep condition number " + formatShort(o.correction.condition_number) +
             (o.correction.ok ? "" : " (" + o.correction.reason + ")"));
  const double rms_amplitude = estimator_.pairs() ? std::sqrt(reference_energy_ / (4.0 * estimator_.pairs())) : 1.0;
  const double relative = o.correction.residual_rms / rms_amplitude;
  o.gate("residual", o.correction.ok && relative <= 1e-2, relative, 1e-2,
         "channel residual after correction is " + formatShort(relative) + " of the amplitude");
  double pmax = 0.0;
  for (double p : o.correction.correction.p) pmax = std::max(pmax, std::abs(p));
  o.gate("plausible", pmax < 0.05, pmax, 0.05, "largest |p| = " + formatShort(pmax));
  o.parameters = prior;
  o.parameters.correction = o.correction.correction;
  // K and D were measured through the old P: keep their means, drop their harmonics until the
  // next dual-rate run (the paper's second stage) measures the residual.
  const HarmonicModel& k = prior.scale_factor;
  const HarmonicModel& d = prior.drift;
  o.parameters.scale_factor = HarmonicModel(k.orders(), k.meanAt(NAN), std::vector<double>(k.orders().size(), 0.0),
                                            std::vector<double>(k.orders().size(), 0.0));
  o.parameters.drift = HarmonicModel(d.orders(), d.meanAt(NAN), std::vector<double>(d.orders().size(), 0.0),
                                     std::vector<double>(d.orders().size(), 0.0));
  o.parameters.calibration.method = ParameterOrigin::calibratedBy(kind());
  o.parameters.calibration.time = utcNow();
  o.notes.push_back("K and D harmonics reset to zero with the new P: run dual_rate next (two-stage refinement)");
  o.decide();
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
