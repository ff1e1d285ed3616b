// When a simulated or replayed sample is due on the wall clock, and what to do when it is late.
//
// The sample at simulated time t is due at start + t / time_scale. When the thread runs late, the
// answer depends on whose clock the stamps follow. With wall-clock stamps (real time, no
// /use_sim_time) the stamps are due times, so the source catches up: a hardware gyro keeps
// sampling while the host is busy. Under sim time the source drives /clock itself; chasing lost wall
// time would only burst the pipeline at full speed, so a lag beyond `max_lag` is let go: the
// schedule slides and the simulated clock simply ran slower for a while (Gazebo's real-time factor).
// Small lags (sleep overshoot, scheduler jitter) are still caught up so the average rate holds.
#pragma once

#include <cstdint>
#include <limits>

namespace hrg_gyro {
namespace core {

class PlaybackSchedule {
 public:
  /// time_scale: simulated seconds per wall second, 0 or less = as fast as possible (never waits).
  /// max_lag: wall seconds of lateness caught up; beyond it the schedule slides (infinity: never).
  PlaybackSchedule(double time_scale, double max_lag = std::numeric_limits<double>::infinity());

  /// Anchors simulated time 0 at wall time `wall_now` (s).
  void start(double wall_now);

  /// Wall seconds to wait before publishing the sample at simulated time `elapsed` (0 when it is due
  /// or late). `*late` gets the lateness before any slide (0 when on time).
  double waitFor(double elapsed, double wall_now, double* late);

  double maxLateness() const { return max_late_; }
  /// Wall seconds the schedule was moved back, and how many times.
  double slid() const { return slid_; }
  std::uint64_t slides() const { return slides_; }

 private:
  double time_scale_, max_lag_;
  double start_ = 0.0;
  double max_late_ = 0.0, slid_ = 0.0;
  std::uint64_t slides_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
