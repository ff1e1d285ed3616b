// Whether the standing wave was turned on command (virtual precession) over a processor output's
// interval: the one rule the processor node, its nodelet and `hrg_bag process` apply, so that the
// flag offline is the flag live.
//
// A whole-angle gyro's precession loop turns the wave at a commanded rate; the processor cannot tell
// that turning from a body rate. The driver reports the loop's state with every channel sample, in
// that sample's stamp: the commanded rate in force at the sample's end and the commanded virtual
// angle (the rate's integral) at its centre. An output covering (from, to] -- the processor's previous
// accepted stamp and this one -- is precessed when the rate in force at `from` (the last state at or
// before it) or at any state in (from, to] is not 0, or the commanded angle moved between those
// states (a command shorter than a sample). Its dalpha is what the wave did; the verdict only flags it.
//
// The state and the channels come over two connections, in no fixed order between them. An output
// waits until the state stream has reached its stamp, so its verdict depends on the stamps alone, not
// on which message came first:
//   - before the first state record (a gyro without the loop) outputs do not wait and are not flagged;
//   - an output waits at most `hold` s of output stamps: a state stream that lies further behind the
//     newest output (stopped, or far behind) leaves the outputs undecided (kUnknown) and flagged, at
//     once for those that follow, until it catches up -- the wave may be turning and nothing says so;
//   - a state record that is not finite, or at or before the previous one (by less than
//     backward_reset), is dropped and counted; a stream going back by more (a bag loop, a restarted
//     driver) starts a new timeline, and so does the processor's output going back: what waits is
//     decided with the records known, and records of the old timeline that still come are dropped.
// Memory is bounded: at most max_held outputs wait (beyond, the oldest is decided kUnknown) and the
// state records kept are those the waiting outputs and the next one need.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "hrg_gyro/core/common/ring_buffer.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

/// One record of the driver's precession state (PrecessionState.msg).
struct PrecessionStateRecord {
  Nanoseconds stamp = 0;  ///< the channel sample's stamp
  double rate = 0.0;      ///< rad/s, electrical: the commanded rate in force at the sample's end
  double angle = 0.0;     ///< rad, electrical: the commanded virtual angle at the sample's centre
};

enum class PrecessionVerdict : std::uint8_t {
  kNoState,     ///< no state record seen yet: a gyro without a precession loop (not flagged)
  kStill,       ///< the records cover the interval and no commanded rate was in force
  kPrecessing,  ///< a commanded rate was in force over (part of) the interval: flagged
  kUnknown,     ///< the state stream stopped short of the interval: flagged, the wave may have turned
};
const char* toString(PrecessionVerdict verdict);

struct PrecessionDecision {
  PrecessionVerdict verdict = PrecessionVerdict::kNoState;
  /// The commanded rate in force at the output's stamp (the last record at or before it), rad/s;
  /// NaN when no record tells.
  double rate = NAN;
  bool flagged() const { return verdict == PrecessionVerdict::kPrecessing || verdict == PrecessionVerdict::kUnknown; }
};

struct PrecessionWatchSettings {
  double hold = 1.0;              ///< s of output stamps an output waits for the state stream
  double backward_reset = 0.5;    ///< s a stream must go back to start a new timeline (the processor's)
  std::size_t max_held = 100000;  ///< outputs waiting at most (and state records kept)
  /// hold and backward_reset finite and positive, max_held >= 1; ConfigError naming the node's
  /// parameter (precession_hold, backward_reset) otherwise.
  void validate() const;
};

struct PrecessionWatchCounters {
  std::uint64_t states = 0;          ///< state records taken
  std::uint64_t dropped_states = 0;  ///< not finite, zero stamp, duplicate, out of order, old timeline
  std::uint64_t timelines = 0;       ///< a stream went back: a new timeline began
  std::uint64_t decided = 0;         ///< outputs decided
  std::uint64_t precessing = 0;      ///< of which kPrecessing
  std::uint64_t unknown = 0;         ///< of which kUnknown
};

class PrecessionWatch {
 public:
  /// Throws ConfigError for invalid settings.
  explicit PrecessionWatch(const PrecessionWatchSettings& settings = PrecessionWatchSettings());

  /// A state record, in the order received; false when it was dropped (counted).
  bool addState(const PrecessionStateRecord& record);
  /// The processor's next output, covering (from, to], joins the queue behind those waiting.
  void addOutput(Nanoseconds from, Nanoseconds to);
  /// The decision for the oldest waiting output when it can be made now: true, *decision set and the
  /// output leaves the queue; false when it must wait (or none waits). Outputs leave in order.
  bool next(PrecessionDecision* decision);
  /// The input has ended (a bag read to its end): every waiting output is decided with what is known.
  void finish();

  std::size_t waiting() const { return outputs_.size(); }
  /// A state record has been taken since start-up: the gyro reports a precession loop.
  bool seenState() const { return seen_state_; }
  const PrecessionWatchCounters& counters() const { return counters_; }
  const PrecessionWatchSettings& settings() const { return settings_; }

 private:
  struct Waiting {
    Nanoseconds from, to;
    bool decided;  // decided already (a timeline ended under it), in `decision`
    PrecessionDecision decision;
  };
  /// The verdict from the records known, which reach `to` (or cannot any more).
  PrecessionDecision decide(Nanoseconds from, Nanoseconds to) const;
  /// A timeline ends: every waiting output is decided now with the records known.
  void decideWaiting();
  /// Drops the records no waiting or coming output needs (the last at or before `upto` is kept).
  void trim(Nanoseconds upto);

  PrecessionWatchSettings settings_;
  Nanoseconds hold_ns_, backward_reset_ns_;
  RingBuffer<PrecessionStateRecord> states_;
  RingBuffer<Waiting> outputs_;
  bool seen_state_ = false;
  bool has_state_stamp_ = false;
  Nanoseconds last_state_stamp_ = 0;  // of the state stream's timeline (or where a new one is awaited)
  bool has_output_ = false;
  Nanoseconds newest_to_ = 0;         // the newest output's stamp
  Nanoseconds decided_to_ = 0;        // the newest decided output's stamp
  bool awaiting_state_jump_ = false;  // the outputs went back, the state stream not yet
  bool finished_ = false;
  PrecessionWatchCounters counters_;
};

}  // namespace core
}  // namespace hrg_gyro
