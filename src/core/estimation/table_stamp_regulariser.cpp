#include "hrg_gyro/core/estimation/table_stamp_regulariser.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace hrg_gyro {
namespace core {
namespace {

// A sequence number that moves by more than this between two records does not count records.
constexpr std::uint64_t kMaxSequenceStep = 100000;
// Records in a row whose sequence number and stamp disagree by half a spacing or more (and four
// jitters) before the sequence numbers are taken for a renumbering and set aside.
constexpr int kMaxSequenceDisagreements = 3;
// Records the line is fitted through at most (memory: 16 bytes each).
constexpr double kMaxPoints = 65536.0;

}  // namespace

TableStampRegulariser::TableStampRegulariser(const StampRegulariserSettings& settings) : settings_(settings) {
  if (!(settings_.window > 0.0)) throw std::invalid_argument("stamp regulariser: window must be positive");
  if (settings_.min_records < 3) throw std::invalid_argument("stamp regulariser: min_records must be >= 3");
  if (!(settings_.max_jitter > 0.0)) throw std::invalid_argument("stamp regulariser: max_jitter must be positive");
  if (settings_.step_persist < 2) throw std::invalid_argument("stamp regulariser: step_persist must be >= 2");
}

void TableStampRegulariser::restart(Nanoseconds stamp, double count) {
  origin_ = stamp;
  count_origin_ = count;
  points_.clear();
  sums_ = Sums();
  base_count_ = base_time_ = 0.0;
  since_rebase_ = 0;
  off_run_ = 0;
}

double TableStampRegulariser::line(double count) const { return intercept_ + slope_ * (count - count_origin_); }

void TableStampRegulariser::addToSums(const Point& p, double sign) {
  const double c = p.count - base_count_, t = p.time - base_time_;
  sums_.n += sign;
  sums_.c += sign * c;
  sums_.t += sign * t;
  sums_.cc += sign * c * c;
  sums_.ct += sign * c * t;
}

void TableStampRegulariser::refit() {
  // Sums relative to a base point that is moved up now and then, so that they stay small numbers.
  if (++since_rebase_ > 4 * points_.size() + 64) {
    since_rebase_ = 0;
    base_count_ = points_.front().count;
    base_time_ = points_.front().time;
    sums_ = Sums();
    for (const Point& p : points_) addToSums(p, 1.0);
  }
  const double n = sums_.n;
  const double scc = sums_.cc - sums_.c * sums_.c / n, sct = sums_.ct - sums_.c * sums_.t / n;
  if (n < 2.0 || !(scc > 0.0)) return;
  const double slope = sct / scc;
  const double mean_c = sums_.c / n + base_count_, mean_t = sums_.t / n + base_time_;
  slope_ = slope;
  intercept_ = mean_t - slope * (mean_c - count_origin_);
}

double TableStampRegulariser::countOf(Nanoseconds stamp, std::uint64_t sequence, bool* trustworthy) {
  *trustworthy = true;
  if (sequence != kNoSequence && sequence_trusted_ && last_sequence_ != kNoSequence) {
    // Header sequence numbers are 32 bits: they wrap.
    const std::uint64_t step = (sequence - last_sequence_) & 0xffffffffULL;
    if (step >= 1 && step <= kMaxSequenceStep) {
      const double count = last_count_ + static_cast<double>(step);
      // A publisher across a network renumbers its messages (roscpp does): then a lost record
      // leaves no gap, and from there on every count falls a spacing short of where its stamp lies.
      // Three such records in a row (beyond what jitter does), and the spacing counts instead.
      // (A lost record makes the stamp late by whole spacings; a clock step by any amount.)
      bool renumbered = false;
      if (fitted() && slope_ > 0.0) {
        const double jitter = residual_count_ > 0 ? std::sqrt(residual_squares_ / residual_count_) : initial_scatter_;
        const double late = (toSeconds(stamp - origin_) - line(count)) / slope_;
        renumbered = late >= 0.5 && std::abs(late - std::round(late)) < 0.25 && late * slope_ > 4.0 * jitter;
      }
      sequence_disagreements_ = renumbered ? sequence_disagreements_ + 1 : 0;
      if (sequence_disagreements_ < kMaxSequenceDisagreements) return count;
    }
    sequence_trusted_ = false;  // repeated, jumping or renumbered: not a record count
  }
  if (sequence == kNoSequence || !sequence_trusted_) statistics_.used_sequence = false;
  if (fitted() && slope_ > 0.0) {
    // Lost records are rare and jitter is not: the next record's count unless the stamp lies three
    // quarters of a spacing or more past where the next one belongs.
    const double past_next = (toSeconds(stamp - origin_) - line(last_count_ + 1.0)) / slope_;
    if (past_next > -0.75) return last_count_ + 1.0 + std::max(0.0, std::floor(past_next + 0.25));
    *trustworthy = false;  // a stamp well before the next record's place: its count cannot be told
  }
  // Before a line exists: the spacing is the median of the first intervals (a lost record doubles
  // one of them, jitter moves each by at most a fraction).
  if (last_stamp_ != 0 && stamp > last_stamp_ && early_intervals_.size() >= 3) {
    std::vector<double> sorted = early_intervals_;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double spacing = sorted[sorted.size() / 2];
    if (spacing > 0.0) return last_count_ + std::max(1.0, std::round(toSeconds(stamp - last_stamp_) / spacing));
  }
  return last_count_ + 1.0;
}

Nanoseconds TableStampRegulariser::regularise(Nanoseconds stamp, std::uint64_t sequence) {
  ++statistics_.records;
  if (!settings_.enabled) return stamp;
  if (!started_) return first(stamp, sequence);
  if (decided_ && !statistics_.fixed_rate) return stamp;
  bool trustworthy = true;
  const double count = countOf(stamp, sequence, &trustworthy);
  const double t = toSeconds(stamp - origin_);
  if (!fitted()) return beforeTheLine(stamp, sequence, count, t);
  const double residual = t - line(count);
  const double jitter = residual_count_ > 0 ? std::sqrt(residual_squares_ / residual_count_) : initial_scatter_;
  const double threshold = std::max(settings_.outlier_sigmas * jitter, 0.1 * slope_);
  if (!trustworthy || std::abs(residual) > threshold) return offTheLine(stamp, sequence, count, residual, threshold);
  return onTheLine(stamp, sequence, count, t, residual);
}

void TableStampRegulariser::remember(Nanoseconds stamp, std::uint64_t sequence, double count) {
  last_count_ = count;
  last_stamp_ = stamp;
  last_sequence_ = sequence;
}

Nanoseconds TableStampRegulariser::first(Nanoseconds stamp, std::uint64_t sequence) {
  started_ = true;
  statistics_.used_sequence = sequence != kNoSequence;
  restart(stamp, 0.0);
  const Point p{0.0, 0.0};
  points_.push_back(p);
  addToSums(p, 1.0);
  remember(stamp, sequence, 0.0);
  return stamp;
}

Nanoseconds TableStampRegulariser::beforeTheLine(Nanoseconds stamp, std::uint64_t sequence, double count, double t) {
  // Too few records for a line yet: take them as they come (a log starts at rest, mostly).
  const Point p{count, t};
  points_.push_back(p);
  addToSums(p, 1.0);
  refit();
  if (stamp > last_stamp_ && last_stamp_ != 0 && early_intervals_.size() < 64) {
    early_intervals_.push_back(toSeconds(stamp - last_stamp_) / (count - last_count_));
  }
  remember(stamp, sequence, count);
  if (fitted() && !decided_) decide();
  return stamp;
}

Nanoseconds TableStampRegulariser::offTheLine(Nanoseconds stamp, std::uint64_t sequence, double count, double residual,
                                              double threshold) {
  ++statistics_.off_line;
  // A run of records off the line by about the same amount is a clock step: start a new line there.
  if (off_run_ > 0 && std::abs(residual - off_run_first_) <= threshold) {
    ++off_run_;
  } else {
    off_run_ = 1;
    off_run_first_ = residual;
    off_run_stamp_ = stamp;
    off_run_count_ = count;
  }
  if (sequence != kNoSequence && sequence_trusted_) {
    last_count_ = count;
    last_sequence_ = sequence;
  }
  if (off_run_ >= settings_.step_persist) {
    ++statistics_.clock_steps;
    const double run_start = off_run_count_;
    const Nanoseconds run_stamp = off_run_stamp_;
    restart(run_stamp, run_start);
    const Point first{run_start, 0.0}, now{count, toSeconds(stamp - run_stamp)};
    for (const Point& p : {first, now}) {
      points_.push_back(p);
      addToSums(p, 1.0);
    }
    refit();
    last_count_ = count;
    last_sequence_ = sequence;
  }
  return stamp;
}

Nanoseconds TableStampRegulariser::onTheLine(Nanoseconds stamp, std::uint64_t sequence, double count, double t,
                                             double residual) {
  off_run_ = 0;
  residual_squares_ += residual * residual;
  ++residual_count_;
  statistics_.jitter = std::sqrt(residual_squares_ / residual_count_);
  // A fast log fits a subsample of its records: a line through kMaxPoints is as good as any.
  const double per_point = std::max(1.0, std::ceil(settings_.window / slope_ / kMaxPoints));
  if (std::fmod(count, per_point) == 0.0) {
    const Point p{count, t};
    points_.push_back(p);
    addToSums(p, 1.0);
  }
  while (!points_.empty() && t - points_.front().time > settings_.window &&
         static_cast<int>(points_.size()) > settings_.min_records) {
    addToSums(points_.front(), -1.0);
    points_.pop_front();
  }
  refit();
  remember(stamp, sequence, count);
  statistics_.period = slope_;
  ++statistics_.regularised;
  return origin_ + toNanoseconds(line(count));
}

void TableStampRegulariser::decide() {
  // The first records' scatter about their line: a fixed-rate log's is its jitter. Counting by the
  // spacing also needs it well below half the spacing.
  double squares = 0.0;
  for (const Point& p : points_) squares += std::pow(p.time - line(p.count), 2);
  initial_scatter_ = std::sqrt(squares / std::max<std::size_t>(1, points_.size() - 2));
  decided_ = true;
  const bool by_spacing = !statistics_.used_sequence;
  statistics_.period = slope_;
  if (!(slope_ > 0.0)) {
    statistics_.note = "the first records' stamps do not increase with their count";
  } else if (initial_scatter_ > settings_.max_jitter) {
    statistics_.note = "the first " + std::to_string(points_.size()) + " records' stamps scatter by " +
                       std::to_string(initial_scatter_ * 1e3) + " ms about a line in their count: not a fixed-rate log";
  } else if (by_spacing && initial_scatter_ > 0.25 * slope_) {
    statistics_.note =
        "the stamps scatter by more than a quarter of the record spacing and carry no sequence "
        "numbers: the records cannot be counted";
  } else {
    statistics_.fixed_rate = true;
    return;
  }
}

}  // namespace core
}  // namespace hrg_gyro
