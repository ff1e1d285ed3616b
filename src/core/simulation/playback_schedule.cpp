#include "hrg_gyro/core/simulation/playback_schedule.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

PlaybackSchedule::PlaybackSchedule(double time_scale, double max_lag) : time_scale_(time_scale), max_lag_(max_lag) {
  if (std::isnan(time_scale)) throw std::invalid_argument("time_scale must be a number");
  if (!(max_lag > 0.0)) throw std::invalid_argument("max_lag must be positive (s)");
}

void PlaybackSchedule::start(double wall_now) { start_ = wall_now; }

double PlaybackSchedule::waitFor(double elapsed, double wall_now, double* late) {
  *late = 0.0;
  if (!(time_scale_ > 0.0)) return 0.0;
  const double due = start_ + elapsed / time_scale_;
  if (due > wall_now) return due - wall_now;
  *late = wall_now - due;
  max_late_ = std::max(max_late_, *late);
  if (*late > max_lag_) {
    start_ += *late;  // this sample is now on time; the ones after keep their spacing
    slid_ += *late;
    ++slides_;
  }
  return 0.0;
}

}  // namespace core
}  // namespace hrg_gyro
