// Finds turntable rate plateaus in the stream of turntable states.
//
// A plateau is a run of states whose rate stays within a tolerance of the run's mean rate; it is
// "settled" once it has lasted settle_time (the table's rate loop and the wave have stopped
// ringing). A state outside the tolerance, or a gap in the turntable stream, starts a new plateau
// with a new id. Static plateaus (|rate| below static_rate) are the dwells of the step and
// constant-rate methods.
#pragma once

#include <cstdint>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

struct PlateauSettings {
  double rate_tolerance = 2e-4;      ///< rad/s, absolute part of the tolerance
  double relative_tolerance = 2e-3;  ///< of |rate|, added to the absolute part
  double settle_time = 2.0;          ///< s
  double static_rate = 2e-4;         ///< rad/s
  double max_gap = 0.5;              ///< s between turntable states
  /// rad/s: a reported |rate| above this is no table's (a glitched record) and is dropped before
  /// the detector sees it, as is a non-finite rate.
  double max_rate = 20.0;
};

struct PlateauState {
  std::uint64_t id = 0;  ///< changes whenever a new plateau starts
  bool settled = false;
  bool is_static = false;
  double rate = 0.0;      ///< running mean rate of the plateau, rad/s
  Nanoseconds start = 0;  ///< first state of the plateau
};

class PlateauDetector {
 public:
  explicit PlateauDetector(const PlateauSettings& settings = {}) : settings_(settings) {}

  /// Feeds one state (stamps increasing, rate finite) and returns the plateau status at it. The
  /// calibration session drops glitched records before they get here.
  PlateauState update(Nanoseconds stamp, double rate);
  const PlateauState& current() const { return state_; }
  const PlateauSettings& settings() const { return settings_; }

 private:
  void start(Nanoseconds stamp);

  PlateauSettings settings_;
  PlateauState state_;
  bool has_state_ = false;
  Nanoseconds last_stamp_ = 0;
  double rate_sum_ = 0.0;
  std::uint64_t count_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
