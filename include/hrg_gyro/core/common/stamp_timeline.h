// The one stamp rule of every input stream (the processor's channels, the triad combiner's axis
// outputs, a calibration's wave, table, precession and fixture records): which record comes next
// in time, which are glitches to drop, and when the stream has really moved to another timeline.
//
// A clock jump, a stray packet or a buffered message gives one record a wrong stamp. Such a record
// is an outlier of its stream, not the start of an epoch:
//   - a zero or negative stamp, a duplicate, a stamp behind the last good one by at most
//     backward_reset: dropped (out of order);
//   - a stamp behind by more than backward_reset, or ahead by more than forward_jump (and, when the
//     caller gives the newest stamp of the recording's other streams, ahead of that by more than
//     forward_jump too): a jump, dropped;
//   - only `persist` records in a row on the far side of one jump, following each other as a
//     stream's records do (increasing, each within forward_jump of the one before), make it a real
//     discontinuity: the persist-th is taken as the first record of the
//     new timeline (kNewTimeline going back: a looping bag, a restarted driver; kResumedAhead going
//     forward: a gap, a clock stepped ahead). A good record in between, or one slightly behind the
//     last good one, ends the count: the jumped records were glitches. The persist - 1
//     records before the persist-th stay dropped: a real discontinuity costs them.
// A stream that was silent and rejoins the others (ahead of its own last record but not of the
// other streams) is not a jump. The first record (or the first after clear()) is always taken.
// When another stream of the same recording has gone back (expectJumpBack), this one is about to
// follow: its records still of the old timeline are dropped, and the first one more than
// backward_reset behind starts its new timeline at once. No ROS.
#pragma once

#include <cstdint>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

enum class StampVerdict : std::uint8_t {
  kNext,          ///< later than the last good stamp within forward_jump (or the first): use it
  kNonPositive,   ///< zero or negative: drop
  kDuplicate,     ///< equal to the last good stamp: drop
  kBehind,        ///< behind the last good stamp by at most backward_reset: out of order, drop
  kJumpedBack,    ///< behind by more: a glitch unless it persists, drop
  kJumpedAhead,   ///< ahead by more than forward_jump: a glitch unless it persists, drop
  kNewTimeline,   ///< the stream went back for good: this record starts the new timeline
  kResumedAhead,  ///< the stream went ahead for good: use this record, across a gap
};

/// Whether a verdict says "use this record".
inline bool stampUsable(StampVerdict v) {
  return v == StampVerdict::kNext || v == StampVerdict::kNewTimeline || v == StampVerdict::kResumedAhead;
}

/// The rule's three numbers. Defaults: the processor's (forward_jump is its max_gap).
struct StampRule {
  double backward_reset = 0.5;  ///< s
  double forward_jump = 0.1;    ///< s
  int persist = 5;              ///< records in a row that make a jump real
};

class StampTimeline {
 public:
  /// Throws std::invalid_argument unless backward_reset and forward_jump are finite and positive and
  /// persist >= 1.
  explicit StampTimeline(const StampRule& rule);

  /// Classifies `stamp` and, for a usable verdict, makes it the last good stamp. `others`: the
  /// newest good stamp of the recording's other streams (0: none, or a stream of its own).
  StampVerdict check(Nanoseconds stamp, Nanoseconds others = 0) {
    if (started_ && stamp > last_ && stamp - last_ <= forward_ && run_ == 0 && !following_) {
      last_ = stamp;  // the usual case, inline
      return StampVerdict::kNext;
    }
    return checkRest(stamp, others);
  }
  /// Forgets the stream: the next record is taken as its first.
  void clear();
  /// Another stream went back: drop this one's records until it goes back too, or until give_up s
  /// of its own stamps have passed without it doing so (then it goes on where it is).
  void expectJumpBack(double give_up);
  bool started() const { return started_; }
  Nanoseconds last() const { return last_; }
  const StampRule& rule() const { return rule_; }

 private:
  StampVerdict checkRest(Nanoseconds stamp, Nanoseconds others);
  /// A record on the far side of a jump: counts it, and says whether the jump is now real.
  bool persists(Nanoseconds stamp, int direction);
  void anchor(Nanoseconds stamp);

  StampRule rule_;
  Nanoseconds backward_ = 0, forward_ = 0;
  bool started_ = false;
  Nanoseconds last_ = 0;
  int run_ = 0;                   // jumped records in a row, following each other
  int run_direction_ = 0;         // -1 back, +1 ahead
  Nanoseconds run_last_ = 0;      // the newest of them
  bool following_ = false;        // expectJumpBack() in force
  Nanoseconds follow_until_ = 0;  // stamp at which it is given up
  Nanoseconds give_up_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
