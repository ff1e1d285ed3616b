#include "hrg_gyro/core/calibration/field_command_plan.h"

#include <cmath>
#include <stdexcept>

#include "hrg_gyro/core/calibration/calibration_outcome.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/first_order_model.h"

namespace hrg_gyro {
namespace core {

double fieldSegmentDuration(const CalibrationSettings& s) {
  const double sweep = s.field.turns * kTwoPi / s.field.rate;
  return s.plateau.settle_time + sweep + 0.5 * s.plateau.smoothing_span + 1.0;
}

double fieldPlanDuration(const CalibrationSettings& s) {
  return s.field.rest + static_cast<double>(s.field.directions.size()) * fieldSegmentDuration(s);
}

std::string fieldPlanLengthProblem(const CalibrationSettings& s) {
  const double total = fieldPlanDuration(s);
  if (total <= kMaxFieldPlanDuration) return "";
  return "the plan lasts " + formatShort(total, 3) + " s (rest " + formatShort(s.field.rest, 3) + " s + " +
         std::to_string(s.field.directions.size()) + " segments of " + formatShort(fieldSegmentDuration(s), 3) +
         " s: plateau settle time + turns x 2 pi / rate + 1.5 s), more than " + formatShort(kMaxFieldPlanDuration, 6) +
         " s (a day): fewer turns or directions, a faster rate or a shorter rest";
}

std::vector<PlannedPrecession> fieldCommandPlan(const CalibrationSettings& s) {
  const std::string problem = fieldPlanLengthProblem(s);
  if (!problem.empty()) throw std::invalid_argument("field plan: " + problem);
  std::vector<PlannedPrecession> plan;
  double t = 0.0;
  plan.push_back({t, 0.0});
  t += s.field.rest;
  const double segment = fieldSegmentDuration(s);
  for (const int sign : s.field.directions) {
    plan.push_back({t, sign * s.field.rate});
    t += segment;
  }
  plan.push_back({t, 0.0});
  return plan;
}

double fieldLoopLag(const FieldSettings& field, double rate) {
  if (!field.resonator) return NAN;
  const FieldResonator& r = *field.resonator;
  return precessionLagDrift(r.shell, r.loops, r.drive, rate).peakDeviation();
}

void checkFieldPlan(const CalibrationSettings& s) {
  const std::string problem = fieldPlanLengthProblem(s);
  if (!problem.empty()) throw std::invalid_argument("field plan: " + problem);
  const FieldSettings& f = s.field;
  const double lag = fieldLoopLag(f, f.rate);
  if (lag > f.max_drift_std) {
    throw std::invalid_argument(
        "field/rate " + formatShort(f.rate, 3) + " rad/s: the loops' lag adds up to " + formatShort(lag, 3) +
        " rad/s to D for the gyro of field/resonator, more than field/max_drift_std " +
        formatShort(f.max_drift_std, 3) + " rad/s; the loop_lag gate would refuse the result: command a slower rate");
  }
}

}  // namespace core
}  // namespace hrg_gyro
