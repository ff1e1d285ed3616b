#include "hrg_gyro/core/simulation/playback_schedule.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

TEST(PlaybackScheduleTest, WaitsUntilEachSampleIsDueAtTheTimeScale) {
  PlaybackSchedule schedule(2.0);
  schedule.start(100.0);
  double late = -1.0;
  EXPECT_DOUBLE_EQ(schedule.waitFor(1.0, 100.0, &late), 0.5);  // 1 simulated s = 0.5 wall s
  EXPECT_EQ(late, 0.0);
  EXPECT_NEAR(schedule.waitFor(3.0, 101.2, &late), 0.3, 1e-12);
  EXPECT_EQ(schedule.maxLateness(), 0.0);
}

TEST(PlaybackScheduleTest, CatchesUpEveryLagWithoutAMaximum) {
  // Wall-clock stamps: a late thread publishes at once until it is back on its schedule.
  PlaybackSchedule schedule(1.0);
  schedule.start(0.0);
  double late = 0.0;
  EXPECT_EQ(schedule.waitFor(1.0, 4.0, &late), 0.0);
  EXPECT_DOUBLE_EQ(late, 3.0);
  EXPECT_EQ(schedule.waitFor(2.0, 4.0, &late), 0.0);  // still 2 s late: no wait
  EXPECT_DOUBLE_EQ(late, 2.0);
  EXPECT_DOUBLE_EQ(schedule.waitFor(5.0, 4.0, &late), 1.0);  // caught up: the old schedule holds
  EXPECT_EQ(schedule.slides(), 0u);
  EXPECT_EQ(schedule.slid(), 0.0);
  EXPECT_DOUBLE_EQ(schedule.maxLateness(), 3.0);
}

TEST(PlaybackScheduleTest, SlidesPastALagBeyondTheMaximumAndCatchesUpSmallerOnes) {
  PlaybackSchedule schedule(1.0, 0.2);
  schedule.start(0.0);
  double late = 0.0;
  // 0.1 s late: caught up (the next sample 0.05 s later is already due).
  EXPECT_EQ(schedule.waitFor(1.0, 1.1, &late), 0.0);
  EXPECT_NEAR(late, 0.1, 1e-12);
  EXPECT_EQ(schedule.waitFor(1.05, 1.1, &late), 0.0);
  EXPECT_EQ(schedule.slides(), 0u);
  // 3 s late (the host stopped the thread): let go; the samples after keep their spacing from here.
  EXPECT_EQ(schedule.waitFor(2.0, 5.0, &late), 0.0);
  EXPECT_DOUBLE_EQ(late, 3.0);
  EXPECT_EQ(schedule.slides(), 1u);
  EXPECT_DOUBLE_EQ(schedule.slid(), 3.0);
  EXPECT_DOUBLE_EQ(schedule.waitFor(2.5, 5.0, &late), 0.5);
  EXPECT_EQ(late, 0.0);
  EXPECT_DOUBLE_EQ(schedule.maxLateness(), 3.0);
}

TEST(PlaybackScheduleTest, AsFastAsPossibleNeverWaitsNorCountsLateness) {
  for (double scale : {0.0, -1.0}) {
    PlaybackSchedule schedule(scale, 0.1);
    schedule.start(0.0);
    double late = 1.0;
    EXPECT_EQ(schedule.waitFor(1000.0, 0.0, &late), 0.0);
    EXPECT_EQ(late, 0.0);
    EXPECT_EQ(schedule.slides(), 0u);
  }
}

TEST(PlaybackScheduleTest, RefusesANonPositiveLagOrAScaleThatIsNotANumber) {
  EXPECT_THROW(PlaybackSchedule(1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(PlaybackSchedule(1.0, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  EXPECT_THROW(PlaybackSchedule(std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
