// The stamp check of one input stream: which records come next in time, which are glitches to drop
// (a zero or negative stamp, a duplicate, a stamp behind the last good one), and when the stream has
// really moved to an earlier timeline (a looping bag, a restarted driver).
//
// One record behind the last good stamp is a glitch. Only `persist` records in a row that lie more
// than `backward_reset` s behind it, themselves in increasing order, are taken for a new timeline;
// a good record in between ends that count. The first record (or the first after clear()) is
// always taken. When another stream of the same recording has gone back (expectJumpBack), this one
// is about to follow: its records still of the old timeline are dropped, and the first one more
// than backward_reset behind starts its new timeline at once.
#pragma once

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

enum class StampVerdict {
  kNext,         ///< later than the last good stamp (or the first): use it
  kNonPositive,  ///< zero or negative: drop
  kDuplicate,    ///< equal to the last good stamp: drop
  kBehind,       ///< before the last good stamp: drop (one of a possible new timeline, or a glitch)
  kNewTimeline,  ///< the stream went back for good: this record starts the new timeline
};

class StampTimeline {
 public:
  /// backward_reset: s a stamp must lie behind to count towards a new timeline (> 0);
  /// persist: records in a row that make it one (>= 1). Throws std::invalid_argument otherwise.
  StampTimeline(double backward_reset, int persist);

  /// Classifies `stamp` and, for kNext and kNewTimeline, makes it the last good stamp.
  StampVerdict check(Nanoseconds stamp);
  /// Forgets the stream: the next record is taken as its first.
  void clear();
  /// Another stream went back: drop this one's records until it goes back too, or until give_up s
  /// of its own stamps have passed without it doing so (then it goes on where it is).
  void expectJumpBack(double give_up);
  bool started() const { return started_; }
  Nanoseconds last() const { return last_; }

 private:
  Nanoseconds backward_reset_;
  int persist_;
  bool started_ = false;
  Nanoseconds last_ = 0;
  int behind_run_ = 0;            // records in a row far behind last_, increasing among themselves
  Nanoseconds behind_last_ = 0;   // the newest of them
  bool following_ = false;        // expectJumpBack() in force
  Nanoseconds follow_until_ = 0;  // stamp at which it is given up
  Nanoseconds give_up_ = 0;

  void anchor(Nanoseconds stamp);
};

}  // namespace core
}  // namespace hrg_gyro
