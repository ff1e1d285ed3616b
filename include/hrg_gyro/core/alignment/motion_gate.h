// The gate "motion" of a gyrocompass window: the base, the indexer or the wave moved beyond what the
// still-base fit carries. Each way it can be met is a function here, which says whether it was and why
// (the refusal's wording), so the gyrocompass's intake and its solver raise the gate from one place:
//   commanded wave  the precession loop turned a wave during the window outside the sweep mode;
//   indexer         the indexer's angle wandered at a rest beyond indexer/position_tolerance;
//   base            the base's steps took too much of the window (motion/max_excluded), it kept moving
//                   (motion/max_steps), or a rest's block mean rates (block_mean_stillness.h) spread
//                   beyond +-motion/max_motion.
// Whether another estimator answers instead is the solver's choice (gyrocompass_solver.h). No ROS.
#pragma once

#include <cstddef>
#include <string>

#include "hrg_gyro/core/alignment/alignment_settings.h"

namespace hrg_gyro {
namespace core {

/// The gate's name in a result (AlignmentResult::gate).
constexpr const char* kMotionGate = "motion";

/// What the still-base fit saw of the base's motion over a window.
struct BaseMotionEvidence {
  double excluded_seconds = 0.0;    ///< s left out around the base's steps
  std::size_t steps_carried = 0;    ///< steps found and carried
  bool steps_exhausted = false;     ///< max_steps reached with a step still found
  double worst_block_spread = 0.0;  ///< rad/s, the largest half-spread of a rest's block mean rates
};

/// Why the base's motion keeps the still-base fit from answering; "" when it was still enough.
std::string baseMotionProblem(const BaseMotionEvidence& evidence, const MotionSettings& motion, double duration);
/// Why a window is refused whose wave the precession loop turned (FLAG_PRECESSING) outside the sweep mode.
std::string commandedWaveProblem();
/// Why an indexer rest is refused: its angle wandered by `wander` rad near `angle` rad; "" within `tolerance`.
std::string indexerWanderProblem(double wander, double angle, double tolerance);

}  // namespace core
}  // namespace hrg_gyro
