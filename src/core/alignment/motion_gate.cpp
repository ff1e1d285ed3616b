#include "hrg_gyro/core/alignment/motion_gate.h"

#include "hrg_gyro/core/common/number_format.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

std::string baseMotionProblem(const BaseMotionEvidence& e, const MotionSettings& m, double duration) {
  if (e.excluded_seconds > m.max_excluded * duration) {
    return formatNumbers(
        "the base moved for %.1f s of the %.1f s window (steps and their transitions; motion/max_excluded %.2f)",
        e.excluded_seconds, duration, m.max_excluded);
  }
  if (e.steps_exhausted) {
    return formatNumbers(
        "the base kept moving: %.0f steps carried (motion/max_steps %.0f) and it does not rest between them",
        static_cast<double>(e.steps_carried), m.max_steps);
  }
  if (e.worst_block_spread > m.max_motion) {
    return formatNumbers("the base moved within a rest: block mean rates spread over %.3g rad/s (limit %.3g)",
                         2.0 * e.worst_block_spread, 2.0 * m.max_motion);
  }
  return "";
}

std::string commandedWaveProblem() {
  return "the precession loop turned a wave during the window (FLAG_PRECESSING): its output is not the body's "
         "rate; align in the sweep mode, or when the wave rests";
}

std::string indexerWanderProblem(double wander, double angle, double tolerance) {
  if (!(wander > tolerance)) return "";
  return formatNumbers(
      "the indexer's angle wandered by %.3g rad while at rest near %.2f deg (position_tolerance %.3g rad)", wander,
      angle * (180.0 / kPi), tolerance);
}

}  // namespace core
}  // namespace hrg_gyro
