#include "hrg_gyro/core/calibration/outcome_from_fits.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

GroupSummary summarizeGroup(const RateGroup& g, double min_bin_time) {
  GroupSummary s;
  s.rate = g.meanRate();
  s.rate_std = g.rateStd();
  s.duration = g.rates().totalTime();
  s.samples = g.rates().samples();
  s.coverage = g.rates().coverage(min_bin_time);
  s.turns = g.rates().thetaSwept() / kPi;
  return s;
}

double slopeBound(const HarmonicFitResult& f) {
  double s = 0.0;
  for (std::size_t j = 0; j < f.orders.size(); ++j) s += f.orders[j] * std::hypot(f.cos[j], f.sin[j]);
  return s;
}

double largestHarmonicStd(const HarmonicFitResult& f) {
  double m = 0.0;
  for (std::size_t j = 0; j < f.orders.size(); ++j) m = std::max({m, f.cos_std[j], f.sin_std[j]});
  return m;
}

double largestTermStd(const HarmonicFitResult& f) { return std::max(f.mean_std, largestHarmonicStd(f)); }

void finishScaleFactorAndDrift(CalibrationOutcome* o, const HarmonicFitResult& k, const HarmonicFitResult& d,
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
  const double hstd = largestHarmonicStd(k) / std::abs(k0);
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

}  // namespace core
}  // namespace hrg_gyro
