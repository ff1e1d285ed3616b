#include "hrg_gyro/core/common/stamp_timeline.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace hrg_gyro {
namespace core {

StampTimeline::StampTimeline(double backward_reset, int persist)
    : backward_reset_(std::isfinite(backward_reset) ? toNanoseconds(backward_reset) : 0), persist_(persist) {
  if (!(backward_reset > 0.0) || !std::isfinite(backward_reset)) {
    throw std::invalid_argument("backward_reset must be a positive number of seconds, got " +
                                std::to_string(backward_reset));
  }
  if (persist < 1) throw std::invalid_argument("backward_persist must be >= 1, got " + std::to_string(persist));
}

StampVerdict StampTimeline::check(Nanoseconds stamp) {
  if (stamp <= 0) return StampVerdict::kNonPositive;
  if (following_) {
    if (stamp <= last_ - backward_reset_) {
      anchor(stamp);
      return StampVerdict::kNext;
    }
    if (follow_until_ == 0) follow_until_ = std::max(stamp, last_) + give_up_;
    if (stamp < follow_until_) return StampVerdict::kBehind;
    anchor(stamp);  // this stream did not loop: go on with it
    return StampVerdict::kNext;
  }
  if (!started_ || stamp > last_) {
    anchor(stamp);
    return StampVerdict::kNext;
  }
  if (stamp == last_) return StampVerdict::kDuplicate;
  if (last_ - stamp <= backward_reset_) {
    behind_run_ = 0;  // slightly out of order: a glitch of this timeline, not the start of another
    return StampVerdict::kBehind;
  }
  behind_run_ = behind_run_ > 0 && stamp > behind_last_ ? behind_run_ + 1 : 1;
  behind_last_ = stamp;
  if (behind_run_ < persist_) return StampVerdict::kBehind;
  anchor(stamp);
  return StampVerdict::kNewTimeline;
}

void StampTimeline::clear() {
  started_ = false;
  following_ = false;
  last_ = 0;
  behind_run_ = 0;
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
  behind_run_ = 0;
}

}  // namespace core
}  // namespace hrg_gyro
