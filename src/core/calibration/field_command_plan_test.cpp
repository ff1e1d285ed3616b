// The virtual rotation a field calibration commands: a rest at 0, one segment per direction long
// enough for `turns` full turns of settled data, then 0; the shipped scenario's schedule is checked
// against it in field_calibration_test.
#include "hrg_gyro/core/calibration/field_command_plan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "core/testing/resonator_cases.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/resonator/first_order_model.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(FieldCommandPlanTest, RestThenOneSegmentPerDirectionThenZero) {
  CalibrationSettings s;
  s.field.rate = 0.25;
  s.field.turns = 1.5;
  s.field.rest = 4.0;
  s.field.directions = {-1, 1, 1};
  s.plateau.settle_time = 3.0;
  s.plateau.smoothing_span = 2.0;
  // settle + sweep + half a smoothing span + 1 s to spare
  const double segment = 3.0 + 1.5 * kTwoPi / 0.25 + 1.0 + 1.0;
  EXPECT_NEAR(fieldSegmentDuration(s), segment, 1e-12);
  const std::vector<PlannedPrecession> plan = fieldCommandPlan(s);
  ASSERT_EQ(plan.size(), 5u);
  EXPECT_EQ(plan[0].time, 0.0);
  EXPECT_EQ(plan[0].rate, 0.0);
  const double rates[] = {-0.25, 0.25, 0.25};
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(plan[1 + i].time, 4.0 + i * segment, 1e-9) << i;
    EXPECT_EQ(plan[1 + i].rate, rates[i]) << i;
  }
  EXPECT_NEAR(plan[4].time, 4.0 + 3 * segment, 1e-9);
  EXPECT_EQ(plan[4].rate, 0.0);  // the wave is left at rest
}

TEST(FieldCommandPlanTest, TheShippedPlanTakes270Seconds) {
  const std::vector<PlannedPrecession> plan = fieldCommandPlan(CalibrationSettings());
  ASSERT_EQ(plan.size(), 6u);  // 0, + - - +, 0
  // 5 s of rest and four segments of 2 + 4 pi / 0.2 + 0.5 + 1 s (docs/field_calibration.md)
  EXPECT_NEAR(plan.back().time, 5.0 + 4 * (3.5 + 2.0 * kTwoPi / 0.2), 1e-9);
  EXPECT_NEAR(plan.back().time, 270.3, 0.05);
}

// No plan runs for ever or longer than a day, whatever reached the settings (the parser bounds the
// keys; the plateau's settle time is not one of them).
TEST(FieldCommandPlanTest, APlanLongerThanADayIsRefused) {
  CalibrationSettings s;
  EXPECT_EQ(fieldPlanLengthProblem(s), "");
  EXPECT_NEAR(fieldPlanDuration(s), fieldCommandPlan(s).back().time, 1e-9);
  s.plateau.settle_time = 1e308;
  EXPECT_NE(fieldPlanLengthProblem(s), "");
  EXPECT_THROW(fieldCommandPlan(s), std::invalid_argument);
  EXPECT_THROW(checkFieldPlan(s), std::invalid_argument);
  s = CalibrationSettings();
  s.field.rate = 0.01;
  s.field.turns = 100.0;
  std::printf("[ refused ] %s\n", fieldPlanLengthProblem(s).c_str());
  EXPECT_THROW(fieldCommandPlan(s), std::invalid_argument);
}

// The loops' lag at the plan's rate, for a gyro whose resonator is given: predicted, and a plan whose
// lag no standard error the drift_std gate accepts could cover is refused before it starts.
TEST(FieldCommandPlanTest, TheLoopsLagAtThePlannedRateIsPredictedForAKnownGyro) {
  CalibrationSettings s;
  EXPECT_TRUE(std::isnan(fieldLoopLag(s.field, s.field.rate)));  // unknown gyro: not predicted
  EXPECT_NO_THROW(checkFieldPlan(s));
  const testing::ResonatorCase gyro = testing::realisticResonator();
  s.field.resonator = FieldResonator{gyro.shell, gyro.loops, gyro.drive};
  const double shipped = fieldLoopLag(s.field, 0.2), fast = fieldLoopLag(s.field, 10.0);
  EXPECT_DOUBLE_EQ(shipped, precessionLagDrift(gyro.shell, gyro.loops, gyro.drive, 0.2).peakDeviation());
  std::printf("[ predicted ] realistic gyro: loop lag %.3g rad/s at 0.2 rad/s, %.3g at 10 rad/s\n", shipped, fast);
  EXPECT_LT(shipped, 1e-9);  // far below the shipped plan's D standard errors (1.2e-8)
  EXPECT_NO_THROW(checkFieldPlan(s));
  s.field.rate = 10.0;
  EXPECT_GT(fast, s.field.max_drift_std);
  try {
    checkFieldPlan(s);
    ADD_FAILURE() << "a plan at 10 rad/s passed";
  } catch (const std::invalid_argument& e) {
    std::printf("[ refused ] %s\n", e.what());
    EXPECT_EQ(std::string(e.what()).rfind("field/rate", 0), 0u) << e.what();
  }
  EXPECT_NO_THROW(fieldCommandPlan(s));  // the plan itself can be made (a simulation may want it)
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
