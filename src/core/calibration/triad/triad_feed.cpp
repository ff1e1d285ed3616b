#include "hrg_gyro/core/calibration/triad/triad_feed.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

// Bound on the records held per stream, whatever the stamps do: beyond it the oldest goes on
// unordered (at 10 kHz, 100 s of one axis's waves).
constexpr std::size_t kMaxHeld = 1000000;

constexpr Nanoseconds kNever = std::numeric_limits<Nanoseconds>::max();

// s of its own stamps a stream may stay on the old timeline after another went back for good.
constexpr double kFollowGiveUp = 60.0;

std::array<StampTimeline, TriadFeed::kStreamCount> makeTimelines(const StampRule& rule) {
  const StampTimeline t(rule);
  return {{t, t, t, t, t}};
}

}  // namespace

TriadFeed::TriadFeed(const CalibrationSettings& axis_settings, const TriadCalibrationSettings& settings,
                     const std::array<GyroParameters, 3>& priors, const TriadParameters& prior_triad,
                     const TriadFeedSettings& feed)
    : axis_settings_(axis_settings),
      settings_(settings),
      priors_(priors),
      prior_triad_(prior_triad),
      feed_(feed),
      timelines_(makeTimelines(feed.stamps)) {
  if (!(feed_.hold >= 0.0)) throw std::invalid_argument("triad feed: the hold must be >= 0 s");
  calibration_ = std::make_unique<TriadCalibration>(axis_settings_, settings_, priors_, prior_triad_);
}

TriadFeed::~TriadFeed() = default;

void TriadFeed::restart() {
  ++restarts_;
  calibration_ = std::make_unique<TriadCalibration>(axis_settings_, settings_, priors_, prior_triad_);
  for (auto& q : items_) q.clear();
  fixtures_.clear();
  for (TriadStreamCounters& c : counters_) c.last_stamp = 0;
  newest_ = fed_until_ = first_fed_ = 0;
  has_fixture_ = false;
  fixture_ = FixtureRecord();
  along_table_ = {{false, false, false}};
  locked_positions_ = 0;
  released_since_ = 0;
}

bool TriadFeed::admit(int stream, Nanoseconds stamp) {
  TriadStreamCounters& c = counters_[stream];
  ++c.received;
  // The newest stamp of the other streams: a stream rejoining them after a silence is no jump.
  Nanoseconds others = 0;
  for (int s = 0; s < kStreamCount; ++s) {
    if (s != stream) others = std::max(others, counters_[s].last_stamp);
  }
  const StampVerdict verdict = timelines_[stream].check(stamp, others);
  if (!c.admits(verdict)) return false;
  if (verdict == StampVerdict::kNewTimeline) {
    restart();  // this record is the first of the new timeline; the others are about to follow
    for (int s = 0; s < kStreamCount; ++s) {
      if (s != stream) timelines_[s].expectJumpBack(kFollowGiveUp);
    }
    c.last_stamp = stamp;
    newest_ = stamp;
    return true;
  }
  if (stamp < fed_until_) ++c.late;  // fed next, behind later stamps of the other streams
  c.last_stamp = stamp;
  newest_ = std::max(newest_, stamp);
  return true;
}

// Admitted records come in their stream's order: each stream's queue stays sorted.
void TriadFeed::queue(int stream, const Item& item) { items_[stream].push_back(item); }

void TriadFeed::addWave(int axis, Nanoseconds stamp, double theta, double frequency) {
  if (axis < 0 || axis > 2) throw std::invalid_argument("triad feed: axis must be 0, 1 or 2");
  const int stream = kAxis0 + axis;
  if (!std::isfinite(theta)) {
    ++counters_[stream].received;
    ++counters_[stream].bad_value;
    return;
  }
  if (!admit(stream, stamp)) return;
  queue(stream, {stamp, theta, frequency, 0});
  release(false);
}

void TriadFeed::addTurntable(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence) {
  if (!admit(kTable, stamp)) return;
  queue(kTable, {stamp, angle, rate, sequence});
  release(false);
}

void TriadFeed::addFixture(FixtureRecord record) {
  if (!acceptFixtureOrientation(&record)) {
    ++counters_[kFixture].received;
    ++counters_[kFixture].bad_value;
    return;
  }
  if (!admit(kFixture, record.stamp)) return;
  fixtures_.push_back(std::move(record));
  release(false);
}

Nanoseconds TriadFeed::headStamp(int stream) const {
  if (stream == kFixture) return fixtures_.empty() ? kNever : fixtures_.front().stamp;
  return items_[stream].empty() ? kNever : items_[stream].front().stamp;
}

std::size_t TriadFeed::held() const {
  std::size_t n = fixtures_.size();
  for (const auto& q : items_) n += q.size();
  return n;
}

void TriadFeed::release(bool everything) {
  for (;;) {
    int stream = -1;
    Nanoseconds t = kNever;
    for (int s = 0; s < kStreamCount; ++s) {
      const Nanoseconds h = headStamp(s);
      if (h < t) {  // strictly: equal stamps go in stream order
        t = h;
        stream = s;
      }
    }
    if (stream < 0) return;
    if (!everything) {
      // Every stream has delivered up to t (nothing earlier can come but late), or t lies the hold
      // behind the newest stamp, or a stream holds too much.
      bool ready = toSeconds(newest_ - t) >= feed_.hold;
      if (!ready) {
        ready = true;
        for (int s = 0; s < kStreamCount; ++s) ready = ready && counters_[s].last_stamp >= t;
      }
      for (int s = 0; s < kStreamCount && !ready; ++s) {
        ready = (s == kFixture ? fixtures_.size() : items_[s].size()) > kMaxHeld;
      }
      if (!ready) return;
    }
    fed_until_ = std::max(fed_until_, t);
    if (first_fed_ == 0) first_fed_ = t;
    ++counters_[stream].fed;
    if (stream == kFixture) {
      const FixtureRecord record = std::move(fixtures_.front());
      fixtures_.pop_front();
      feedFixture(record);
    } else {
      const Item item = items_[stream].front();
      items_[stream].pop_front();
      if (stream == kTable) {
        calibration_->addTurntable(item.stamp, item.a, item.b, item.sequence);
      } else {
        calibration_->addWave(stream - kAxis0, item.stamp, item.a, item.b);
      }
    }
  }
}

void TriadFeed::feedFixture(const FixtureRecord& record) {
  calibration_->addFixture(record);
  const bool was_locked = has_fixture_ && fixture_.locked;
  if (record.locked) {
    if (!was_locked || record.index != fixture_.index) ++locked_positions_;
    // The rule TriadCalibration applies: |u . e_i| >= 1 - vertical_tolerance.
    const Eigen::Vector3d u = record.body_to_table.toRotationMatrix().transpose() * Eigen::Vector3d::UnitZ();
    for (int i = 0; i < 3; ++i) {
      if (std::abs(u(i)) >= 1.0 - settings_.vertical_tolerance) along_table_[i] = true;
    }
    released_since_ = 0;
  } else if (was_locked) {
    released_since_ = record.stamp;
  }
  fixture_ = record;
  has_fixture_ = true;
}

bool TriadFeed::shouldFinish() const {
  if (!(feed_.auto_finish_idle > 0.0) || released_since_ == 0) return false;
  if (!(along_table_[0] && along_table_[1] && along_table_[2])) return false;
  return toSeconds(fed_until_ - released_since_) >= feed_.auto_finish_idle;
}

double TriadFeed::duration() const { return first_fed_ == 0 ? 0.0 : toSeconds(fed_until_ - first_fed_); }

TriadOutcome TriadFeed::finish() {
  release(true);
  TriadOutcome o = calibration_->finish();
  for (int i = 0; i < 3; ++i) {
    if (counters_[kAxis0 + i].fed == 0) {
      o.notes.push_back("axis " + prior_triad_.axes[i] + ": no wave sample was fed (its stream delivered " +
                        std::to_string(counters_[kAxis0 + i].received) + " records)");
    }
  }
  if (counters_[kFixture].fed == 0) {
    o.notes.push_back("no fixture position was fed (" + std::to_string(counters_[kFixture].received) +
                      " records received, " + std::to_string(counters_[kFixture].bad_value) + " not a rotation)");
  }
  return o;
}

}  // namespace core
}  // namespace hrg_gyro
