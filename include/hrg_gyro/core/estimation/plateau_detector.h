// Finds turntable rate plateaus in the stream of turntable records, from what a table controller logs.
//
// Each record carries the table angle (rad, NaN when the controller does not log it) and the reported
// rate. The detector keeps a continuous table angle: the logged angle, or, in a rate-only stream, the
// integral of the reported rate. Membership of a plateau is judged on the *judged rate*: the angle
// advanced over a span of smoothing_span s centred on the record, divided by the time elapsed. This
// is the slope of the logged angle (encoder noise enters only through the two ends of the span, and
// a reported rate that is the angle differenced at the log rate telescopes to the same thing), or the
// time-weighted moving average of the reported rate. Centring the span keeps a real rate change from
// leaking into either plateau: a record is judged once the stream has passed it by half the span, so
// the records are handed back with that lag.
//
// A plateau is a run of records whose judged rate stays within rate_tolerance + relative_tolerance *
// |rate| of the run's mean judged rate; it is "settled" once it has lasted settle_time (the table's
// rate loop and the wave have stopped ringing). A judged rate outside the tolerance, a gap in the
// stream or the first logged angle of a stream starts a new plateau with a new id. The plateau's rate
// is the least-squares slope of the table angle over its records; static plateaus (|mean judged rate|
// below static_rate) are the dwells of the step and constant-rate methods.
//
// The detector also measures what the session needs to explain a refusal: how long plateaus lasted
// and how much the reported and judged rates scatter on a moving table (about the linear trend of
// blocks of 1 s for the reported rate, of 10 spans for the judged rate whose values within a span are
// correlated; the trend keeps ramps from counting as scatter).
#pragma once

#include <cmath>
#include <cstdint>
#include <deque>
#include <vector>

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
  /// s: span, centred on each record, over which the judged rate is measured (0: the reported rate
  /// of the record itself, judged at once).
  double smoothing_span = 1.0;
};

struct PlateauState {
  std::uint64_t id = 0;  ///< changes whenever a new plateau starts
  bool settled = false;
  bool is_static = false;
  double rate = 0.0;      ///< rad/s: least-squares slope of the table angle over the plateau so far
  Nanoseconds start = 0;  ///< first record of the plateau
};

/// A turntable record once judged.
struct PlateauRecord {
  Nanoseconds stamp = 0;
  double angle = 0.0;         ///< rad, continuous: the logged angle, or the integral of the reported rate
  double rate = 0.0;          ///< rad/s, as reported
  double judged_rate = 0.0;   ///< rad/s, the rate over the smoothing span
  bool angle_logged = false;  ///< angle is the controller's, not the integral of the rate
  PlateauState plateau;
};

/// What the detector saw, for the session's diagnosis of a refusal.
struct PlateauStatistics {
  std::uint64_t records = 0;   ///< judged
  std::uint64_t plateaus = 0;  ///< started
  std::uint64_t breaks = 0;    ///< plateaus ended by a judged rate outside the tolerance
  /// Of those, the ones that ended a plateau shorter than settle_time whose next judged rate was back
  /// within the tolerance of the plateau before it: the rate went nowhere, its scatter broke them.
  std::uint64_t spurious_breaks = 0;
  double longest = 0.0;              ///< s, longest plateau (moving or static)
  double longest_moving = 0.0;       ///< s, longest plateau whose rate is not static
  double settled_moving = 0.0;       ///< s of records on settled moving plateaus
  double settled_static = 0.0;       ///< s of records on settled static plateaus
  std::uint64_t scatter_blocks = 0;  ///< blocks on a moving table behind the figures below (judged rate)
  double reported_scatter = NAN;     ///< median over those blocks of std(reported rate) / |rate|
  double judged_scatter = NAN;       ///< the same for the judged rate
  double noise_to_tolerance = NAN;   ///< median of std(judged rate) / plateau tolerance at that rate
  double typical_rate = NAN;         ///< rad/s, median |rate| of those blocks
};

class PlateauDetector {
 public:
  explicit PlateauDetector(const PlateauSettings& settings = {}) : settings_(settings) {}

  /// Feeds one record (stamps increasing, rate finite; angle finite, or NaN when the stream does not
  /// log it) and appends to *out every record whose plateau is now decided, in stamp order: those
  /// the stream has passed by half the smoothing span. The first finite angle makes the stream an
  /// angle-logging one for good; the calibration session drops glitched records before they get here.
  void add(Nanoseconds stamp, double angle, double rate, std::vector<PlateauRecord>* out);
  /// Judges the records still held (the end of the stream), with the span cut at the last record.
  void flush(std::vector<PlateauRecord>* out);
  /// Causal and unsmoothed: judges one exact reported rate at once (the simulator's truth).
  PlateauState update(Nanoseconds stamp, double rate);

  bool angleLogged() const { return angle_logged_; }
  const PlateauState& current() const { return state_; }
  const PlateauSettings& settings() const { return settings_; }
  /// Judged so far; the scatter figures are recomputed on each call (bounded: the newest blocks).
  PlateauStatistics statistics() const;

 private:
  struct Held {
    Nanoseconds stamp;
    double angle, rate;
  };
  struct LineSums {  // least-squares line y(t) through the points, t and y relative to the first point
    double n = 0, t = 0, tt = 0, y = 0, ty = 0, yy = 0;
    void add(double dt, double dy);
    double slope() const;
    double residualStd() const;
  };
  /// Scatter of one rate about its linear trend over a block of records.
  struct ScatterBlock {
    Nanoseconds start = 0;
    double first = 0.0;  // the block's first value: keeps its sums small
    LineSums sums;
  };
  struct Scatter {
    double relative, ratio, rate;  // std / |rate|, std / tolerance, |rate|
  };

  double tolerance(double rate) const {
    return settings_.rate_tolerance + settings_.relative_tolerance * std::abs(rate);
  }
  /// Decides one record's plateau from its judged rate.
  PlateauRecord judge(const Held& h, double judged_rate);
  void judgeReady(bool all, std::vector<PlateauRecord>* out);
  /// Adds a value to a block; closes it after `length` s, keeping its scatter if on a moving table.
  void addToBlock(ScatterBlock* block, Nanoseconds stamp, double value, double length, std::deque<Scatter>* closed);

  PlateauSettings settings_;
  PlateauState state_;
  PlateauStatistics stats_;
  bool angle_logged_ = false;
  // Records not yet judged, and those still inside the span of the next one to judge.
  std::deque<Held> held_;
  std::size_t next_ = 0;       // index in held_ of the next record to judge
  std::size_t hi_ = 0;         // index in held_ of the last record in the span of the one being judged
  bool segment_start_ = true;  // the next judged record starts a plateau (stream start, gap, mode change)
  Nanoseconds last_stamp_ = 0;
  double integral_ = 0.0, last_rate_ = 0.0;
  // The current plateau: mean judged rate (the tolerance's reference) and the angle's line.
  double judged_sum_ = 0.0;
  std::uint64_t judged_count_ = 0;
  double start_angle_ = 0.0;
  bool has_previous_ = false;   // the plateau before the current one, in the same segment
  double previous_mean_ = 0.0;  // its mean judged rate
  LineSums plateau_line_;
  Nanoseconds last_judged_ = 0;
  // The current scatter blocks and the newest closed ones.
  ScatterBlock reported_block_, judged_block_;
  std::deque<Scatter> reported_scatter_, judged_scatter_;
};

}  // namespace core
}  // namespace hrg_gyro
