#include "hrg_gyro/core/calibration/field_command_plan.h"

#include <cmath>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

double fieldSegmentDuration(const CalibrationSettings& s) {
  const double sweep = s.field.turns * kTwoPi / s.field.rate;
  return s.plateau.settle_time + sweep + 0.5 * s.plateau.smoothing_span + 1.0;
}

std::vector<PlannedPrecession> fieldCommandPlan(const CalibrationSettings& s) {
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

}  // namespace core
}  // namespace hrg_gyro
