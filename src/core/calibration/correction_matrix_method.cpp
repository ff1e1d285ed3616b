#include "hrg_gyro/core/calibration/correction_matrix_method.h"

#include <algorithm>
#include <cmath>

#include "hrg_gyro/core/common/number_format.h"

namespace hrg_gyro {
namespace core {

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
