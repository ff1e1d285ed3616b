// The live triad calibration's input, put back in stamp order. The calibrator in triad mode receives
// five streams over separate connections: each axis's wave angle, the table's state and the
// fixture's position. Which fixture record is in force at a record's stamp decides whether an axis's
// dual-rate stage sees it (TriadCalibration routes by the fixture timeline it has been given so far),
// and hrg_bag calibrate --method triad reads a bag in stamp order. Live, the fixture's record (sent on
// each change and once a second) may arrive after the data it governs; so may one axis's waves after
// another's. TriadFeed holds every record until each stream has delivered a record at or after its
// stamp, or until it lies `hold` s of stream time behind the newest stamp received (a silent or
// missing stream delays the others by that much, no more), and hands the records to a
// TriadCalibration in stamp order (equal stamps: the fixture, then the table, then the axes in
// order). The calibration thus sees what it would see reading a stamp-sorted bag of the same
// messages. A stream that lags more than the hold (a busy computer; sim time run faster than the
// wall clock shortens the hold in wall time by its factor) still has its records fed, in its own
// order, after later stamps of the others (counted as late): nothing is lost, but where such a record
// falls at a change of the fixture's state it is routed by the state fed so far. A record stamped
// far ahead of the others (a clock glitch) ends the others' hold early in the same way.
//
// Bad input is dropped and counted, never fed: a zero stamp; a non-finite wave angle; a fixture
// orientation that is not a rotation (acceptFixtureOrientation); a record out of order or whose stamp
// jumps, by the one stamp rule (common/stamp_timeline.h), each stream against its own last record and
// the newest of the others: a single record stamped far ahead no longer ends the others' hold. A
// stream that goes back for good (a bag loop, a restarted simulator) has moved to a new timeline: the
// run starts over from the priors (restarts counted).
//
// Auto-finish (shouldFinish): auto_finish_idle > 0, every axis has pointed along the table axis in a
// locked fixture position (the least an accepted run needs), and the fixture has since been released
// (unlocked) and stayed so for auto_finish_idle s of stream time. No ROS.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>

#include "hrg_gyro/core/calibration/triad/triad_calibration.h"

namespace hrg_gyro {
namespace core {

/// What one input stream has delivered; the records dropped by reason (TriadStreamRejects: a zero
/// stamp, a bad value, out of order, a stamp jump) were not queued.
struct TriadStreamCounters : TriadStreamRejects {
  std::uint64_t received = 0;  ///< records offered
  std::uint64_t fed = 0;       ///< handed to the calibration
  std::uint64_t late = 0;      ///< fed after later-stamped records of other streams (it lagged beyond the hold)
  Nanoseconds last_stamp = 0;  ///< newest stamp received (0: none yet)
};

struct TriadFeedSettings {
  double hold = 2.0;              ///< s of stream time a record may wait for the other streams
  double auto_finish_idle = 0.0;  ///< s with the fixture released after full coverage; <= 0: never
  StampRule stamps;               ///< the stamp rule (usually the calibration settings' stampRule())
};

class TriadFeed {
 public:
  /// The five streams, in the order records of equal stamps are fed (the fixture first).
  enum Stream {
    kFixture = kFixtureStream,
    kTable = kTableStream,
    kAxis0 = kAxisStream0,
    kStreamCount = kTriadStreamCount
  };

  /// The calibration's arguments as TriadCalibration's; `feed` as above (stamps and
  /// auto_finish_idle are usually the calibration settings').
  TriadFeed(const CalibrationSettings& axis_settings, const TriadCalibrationSettings& settings,
            const std::array<GyroParameters, 3>& priors, const TriadParameters& prior_triad,
            const TriadFeedSettings& feed);
  ~TriadFeed();

  void addWave(int axis, Nanoseconds stamp, double theta, double frequency);
  void addTurntable(Nanoseconds stamp, double angle, double rate,
                    std::uint64_t sequence = TableStampRegulariser::kNoSequence);
  /// The orientation is checked here (acceptFixtureOrientation).
  void addFixture(FixtureRecord record);

  /// See the auto-finish rule above.
  bool shouldFinish() const;
  /// Feeds every record still held, in stamp order, and runs the calibration. Notes an axis whose
  /// stream fed nothing. The feed is spent afterwards.
  TriadOutcome finish();

  const TriadStreamCounters& counters(int stream) const { return counters_[stream]; }
  /// Records held, waiting for the other streams.
  std::size_t held() const;
  std::uint64_t restarts() const { return restarts_; }
  /// The last fixture record fed (nullptr: none yet).
  const FixtureRecord* fixture() const { return has_fixture_ ? &fixture_ : nullptr; }
  /// Per axis: it pointed along the table axis in a locked position fed so far.
  const std::array<bool, 3>& axesAlongTable() const { return along_table_; }
  /// Locked positions fed so far (changes of the fixture into a locked state).
  std::uint64_t lockedPositions() const { return locked_positions_; }
  /// s of stream time fed, first stamp to last.
  double duration() const;

 private:
  struct Item {
    Nanoseconds stamp;
    double a, b;  // wave: theta, frequency; table: angle, rate
    std::uint64_t sequence;
  };
  /// True when the record may be queued; handles out-of-order records and a new timeline.
  bool admit(int stream, Nanoseconds stamp);
  void queue(int stream, const Item& item);
  /// Feeds the held records that may go (all of them with `everything`).
  void release(bool everything);
  void feedFixture(const FixtureRecord& record);
  void restart();
  Nanoseconds headStamp(int stream) const;

  CalibrationSettings axis_settings_;
  TriadCalibrationSettings settings_;
  std::array<GyroParameters, 3> priors_;
  TriadParameters prior_triad_;
  TriadFeedSettings feed_;
  std::unique_ptr<TriadCalibration> calibration_;

  std::array<std::deque<Item>, kStreamCount> items_;  // the fixture's slot unused
  std::deque<FixtureRecord> fixtures_;
  std::array<TriadStreamCounters, kStreamCount> counters_;
  std::array<StampTimeline, kStreamCount> timelines_;
  Nanoseconds newest_ = 0;     // newest stamp received on any stream (this timeline)
  Nanoseconds fed_until_ = 0;  // latest stamp fed
  Nanoseconds first_fed_ = 0;
  std::uint64_t restarts_ = 0;

  bool has_fixture_ = false;
  FixtureRecord fixture_;
  std::array<bool, 3> along_table_{{false, false, false}};
  std::uint64_t locked_positions_ = 0;
  Nanoseconds released_since_ = 0;  // stamp the fixture was released at (0: locked or never locked)
};

}  // namespace core
}  // namespace hrg_gyro
