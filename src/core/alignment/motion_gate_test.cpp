#include "hrg_gyro/core/alignment/motion_gate.h"

#include <gtest/gtest.h>

#include <string>

namespace hrg_gyro {
namespace core {
namespace {

bool names(const std::string& reason, const std::string& words) { return reason.find(words) != std::string::npos; }

TEST(MotionGate, AStillBaseHasNoProblem) {
  const MotionSettings m;
  BaseMotionEvidence e;
  e.excluded_seconds = 0.5 * m.max_excluded * 100.0;
  e.worst_block_spread = 0.5 * m.max_motion;
  EXPECT_EQ(baseMotionProblem(e, m, 100.0), "");
}

TEST(MotionGate, EachWayTheBaseMovesIsNamed) {
  MotionSettings m;
  m.max_excluded = 0.2;
  m.max_motion = 1e-4;
  BaseMotionEvidence e;
  e.excluded_seconds = 30.0;  // of 100 s: beyond 20 %
  EXPECT_TRUE(names(baseMotionProblem(e, m, 100.0), "moved for 30.0 s of the 100.0 s window")) << e.excluded_seconds;
  e.excluded_seconds = 0.0;
  e.steps_exhausted = true;
  e.steps_carried = 12;
  EXPECT_TRUE(names(baseMotionProblem(e, m, 100.0), "kept moving: 12 steps carried"));
  e.steps_exhausted = false;
  e.worst_block_spread = 3e-4;
  EXPECT_TRUE(names(baseMotionProblem(e, m, 100.0), "spread over 0.0006 rad/s (limit 0.0002)"));
}

TEST(MotionGate, TheIndexerWandersBeyondItsTolerance) {
  EXPECT_EQ(indexerWanderProblem(1e-4, 0.5, 1e-3), "");
  const std::string reason = indexerWanderProblem(2e-3, 1.5707963267948966, 1e-3);
  EXPECT_TRUE(names(reason, "wandered by 0.002 rad while at rest near 90.00 deg")) << reason;
}

TEST(MotionGate, ACommandedWaveSaysWhatToDo) {
  EXPECT_TRUE(names(commandedWaveProblem(), "FLAG_PRECESSING"));
  EXPECT_TRUE(names(commandedWaveProblem(), "sweep mode"));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
