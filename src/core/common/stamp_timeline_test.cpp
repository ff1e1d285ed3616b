// StampTimeline: glitches are dropped by kind; only a persisting earlier timeline is a new one.
#include "hrg_gyro/core/common/stamp_timeline.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

Nanoseconds s(double seconds) { return toNanoseconds(seconds); }

TEST(StampTimelineTest, ClassifiesGlitches) {
  StampTimeline t(0.5, 3);
  EXPECT_EQ(t.check(s(10.0)), StampVerdict::kNext);
  EXPECT_EQ(t.check(0), StampVerdict::kNonPositive);
  EXPECT_EQ(t.check(-5), StampVerdict::kNonPositive);
  EXPECT_EQ(t.check(s(10.0)), StampVerdict::kDuplicate);
  EXPECT_EQ(t.check(s(9.9)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(s(10.1)), StampVerdict::kNext);
  EXPECT_EQ(t.last(), s(10.1));
}

TEST(StampTimelineTest, OnlyAPersistingEarlierTimelineIsNew) {
  StampTimeline t(0.5, 3);
  t.check(s(100.0));
  EXPECT_EQ(t.check(s(1.0)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(s(1.1)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(s(100.1)), StampVerdict::kNext);  // a good record ends the count
  EXPECT_EQ(t.check(s(1.2)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(s(1.3)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(0), StampVerdict::kNonPositive);  // zero stamps neither count nor break it
  EXPECT_EQ(t.check(s(1.4)), StampVerdict::kNewTimeline);
  EXPECT_EQ(t.last(), s(1.4));
  EXPECT_EQ(t.check(s(1.5)), StampVerdict::kNext);
}

TEST(StampTimelineTest, ScatteredFarStampsAreNoTimeline) {
  StampTimeline t(0.5, 2);
  t.check(s(100.0));
  EXPECT_EQ(t.check(s(50.0)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(s(20.0)), StampVerdict::kBehind);  // not after the previous one: starts a new count
  EXPECT_EQ(t.check(s(20.5)), StampVerdict::kNewTimeline);
}

TEST(StampTimelineTest, FollowsAnotherStreamBack) {
  StampTimeline t(0.5, 5);
  t.check(s(100.0));
  t.expectJumpBack(60.0);
  EXPECT_EQ(t.check(s(100.2)), StampVerdict::kBehind);  // still the old timeline: dropped
  EXPECT_EQ(t.check(s(1.0)), StampVerdict::kNext);      // went back: taken at once
  EXPECT_EQ(t.check(s(1.1)), StampVerdict::kNext);
  // A stream that never goes back is taken again after the give-up time.
  StampTimeline u(0.5, 5);
  u.check(s(100.0));
  u.expectJumpBack(10.0);
  EXPECT_EQ(u.check(s(105.0)), StampVerdict::kBehind);
  EXPECT_EQ(u.check(s(115.5)), StampVerdict::kNext);
}

TEST(StampTimelineTest, RefusesBadSettings) {
  EXPECT_THROW(StampTimeline(0.0, 3), std::invalid_argument);
  EXPECT_THROW(StampTimeline(NAN, 3), std::invalid_argument);
  EXPECT_THROW(StampTimeline(0.5, 0), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
