// The stamps of a table controller that logs at a fixed rate, freed of the logging computer's
// jitter. The controller samples its table at regular instants, but the computer that stamps the
// records (often another one than the gyro's) stamps each when it gets to it: a millisecond of jitter
// at 0.05 rad/s puts 50 urad of error on every table angle, 25 times a good encoder's noise. Since
// the instants are regular, each record's stamp is replaced by the straight line through the recent
// stamps against the record count: the count is the header's sequence number where it counts the
// records (it then also counts the lost ones), otherwise it is inferred from the spacing. The line
// is fitted over the past `window` seconds only (causal: no record waits), so the slow rate
// difference between two computers' clocks is followed; what is left of the jitter is its error
// averaged over the window, smooth from record to record.
//
// A record far off the line (a glitched stamp: zero, backward, a burst of lateness) is passed on as
// it came and not fitted; a run of records off the line by the same amount is a clock step, after
// which the line starts anew. A log whose stamps scatter by more than a quarter of its spacing is not
// a fixed-rate log: its stamps are passed on unchanged. No ROS.
#pragma once

#include <cstdint>
#include <deque>
#include <limits>
#include <string>
#include <vector>

#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {

struct StampRegulariserSettings {
  bool enabled = true;
  double window = 600.0;        ///< s of past records the line is fitted over (at most 65536 of them)
  int min_records = 20;         ///< records before the first regularised stamp (and after a clock step)
  double max_jitter = 0.005;    ///< s: a log whose first stamps scatter more about their line is not fixed-rate
  double outlier_sigmas = 6.0;  ///< a stamp this many jitters (and a tenth of the spacing) off the line is off it
  int step_persist = 10;        ///< records off the line by the same amount in a row: a clock step
};

/// What the regulariser saw of the log's clock.
struct TableStampStatistics {
  std::uint64_t records = 0;      ///< handed in
  std::uint64_t regularised = 0;  ///< given the line's stamp
  std::uint64_t off_line = 0;     ///< passed on unchanged as off the line (glitches, steps before recognised)
  std::uint64_t clock_steps = 0;  ///< times the line started anew after a run off it
  double jitter = 0.0;            ///< s, rms of the stamps about the line (prediction residuals)
  double period = 0.0;            ///< s between records, the line's slope
  bool fixed_rate = false;        ///< the stamps lay on a line: the log was regularised
  bool used_sequence = false;     ///< the count came from the sequence numbers (else from the spacing)
  std::string note;               ///< why the stamps were not regularised, when they were not
};

class TableStampRegulariser {
 public:
  /// A sequence number that is not known (the record count is then inferred from the spacing).
  static constexpr std::uint64_t kNoSequence = std::numeric_limits<std::uint64_t>::max();

  explicit TableStampRegulariser(const StampRegulariserSettings& settings = {});

  /// The stamp to use for a record stamped `stamp` with sequence number `sequence` (kNoSequence
  /// when the stream has none); records in the order the controller logged them.
  Nanoseconds regularise(Nanoseconds stamp, std::uint64_t sequence);

  const TableStampStatistics& statistics() const { return statistics_; }
  /// Records the line now runs through (its error shrinks as 1 / sqrt of them).
  std::size_t lineRecords() const { return points_.size(); }

 private:
  struct Point {
    double count;  // record count
    double time;   // s from origin_
  };
  struct Sums {
    double n = 0.0, c = 0.0, t = 0.0, cc = 0.0, ct = 0.0;
  };
  /// A new line from the record stamped `stamp` whose count is `count`.
  void restart(Nanoseconds stamp, double count);
  bool fitted() const { return static_cast<int>(points_.size()) >= settings_.min_records; }
  /// The line's time (s from origin_) at `count`.
  double line(double count) const;
  void addToSums(const Point& p, double sign);
  void refit();
  /// Judges from the first fitted records whether the log is fixed-rate.
  void decide();
  /// The record's count: from the sequence number while it counts records, else from the line.
  /// *trustworthy false: the stamp gives no count (at or before the last record's).
  double countOf(Nanoseconds stamp, std::uint64_t sequence, bool* trustworthy);
  /// The steps of regularise(): the first record; a record before the line is fitted; one off the
  /// line (a glitch, or a clock step once the run persists); one on it, put on the line.
  Nanoseconds first(Nanoseconds stamp, std::uint64_t sequence);
  Nanoseconds beforeTheLine(Nanoseconds stamp, std::uint64_t sequence, double count, double t);
  Nanoseconds offTheLine(Nanoseconds stamp, std::uint64_t sequence, double count, double residual, double threshold);
  Nanoseconds onTheLine(Nanoseconds stamp, std::uint64_t sequence, double count, double t, double residual);
  /// The record just taken becomes the last one.
  void remember(Nanoseconds stamp, std::uint64_t sequence, double count);

  StampRegulariserSettings settings_;
  TableStampStatistics statistics_;
  bool started_ = false, decided_ = false;
  Nanoseconds origin_ = 0;   // the line's first stamp
  double count_origin_ = 0;  // and its count
  std::deque<Point> points_;
  Sums sums_;  // of the points relative to (base_count_, base_time_), moved up now and then
  double base_count_ = 0.0, base_time_ = 0.0;
  std::size_t since_rebase_ = 0;
  double intercept_ = 0.0, slope_ = 0.0;  // time = intercept + slope x (count - count_origin_)
  double last_count_ = 0.0;
  Nanoseconds last_stamp_ = 0;
  std::vector<double> early_intervals_;  // s per record, before the first line
  std::uint64_t last_sequence_ = kNoSequence;
  bool sequence_trusted_ = true;
  int sequence_disagreements_ = 0;
  double initial_scatter_ = 0.0;  // s, of the first records about their line
  double residual_squares_ = 0.0;
  std::uint64_t residual_count_ = 0;
  // The run of records off the line.
  int off_run_ = 0;
  double off_run_first_ = 0.0, off_run_count_ = 0.0;
  Nanoseconds off_run_stamp_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
