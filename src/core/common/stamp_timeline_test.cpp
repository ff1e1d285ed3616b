// StampTimeline: a record whose stamp jumps (back or ahead) is a glitch, dropped; only a jump that
// persists for `persist` records is a new timeline or a gap.
#include "hrg_gyro/core/common/stamp_timeline.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

Nanoseconds s(double seconds) { return toNanoseconds(seconds); }

StampRule rule(double backward_reset, double forward_jump, int persist) {
  StampRule r;
  r.backward_reset = backward_reset;
  r.forward_jump = forward_jump;
  r.persist = persist;
  return r;
}

/// The verdicts on `stamps` (s) in turn, of a timeline whose first record was at `first`.
std::vector<StampVerdict> verdicts(const StampRule& r, double first, const std::vector<double>& stamps) {
  StampTimeline t(r);
  EXPECT_EQ(t.check(s(first)), StampVerdict::kNext);
  std::vector<StampVerdict> out;
  for (double stamp : stamps) out.push_back(t.check(s(stamp)));
  return out;
}

using V = StampVerdict;

TEST(StampTimelineTest, ClassifiesGlitches) {
  StampTimeline t(rule(0.5, 0.1, 3));
  EXPECT_EQ(t.check(s(10.0)), StampVerdict::kNext);
  EXPECT_EQ(t.check(0), StampVerdict::kNonPositive);
  EXPECT_EQ(t.check(-5), StampVerdict::kNonPositive);
  EXPECT_EQ(t.check(s(10.0)), StampVerdict::kDuplicate);
  EXPECT_EQ(t.check(s(9.9)), StampVerdict::kBehind);
  EXPECT_EQ(t.check(s(10.1)), StampVerdict::kNext);
  EXPECT_EQ(t.last(), s(10.1));
}

TEST(StampTimelineTest, OneStampAheadIsAGlitch) {
  StampTimeline t(rule(0.5, 0.1, 5));
  t.check(s(10.0));
  EXPECT_EQ(t.check(s(1010.0)), StampVerdict::kJumpedAhead);  // 1000 s in the future: dropped
  EXPECT_EQ(t.last(), s(10.0));
  EXPECT_EQ(t.check(s(10.001)), StampVerdict::kNext);  // the stream goes on where it was
  EXPECT_EQ(t.check(s(10.002)), StampVerdict::kNext);
  // Four more of the same jump, then the old timeline: still glitches (persist is 5).
  for (double d : {1000.0, 1000.001, 1000.002, 1000.003}) EXPECT_EQ(t.check(s(d)), StampVerdict::kJumpedAhead);
  EXPECT_EQ(t.check(s(10.003)), StampVerdict::kNext);
}

TEST(StampTimelineTest, AJumpAheadThatPersistsIsAGap) {
  StampTimeline t(rule(0.5, 0.1, 5));
  t.check(s(10.0));
  for (int i = 0; i < 4; ++i) EXPECT_EQ(t.check(s(20.0 + 0.001 * i)), StampVerdict::kJumpedAhead);
  EXPECT_EQ(t.check(s(20.004)), StampVerdict::kResumedAhead);  // the fifth in a row: a real gap
  EXPECT_EQ(t.last(), s(20.004));
  EXPECT_EQ(t.check(s(20.005)), StampVerdict::kNext);
  EXPECT_EQ(t.check(s(10.1)), StampVerdict::kJumpedBack);  // the old timeline is now far behind
}

TEST(StampTimelineTest, AStepWithinForwardJumpIsNoJump) {
  EXPECT_EQ(verdicts(rule(0.5, 0.1, 5), 10.0, {10.1, 10.2000001}), (std::vector<V>{V::kNext, V::kJumpedAhead}));
}

TEST(StampTimelineTest, AStreamRejoiningTheOthersIsNoJump) {
  StampTimeline fixture(rule(0.5, 0.1, 5));
  fixture.check(s(10.0));
  // One record a second while the other streams run at their rate: each is where the others are.
  EXPECT_EQ(fixture.check(s(11.0), s(10.999)), StampVerdict::kNext);
  EXPECT_EQ(fixture.check(s(40.0), s(39.95)), StampVerdict::kNext);         // silent 29 s, back with the others
  EXPECT_EQ(fixture.check(s(140.0), s(40.1)), StampVerdict::kJumpedAhead);  // 100 s ahead of everything
}

TEST(StampTimelineTest, OneStampBackIsAGlitch) {
  StampTimeline t(rule(0.5, 0.1, 5));
  t.check(s(100.0));
  EXPECT_EQ(t.check(s(99.9998)), StampVerdict::kBehind);  // two periods back: out of order
  EXPECT_EQ(t.check(s(1.0)), StampVerdict::kJumpedBack);  // far back
  EXPECT_EQ(t.check(s(100.0001)), StampVerdict::kNext);
  EXPECT_EQ(t.last(), s(100.0001));
}

TEST(StampTimelineTest, OnlyAPersistingEarlierTimelineIsNew) {
  StampTimeline t(rule(0.5, 0.5, 3));
  t.check(s(100.0));
  EXPECT_EQ(t.check(s(1.0)), StampVerdict::kJumpedBack);
  EXPECT_EQ(t.check(s(1.1)), StampVerdict::kJumpedBack);
  EXPECT_EQ(t.check(s(100.1)), StampVerdict::kNext);  // a good record ends the count
  EXPECT_EQ(t.check(s(1.2)), StampVerdict::kJumpedBack);
  EXPECT_EQ(t.check(s(1.3)), StampVerdict::kJumpedBack);
  EXPECT_EQ(t.check(0), StampVerdict::kNonPositive);  // zero stamps neither count nor break it
  EXPECT_EQ(t.check(s(1.4)), StampVerdict::kNewTimeline);
  EXPECT_EQ(t.last(), s(1.4));
  EXPECT_EQ(t.check(s(1.5)), StampVerdict::kNext);
}

TEST(StampTimelineTest, ARecordSlightlyBehindEndsTheCount) {
  // 99.9: the old timeline goes on, and the count of records on the earlier one starts again.
  EXPECT_EQ(verdicts(rule(0.5, 0.5, 3), 100.0, {1.0, 1.1, 99.9, 1.2}),
            (std::vector<V>{V::kJumpedBack, V::kJumpedBack, V::kBehind, V::kJumpedBack}));
}

TEST(StampTimelineTest, ScatteredFarStampsAreNoTimeline) {
  StampTimeline t(rule(0.5, 0.1, 2));
  t.check(s(100.0));
  EXPECT_EQ(t.check(s(50.0)), StampVerdict::kJumpedBack);
  EXPECT_EQ(t.check(s(20.0)), StampVerdict::kJumpedBack);  // not after the previous one: starts a new count
  EXPECT_EQ(t.check(s(20.5)), StampVerdict::kJumpedBack);  // too far after it: a new count again
  EXPECT_EQ(t.check(s(20.55)), StampVerdict::kNewTimeline);
  // Ahead, the same: scattered future stamps never make a gap.
  StampTimeline u(rule(0.5, 0.1, 2));
  u.check(s(10.0));
  EXPECT_EQ(u.check(s(500.0)), StampVerdict::kJumpedAhead);
  EXPECT_EQ(u.check(s(900.0)), StampVerdict::kJumpedAhead);
  EXPECT_EQ(u.check(s(800.0)), StampVerdict::kJumpedAhead);
  EXPECT_EQ(u.check(s(10.01)), StampVerdict::kNext);
}

TEST(StampTimelineTest, PersistOneTakesEveryJumpAtOnce) {
  EXPECT_EQ(verdicts(rule(0.5, 0.1, 1), 10.0, {20.0, 5.0}), (std::vector<V>{V::kResumedAhead, V::kNewTimeline}));
}

TEST(StampTimelineTest, FollowsAnotherStreamBack) {
  StampTimeline t(rule(0.5, 0.1, 5));
  t.check(s(100.0));
  t.expectJumpBack(60.0);
  EXPECT_EQ(t.check(s(100.2)), StampVerdict::kBehind);  // still the old timeline: dropped
  EXPECT_EQ(t.check(s(1.0)), StampVerdict::kNext);      // went back: taken at once
  EXPECT_EQ(t.check(s(1.001)), StampVerdict::kNext);
  // A stream that never goes back is taken again after the give-up time.
  StampTimeline u(rule(0.5, 0.1, 5));
  u.check(s(100.0));
  u.expectJumpBack(10.0);
  EXPECT_EQ(u.check(s(105.0)), StampVerdict::kBehind);
  EXPECT_EQ(u.check(s(115.5)), StampVerdict::kNext);
}

TEST(StampTimelineTest, RefusesBadSettings) {
  EXPECT_THROW(StampTimeline(rule(0.0, 0.1, 3)), std::invalid_argument);
  EXPECT_THROW(StampTimeline(rule(NAN, 0.1, 3)), std::invalid_argument);
  EXPECT_THROW(StampTimeline(rule(0.5, 0.0, 3)), std::invalid_argument);
  EXPECT_THROW(StampTimeline(rule(0.5, INFINITY, 3)), std::invalid_argument);
  EXPECT_THROW(StampTimeline(rule(0.5, 0.1, 0)), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
