// What the single-axis methods share to turn their rate groups and harmonic fits into a
// CalibrationOutcome: a rate group's summary for the report, the bounds and largest standard errors
// of a fit, and the gates every K(theta) estimate passes with the parameter update that follows.
#pragma once

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/calibration/calibration_settings.h"
#include "hrg_gyro/core/estimation/rate_groups.h"

namespace hrg_gyro {
namespace core {

/// A rate group's line of the report: its rate, data and coverage (bins swept for min_bin_time s).
GroupSummary summarizeGroup(const RateGroup& group, double min_bin_time);

/// Upper bound of |dK/dtheta| for a fitted model: sum_k k sqrt(a_k^2 + b_k^2).
double slopeBound(const HarmonicFitResult& fit);
/// The largest standard error of a harmonic (cos or sin) term, the mean's left out.
double largestHarmonicStd(const HarmonicFitResult& fit);
/// The largest standard error of any term, the mean's included.
double largestTermStd(const HarmonicFitResult& fit);

/// The gates every K(theta) estimate passes (fit condition, K0 sign and change from the prior,
/// residual, largest harmonic standard error), the peak nonlinearity, and the parameters: the prior
/// with K and D replaced, stamped with the method and the time. Decides the outcome.
void finishScaleFactorAndDrift(CalibrationOutcome* outcome, const HarmonicFitResult& k, const HarmonicFitResult& d,
                               const GyroParameters& prior, const QualityLimits& limits);

}  // namespace core
}  // namespace hrg_gyro
