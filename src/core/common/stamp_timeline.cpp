#include "hrg_gyro/core/common/stamp_timeline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hrg_gyro {
namespace core {
namespace {

Nanoseconds positiveSeconds(double seconds, const char* name) {
  if (!(seconds > 0.0) || !std::isfinite(seconds) || seconds > 1e9) {
    throw std::invalid_argument(std::string(name) + " must be a positive number of seconds (at most 1e9), got " +
                                std::to_string(seconds));
  }
  return toNanoseconds(seconds);
}

}  // namespace

StampTimeline::StampTimeline(const StampRule& rule)
    : rule_(rule),
      backward_(positiveSeconds(rule.backward_reset, "backward_reset")),
      forward_(positiveSeconds(rule.forward_jump, "forward_jump")) {
  if (rule.persist < 1) throw std::invalid_argument("jump_persist must be >= 1, got " + std::to_string(rule.persist));
}

StampVerdict StampTimeline::checkRest(Nanoseconds stamp, Nanoseconds others) {
  if (stamp <= 0) return StampVerdict::kNonPositive;
  if (!started_) {
    anchor(stamp);
    return StampVerdict::kNext;
  }
  if (following_) {
    if (stamp <= last_ - backward_) {
      anchor(stamp);
      return StampVerdict::kNext;
    }
    if (follow_until_ == 0) follow_until_ = std::max(stamp, last_) + give_up_;
    if (stamp < follow_until_) return StampVerdict::kBehind;
    anchor(stamp);  // this stream did not loop: go on with it
    return StampVerdict::kNext;
  }
  if (stamp == last_) return StampVerdict::kDuplicate;
  if (stamp > last_) {
    // Ahead of its own stream by more than forward_jump, and of the others too: a jump. A stream
    // that rejoins the others after a silence is not one.
    const bool jumped = stamp - last_ > forward_ && (others <= 0 || stamp - others > forward_);
    if (!jumped) {
      anchor(stamp);
      return StampVerdict::kNext;
    }
    if (!persists(stamp, +1)) return StampVerdict::kJumpedAhead;
    anchor(stamp);
    return StampVerdict::kResumedAhead;
  }
  if (last_ - stamp <= backward_) {
    run_ = 0;  // slightly out of order: a glitch of this timeline, which goes on
    return StampVerdict::kBehind;
  }
  if (!persists(stamp, -1)) return StampVerdict::kJumpedBack;
  anchor(stamp);
  return StampVerdict::kNewTimeline;
}

bool StampTimeline::persists(Nanoseconds stamp, int direction) {
  // The records of a real new timeline follow each other as the stream's records do.
  const bool continues = run_ > 0 && direction == run_direction_ && stamp > run_last_ && stamp - run_last_ <= forward_;
  run_ = continues ? run_ + 1 : 1;
  run_direction_ = direction;
  run_last_ = stamp;
  return run_ >= rule_.persist;
}

void StampTimeline::clear() {
  started_ = false;
  following_ = false;
  last_ = 0;
  run_ = 0;
}

void StampTimeline::expectJumpBack(double give_up) {
  if (!started_) return;
  following_ = true;
  follow_until_ = 0;
  give_up_ = toNanoseconds(give_up);
}

void StampTimeline::anchor(Nanoseconds stamp) {
  following_ = false;
  started_ = true;
  last_ = stamp;
  run_ = 0;
}

}  // namespace core
}  // namespace hrg_gyro
