#include "hrg_gyro/core/estimation/plateau_detector.h"

#include <cmath>

namespace hrg_gyro {
namespace core {

void PlateauDetector::start(Nanoseconds stamp) {
  state_.id = has_state_ ? state_.id + 1 : 1;
  state_.start = stamp;
  rate_sum_ = 0.0;
  count_ = 0;
  has_state_ = true;
}

PlateauState PlateauDetector::update(Nanoseconds stamp, double rate) {
  const bool gap = has_state_ && toSeconds(stamp - last_stamp_) > settings_.max_gap;
  bool outside = false;
  if (has_state_ && count_ > 0) {
    const double mean = rate_sum_ / static_cast<double>(count_);
    outside = std::abs(rate - mean) > settings_.rate_tolerance + settings_.relative_tolerance * std::abs(mean);
  }
  if (!has_state_ || gap || outside || !std::isfinite(rate)) start(stamp);
  last_stamp_ = stamp;
  if (std::isfinite(rate)) {
    rate_sum_ += rate;
    ++count_;
  }
  state_.rate = count_ > 0 ? rate_sum_ / static_cast<double>(count_) : 0.0;
  state_.is_static = std::abs(state_.rate) < settings_.static_rate;
  state_.settled = std::isfinite(rate) && toSeconds(stamp - state_.start) >= settings_.settle_time;
  return state_;
}

}  // namespace core
}  // namespace hrg_gyro
