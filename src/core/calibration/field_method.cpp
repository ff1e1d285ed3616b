#include "hrg_gyro/core/calibration/field_method.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "hrg_gyro/core/calibration/field_command_plan.h"
#include "hrg_gyro/core/calibration/outcome_from_fits.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
FieldMethod::FieldMethod(const CalibrationSettings& s)
    : settings_(s),
      // The wave turns at about the commanded rate: one radian of theta per radian of psi.
      groups_(s.bins, s.window, s.window_span, 1.0, maxFittedOrder(s.field.gain_orders, s.drift_orders),
              s.group_tolerance, s.plateau.max_gap),
      regression_(s.field.gain_orders, s.drift_orders, s.bins, s.bias_trend_order),
      chains_(s, maxFittedOrder(s.field.gain_orders, s.drift_orders), 1.0) {}

void FieldMethod::addSample(const PlateauSample& s) {
  // At rest (w_v = 0) the wave hardly moves: nothing to separate.
  if (s.plateau.is_static || !std::isfinite(s.theta) || !std::isfinite(s.rotation_angle) ||
      !std::isfinite(s.rotation_rate))
    return;
  groups_.add(s.stamp, s.theta, s.theta, s.plateau.id, s.plateau.rate, s.rotation_rate);
  ++samples_;
  if (std::isfinite(s.frequency)) {
    frequency_sum_ += s.frequency;
    ++frequency_count_;
  }
  chains_.follow(s, &regression_);
  // psi is the driver's own integral of the command: exact, and continuous (never wrapped).
  regression_.add(s.stamp, s.theta, s.rotation_angle);
}

void FieldMethod::directionGroups(int* positive, int* negative) const {
  *positive = *negative = -1;
  for (std::size_t i : groups_.byDuration()) {
    const double rate = groups_.groups()[i].meanRate();
    if (rate > 0.0 && *positive < 0) *positive = static_cast<int>(i);
    if (rate < 0.0 && *negative < 0) *negative = static_cast<int>(i);
  }
}

bool FieldMethod::complete() const { return progress().fraction >= 1.0; }

CalibrationProgress FieldMethod::progress() const {
  CalibrationProgress p;
  int plus, minus;
  directionGroups(&plus, &minus);
  std::ostringstream s;
  s << "field:";
  double fraction = 1.0;
  const FieldSettings& f = settings_.field;
  for (const auto& [index, name] : {std::pair<int, const char*>{plus, "+"}, {minus, "-"}}) {
    if (index < 0) {
      s << " " << name << " no data;";
      fraction = 0.0;
      continue;
    }
    const RateGroup& g = groups_.groups()[index];
    const double coverage = g.rates().coverage(minBinTime(g.meanRate()));
    const double turns = g.rates().thetaSwept() / kTwoPi;
    s << " " << formatShort(g.meanRate(), 3) << " rad/s: " << formatShort(turns, 3) << " turns, coverage "
      << formatShort(100 * coverage, 3) << " %;";
    fraction =
        std::min({fraction, coverage / settings_.gates.min_coverage, f.min_turns > 0 ? turns / f.min_turns : 1.0});
  }
  p.fraction = std::min(1.0, fraction);
  p.summary = s.str();
  return p;
}

double FieldMethod::gateDirections(const RateGroup& gp, const RateGroup& gm, CalibrationOutcome* out) const {
  CalibrationOutcome& o = *out;
  const QualityLimits& q = settings_.gates;
  const FieldSettings& fs = settings_.field;
  FieldReport& r = o.field;  // present once the fit gave its numbers
  r.positive_rate = gp.meanRate();
  r.negative_rate = gm.meanRate();
  r.positive_turns = gp.rates().thetaSwept() / kTwoPi;
  r.negative_turns = gm.rates().thetaSwept() / kTwoPi;
  r.positive_time = gp.rates().totalTime();
  r.negative_time = gm.rates().totalTime();
  o.duration = r.positive_time + r.negative_time;
  const double min_bin_time = std::max(minBinTime(r.positive_rate), minBinTime(r.negative_rate));
  o.coverage =
      std::min(gp.rates().coverage(minBinTime(r.positive_rate)), gm.rates().coverage(minBinTime(r.negative_rate)));
  o.gate("coverage", o.coverage >= q.min_coverage, o.coverage, q.min_coverage,
         "theta bins covered in both directions: " + formatShort(100 * o.coverage) + " %");
  const double turns = std::min(r.positive_turns, r.negative_turns);
  o.gate("turns", turns >= fs.min_turns, turns, fs.min_turns,
         formatShort(r.positive_turns, 3) + " full turns of theta at " + formatShort(r.positive_rate, 3) + " rad/s, " +
             formatShort(r.negative_turns, 3) + " at " + formatShort(r.negative_rate, 3) + " rad/s");
  return min_bin_time;
}

HarmonicFitResult FieldMethod::driftFromFit(const IncrementFit& e, const GyroParameters& prior,
                                            CalibrationOutcome* out) const {
  CalibrationOutcome& o = *out;
  const FieldSettings& fs = settings_.field;
  FieldReport& r = o.field;
  r.present = true;
  r.virtual_rate_gain = e.k;
  r.measured_drift = e.d;
  // K kept from the prior, at the session's resonator frequency (a thermal prior's K(theta, f)).
  const double frequency = frequency_count_ > 0 ? frequency_sum_ / frequency_count_ : NAN;
  const HarmonicModel& k_prior = prior.scale_factor;
  std::vector<double> k(k_prior.termCount());
  k_prior.coefficientsAt(frequency, k.data());
  // Omega_s: the Earth's rate about the sensitive axis as configured (the vehicle's attitude), else
  // its vertical component at the prior's latitude (an axis that points up).
  const bool axis_rate_given = !std::isnan(fs.axis_earth_rate);
  r.earth_rate = axis_rate_given ? fs.axis_earth_rate : prior.earth_rate.verticalRate();
  r.k0_prior = k[0];
  // D = measured - K(theta) Omega_s, term by term where K has D's order (K's other orders times
  // Omega_s are ~1e-9 rad/s and stay in the fit's residual).
  HarmonicFitResult d = e.d;
  d.mean -= k[0] * r.earth_rate;
  const std::size_t nk = k_prior.orders().size();
  for (std::size_t j = 0; j < d.orders.size(); ++j) {
    for (std::size_t i = 0; i < nk; ++i) {
      if (k_prior.orders()[i] != d.orders[j]) continue;
      d.cos[j] -= k[1 + i] * r.earth_rate;
      d.sin[j] -= k[1 + nk + i] * r.earth_rate;
    }
  }
  o.scale_factor.clear();  // K is not estimated: kept
  o.drift = {d};
  o.binned = e.binned;
  for (BinnedCurvePoint& p : o.binned) p.d -= k_prior(p.theta, frequency) * r.earth_rate;
  o.smoothing_factor = 1.0;
  if (e.trend.order > 0) o.bias_trend = e.trend;
  return d;
}

void FieldMethod::gateFit(const IncrementFit& e, const HarmonicFitResult& d, CalibrationOutcome* out) const {
  CalibrationOutcome& o = *out;
  const QualityLimits& q = settings_.gates;
  const FieldSettings& fs = settings_.field;
  FieldReport& r = o.field;
  o.gate("fit_condition", e.k.condition_number <= q.max_condition, e.k.condition_number, q.max_condition,
         "regression condition number " + formatShort(e.k.condition_number));
  // Stillness from D's harmonics: their regressors oscillate, so the block sandwich measures their
  // scatter without the excess it shows on slopes such as D0 (whose increments telescope across the
  // blocks' boundaries, which the sandwich does not pair).
  double excess = 0.0;
  int terms = 0;
  for (std::size_t i = 1; i < e.drift_budget.statistical.size(); ++i) {
    if (!(e.drift_budget.angle_noise[i] > 0.0)) continue;
    const double ratio = e.drift_budget.statistical[i] / e.drift_budget.angle_noise[i];
    excess += ratio * ratio;
    ++terms;
  }
  r.excess_scatter = terms > 0 ? std::sqrt(excess / terms) : 1.0;
  o.gate("stillness", r.excess_scatter <= fs.max_excess_scatter, r.excess_scatter, fs.max_excess_scatter,
         "the data scatter " + formatShort(r.excess_scatter, 3) +
             " times what the wave-angle noise predicts on D's harmonics (rms; a case that moves, or a rate noise, "
             "raises it)");
  const double gain_error = std::abs(e.k.mean - 1.0);
  o.gate("virtual_rate_gain", gain_error <= fs.max_gain_error, gain_error, fs.max_gain_error,
         "the precession loop realised " + formatShort(e.k.mean, 8) + " of the commanded rate (+- " +
             formatShort(e.k.mean_std, 2) + ")");
  const double worst = largestTermStd(d);
  o.gate("drift_std", worst <= fs.max_drift_std, worst, fs.max_drift_std,
         "largest standard error of a D term " + formatShort(worst, 3) + " rad/s");
  // The loops trail the precessed wave; what they leave that keeps its sign in both directions is
  // fitted as D (precessionLagDrift). Predicted where the gyro's resonator is known, at the faster
  // direction's commanded rate, and allowed up to D's own standard error.
  const double lag_rate = std::max(std::abs(r.positive_rate), std::abs(r.negative_rate));
  const double lag = fieldLoopLag(fs, lag_rate);
  if (std::isnan(lag)) {
    o.notes.push_back("the loops' lag at " + formatShort(lag_rate, 3) +
                      " rad/s adds a drift that keeps its sign in both directions, so it is fitted as part of D; "
                      "it grows as the rate squared and faster; not predicted here (field/resonator unknown)");
  } else {
    o.gate("loop_lag", lag <= worst, lag, worst,
           "the loops' lag at " + formatShort(lag_rate, 3) + " rad/s adds up to " + formatShort(lag, 3) +
               " rad/s to D (predicted for the gyro of field/resonator), " + formatShort(lag / worst, 3) +
               " times the largest standard error of a D term" +
               (lag <= worst ? std::string() : ": command a slower field/rate"));
  }
  if (e.trend.order > 0) {
    const BiasTrendFit& t = e.trend;
    const double g0_std = e.k.mean_std / std::abs(e.k.mean);
    const bool separable = t.k0_inflation <= q.max_trend_inflation || g0_std <= q.max_trend_k0_std;
    o.gate("bias_trend", separable, t.k0_inflation, q.max_trend_inflation,
           "bias trend " + formatShort(t.coefficients.front() * 3600.0, 3) + " +- " +
               formatShort(t.stds.front() * 3600.0, 2) + " rad/s per hour fitted with D and the gain (the gain's " +
               "standard error x" + formatShort(t.k0_inflation, 3) + ")" +
               (separable ? std::string() : ": order the directions so that a trend cancels (+ - - +)"));
  }
}

void FieldMethod::noteResult(const IncrementFit& e, const GyroParameters& prior, CalibrationOutcome* out) const {
  CalibrationOutcome& o = *out;
  const FieldReport& r = o.field;
  const bool axis_rate_given = !std::isnan(settings_.field.axis_earth_rate);
  o.notes.push_back("K kept from the prior (K0 = " + formatShort(r.k0_prior, 9) +
                    "): a still gyro is turned by its precession loop, never by a rotation, so nothing in this "
                    "session scales with a body rate; refresh K on a table");
  o.notes.push_back("D = the still gyro's rate - K(theta) Omega_s with Omega_s = " + formatShort(r.earth_rate, 6) +
                    (axis_rate_given
                         ? std::string(" rad/s (field/axis_earth_rate)")
                         : " rad/s (vertical at the prior's latitude " + formatShort(prior.earth_rate.latitude, 6) +
                               " rad: the sensitive axis assumed up)") +
                    ": D0 is only as good as K0 Omega_s, and a case turning at a constant rate would read as bias");
  o.notes.push_back("the commanded rate was realised with gain " + formatShort(e.k.mean, 8) + " +- " +
                    formatShort(e.k.mean_std, 2) + " (theta-dependent part up to " +
                    formatShort(toModel(e.k).peakDeviation(), 3) + "); window " + formatShort(e.mean_window) +
                    " s, angle noise " + formatShort(e.angle_noise) + " rad, " + std::to_string(e.increments) +
                    " increments in " + std::to_string(e.blocks) + " blocks");
}

CalibrationOutcome FieldMethod::finish(const GyroParameters& prior) const {
  CalibrationOutcome o;
  o.method = kind();
  const QualityLimits& q = settings_.gates;
  if (prior.drift.frequencyDependent()) {
    // One session stands at one temperature: it cannot refresh a D(theta, f), and a flat D would
    // silently drop the thermal calibration's dependence.
    o.gate("prior_drift", false, 1.0, 0.0,
           "the prior's D(theta) depends on the resonator frequency (a thermal calibration); the field method "
           "refreshes one D(theta) at the session's temperature and would lose that: refresh it with the thermal "
           "method");
    o.decide();
    return o;
  }
  for (std::size_t i : groups_.byDuration()) {
    const RateGroup& g = groups_.groups()[i];
    o.plateaus.push_back(summarizeGroup(g, minBinTime(g.meanRate())));
  }
  o.samples = samples_;
  o.gate("samples", samples_ >= q.min_samples, static_cast<double>(samples_), static_cast<double>(q.min_samples),
         std::to_string(samples_) + " wave samples while the wave was precessed");
  int plus, minus;
  directionGroups(&plus, &minus);
  const int directions = (plus >= 0) + (minus >= 0);
  o.gate("directions", directions == 2, directions, 2.0,
         directions == 2 ? "virtual rotation in both directions"
                         : std::string("need the wave precessed both ways (the two separate D from the gain), found ") +
                               (plus >= 0    ? "only positive"
                                : minus >= 0 ? "only negative"
                                             : "no") +
                               " rates");
  if (directions < 2) {
    o.decide();
    return o;
  }
  const double min_bin_time = gateDirections(groups_.groups()[plus], groups_.groups()[minus], &o);
  // psi carries no Earth rate: the regression's D is the still gyro's whole rate, D + K Omega_s.
  const IncrementFit e = regression_.solve(0.0, 0.0, min_bin_time, q.max_condition);
  if (!e.ok) {
    o.gate("fit", false, 0.0, 0.0, e.reason);
    o.decide();
    return o;
  }
  const HarmonicFitResult d = driftFromFit(e, prior, &o);
  gateFit(e, d, &o);
  noteResult(e, prior, &o);
  o.parameters = prior;
  o.parameters.drift = toModel(d);
  o.parameters.calibration.method = ParameterOrigin::calibratedBy(o.method);
  o.parameters.calibration.time = utcNow();
  o.decide();
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
