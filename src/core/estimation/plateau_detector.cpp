#include "hrg_gyro/core/estimation/plateau_detector.h"

#include <algorithm>

namespace hrg_gyro {
namespace core {
namespace {

constexpr double kScatterBlock = 1.0;          // s: shortest scatter block
constexpr double kSpansPerJudgedBlock = 10.0;  // the judged rate's blocks are this many spans long
constexpr std::size_t kMinBlockRecords = 8;    // fewer: the block's scatter is not measured
constexpr std::size_t kMaxBlocks = 4096;       // newest blocks kept for the medians

double median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + mid, v.end());
  return v[mid];
}

}  // namespace

void PlateauDetector::LineSums::add(double dt, double dy) {
  n += 1.0;
  t += dt;
  tt += dt * dt;
  y += dy;
  ty += dt * dy;
  yy += dy * dy;
}

double PlateauDetector::LineSums::slope() const {
  const double stt = tt - t * t / n;
  return n >= 2.0 && stt > 0.0 ? (ty - t * y / n) / stt : NAN;
}

double PlateauDetector::LineSums::residualStd() const {
  if (n < 3.0) return NAN;
  const double stt = tt - t * t / n, sty = ty - t * y / n, syy = yy - y * y / n;
  const double ss = stt > 0.0 ? syy - sty * sty / stt : syy;
  return std::sqrt(std::max(0.0, ss) / (n - 2.0));
}

void PlateauDetector::add(Nanoseconds stamp, double angle, double rate, std::vector<PlateauRecord>* out) {
  const bool logged = std::isfinite(angle);
  const bool has_last = last_stamp_ != 0;
  const double dt = has_last ? toSeconds(stamp - last_stamp_) : 0.0;
  const bool gap = has_last && dt > settings_.max_gap;
  // A gap, or the first logged angle (the continuous angle changes its origin): no span reaches
  // across, and a new plateau starts.
  if (gap || (logged && !angle_logged_)) {
    judgeReady(true, out);
    held_.clear();
    next_ = 0;
    hi_ = 0;
    segment_start_ = true;
  }
  if (logged) angle_logged_ = true;
  if (angle_logged_) {
    // A missing angle in an angle-logging stream is the session's to drop; carry the last one on.
    integral_ = logged ? angle : integral_ + rate * dt;
  } else {
    integral_ += 0.5 * (last_rate_ + rate) * dt;
  }
  last_stamp_ = stamp;
  last_rate_ = rate;
  held_.push_back({stamp, integral_, rate});
  judgeReady(false, out);
}

void PlateauDetector::flush(std::vector<PlateauRecord>* out) { judgeReady(true, out); }

void PlateauDetector::judgeReady(bool all, std::vector<PlateauRecord>* out) {
  const double half = 0.5 * settings_.smoothing_span;
  while (next_ < held_.size()) {
    const Held& h = held_[next_];
    if (!all && toSeconds(held_.back().stamp - h.stamp) < half) break;
    // The span: from the first held record within half a span before h to the last within half after.
    std::size_t lo = 0;
    while (lo < next_ && toSeconds(h.stamp - held_[lo].stamp) > half) ++lo;
    hi_ = std::max(hi_, next_);
    while (hi_ + 1 < held_.size() && toSeconds(held_[hi_ + 1].stamp - h.stamp) <= half) ++hi_;
    const double span = toSeconds(held_[hi_].stamp - held_[lo].stamp);
    const double judged = half > 0.0 && span > 0.0 ? (held_[hi_].angle - held_[lo].angle) / span : h.rate;
    out->push_back(judge(h, judged));
    ++next_;
    // Forget what no later span reaches.
    const Nanoseconds reference = next_ < held_.size() ? held_[next_].stamp : held_.back().stamp;
    while (next_ > 0 && toSeconds(reference - held_.front().stamp) > half) {
      held_.pop_front();
      --next_;
      if (hi_ > 0) --hi_;
    }
  }
}

PlateauState PlateauDetector::update(Nanoseconds stamp, double rate) {
  if (!std::isfinite(rate)) {
    segment_start_ = true;
    state_.settled = false;
    return state_;
  }
  const bool has_last = last_stamp_ != 0;
  const double dt = has_last ? toSeconds(stamp - last_stamp_) : 0.0;
  if (has_last && dt > settings_.max_gap) segment_start_ = true;
  integral_ += 0.5 * (last_rate_ + rate) * dt;
  last_stamp_ = stamp;
  last_rate_ = rate;
  return judge({stamp, integral_, rate}, rate).plateau;
}

PlateauRecord PlateauDetector::judge(const Held& h, double judged_rate) {
  bool start = segment_start_ || judged_count_ == 0;
  if (!start) {
    const double mean = judged_sum_ / static_cast<double>(judged_count_);
    start = std::abs(judged_rate - mean) > tolerance(mean);
  }
  const double dt = last_judged_ != 0 ? toSeconds(h.stamp - last_judged_) : 0.0;
  if (start) {
    if (segment_start_) {
      reported_block_ = judged_block_ = ScatterBlock();  // a block never spans a gap
      has_previous_ = false;
    } else {
      ++stats_.breaks;
      if (has_previous_ && toSeconds(last_judged_ - state_.start) < settings_.settle_time &&
          std::abs(judged_rate - previous_mean_) <= tolerance(previous_mean_)) {
        ++stats_.spurious_breaks;
      }
      previous_mean_ = judged_sum_ / static_cast<double>(judged_count_);
      has_previous_ = true;
    }
    state_.id += 1;
    state_.start = h.stamp;
    judged_sum_ = 0.0;
    judged_count_ = 0;
    start_angle_ = h.angle;
    plateau_line_ = LineSums();
    segment_start_ = false;
    ++stats_.plateaus;
  } else if (state_.settled) {
    (state_.is_static ? stats_.settled_static : stats_.settled_moving) += dt;
  }
  last_judged_ = h.stamp;
  judged_sum_ += judged_rate;
  ++judged_count_;
  plateau_line_.add(toSeconds(h.stamp - state_.start), h.angle - start_angle_);
  const double mean = judged_sum_ / static_cast<double>(judged_count_);
  const double slope = plateau_line_.slope();
  state_.rate = std::isfinite(slope) ? slope : judged_rate;
  state_.is_static = std::abs(mean) < settings_.static_rate;
  const double age = toSeconds(h.stamp - state_.start);
  state_.settled = age >= settings_.settle_time;
  ++stats_.records;
  stats_.longest = std::max(stats_.longest, age);
  if (!state_.is_static) stats_.longest_moving = std::max(stats_.longest_moving, age);

  addToBlock(&reported_block_, h.stamp, h.rate, kScatterBlock, &reported_scatter_);
  addToBlock(&judged_block_, h.stamp, judged_rate,
             std::max(kScatterBlock, kSpansPerJudgedBlock * settings_.smoothing_span), &judged_scatter_);

  return {h.stamp, h.angle, h.rate, judged_rate, angle_logged_, state_};
}

void PlateauDetector::addToBlock(ScatterBlock* block, Nanoseconds stamp, double value, double length,
                                 std::deque<Scatter>* closed) {
  if (block->sums.n == 0.0) {
    block->start = stamp;
    block->first = value;
  }
  const double t = toSeconds(stamp - block->start);
  block->sums.add(t, value - block->first);
  if (t < length) return;
  if (block->sums.n >= kMinBlockRecords) {
    const double rate = std::abs(block->first + block->sums.y / block->sums.n);
    if (rate >= settings_.static_rate) {
      const double scatter = block->sums.residualStd();
      closed->push_back({scatter / rate, scatter / tolerance(rate), rate});
      if (closed->size() > kMaxBlocks) closed->pop_front();
    }
  }
  *block = ScatterBlock();
}

PlateauStatistics PlateauDetector::statistics() const {
  PlateauStatistics s = stats_;
  std::vector<double> reported, judged, ratio, rate;
  for (const Scatter& b : reported_scatter_) reported.push_back(b.relative);
  for (const Scatter& b : judged_scatter_) {
    judged.push_back(b.relative);
    ratio.push_back(b.ratio);
    rate.push_back(b.rate);
  }
  s.scatter_blocks = judged_scatter_.size();
  s.reported_scatter = median(reported);
  s.judged_scatter = median(judged);
  s.noise_to_tolerance = median(ratio);
  s.typical_rate = median(rate);
  return s;
}

}  // namespace core
}  // namespace hrg_gyro
