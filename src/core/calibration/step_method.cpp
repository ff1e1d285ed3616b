#include "hrg_gyro/core/calibration/step_method.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/calibration/outcome_from_fits.h"
#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/estimation/harmonic_fit.h"

namespace hrg_gyro {
namespace core {

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
  finishScaleFactorAndDrift(&o, k, d, prior, q);
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
