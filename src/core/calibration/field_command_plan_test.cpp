// The virtual rotation a field calibration commands: a rest at 0, one segment per direction long
// enough for `turns` full turns of settled data, then 0; the shipped scenario's schedule is checked
// against it in field_calibration_test.
#include "hrg_gyro/core/calibration/field_command_plan.h"

#include <gtest/gtest.h>

#include "hrg_gyro/core/common/units.h"

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

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
