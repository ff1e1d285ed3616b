// The single-axis calibration's record switch: every input of a CalibrationSession passes through it,
// live (CalibratorRos), from a bag (hrg_bag calibrate) and from a simulation (calibrateOnSimulation),
// so the three route each record by one rule (the triad's is TriadFeed):
//   - raw channel samples: for a method fed by generator pairs (the correction matrix), to the pairing
//     with the generator's reference (GeneratorPairing); otherwise through the processor into wave
//     samples, when the front end has one (offline; live, the processor node sends the waves). A source
//     that knows which samples are the generator sweep's (the simulation, whose sample carries its
//     reference) hands them over as such: paired, never processed; the others, processed whatever
//     the method;
//   - wave samples, to the session;
//   - the table's states to the session as its rotation records; a method fed by the virtual rotation
//     (field) takes the precession loop's states in their place, and the other stream is ignored;
//   - the generator's reference to the pairing, and the end of the sweep (the reference stream leaves
//     it): the session is told once the raw channels, which may come over their own connection, have
//     reached that stamp too, or once the table's stream is kSweepChannelsWait s past it without them
//     (the sweep's last pairs are then given up).
// After each record it says what the front end must do: a run the session restarted (a stream went
// back for good; the feed forgets what it held for the run itself), and, when asked to watch for it
// (the live calibrator; offline tools finish at the end of their input), a run that may finish by
// itself (CalibrationSession::shouldFinish), checked on each rotation record, at the end of the sweep
// and again when the waves reach the latest rotation record (they come a hop later, through the
// processor). No ROS.
#pragma once

#include <cstdint>

#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/calibration/generator_pairing.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {

/// What one record asks of the front end.
struct FeedStep {
  bool restarted = false;       ///< the session started its run over (a stream went back for good)
  bool should_finish = false;   ///< watching: the auto-finish rule holds, finish the run now
  bool sweep_given_up = false;  ///< the raw channels did not reach the end of the sweep in time
};

class CalibrationFeed {
 public:
  /// s of the table's stream after the end of the generator sweep beyond which its raw channels are
  /// given up on.
  static constexpr double kSweepChannelsWait = 30.0;

  /// `session`: the run fed (nullptr: none yet, see startRun). `processor`: turns raw channels into
  /// wave samples; nullptr when the front end receives the waves. Neither is owned; both must outlive
  /// their use here. `watch_finish`: say when the run may finish by itself (FeedStep::should_finish): on
  /// the wave that reaches the record on which the auto-finish rule first held (the records after it are
  /// not the run's), so that the run holds the same samples however far the waves trail the records.
  explicit CalibrationFeed(CalibrationSession* session, GyroProcessor* processor = nullptr, bool watch_finish = false);
  // The pairing's sink points at this feed.
  CalibrationFeed(const CalibrationFeed&) = delete;
  CalibrationFeed& operator=(const CalibrationFeed&) = delete;

  /// A new run (nullptr: none): forgets the pairs waiting, the sweep's end and the streams' positions.
  void startRun(CalibrationSession* session);

  /// Raw channels of a stream that does not say whether they are the generator sweep's.
  FeedStep addChannels(const ChannelSample& in);
  /// Raw channels known to carry the gyro's own wave (not the sweep's): through the processor
  /// whatever the method, the wave sample filed under `wave_stamp` (the simulation's sample stamp,
  /// which a scheduled glitch of the channels' stamp leaves where it was).
  FeedStep addWaveChannels(const ChannelSample& in, Nanoseconds wave_stamp);
  /// A sample of the generator sweep with its reference: paired, whatever the method.
  FeedStep addSweepSample(Nanoseconds stamp, const ChannelVector& raw, const WaveParameters& reference);
  /// quadrature_ratio: B/A of the wave (NaN if unknown).
  FeedStep addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio);
  FeedStep addTableState(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence);
  FeedStep addPrecessionState(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence);
  /// The generator's wave at `stamp` (a record of the reference stream within the sweep).
  FeedStep addReference(Nanoseconds stamp, const WaveParameters& wave);
  /// A record of the reference stream outside the sweep: the sweep has ended at `stamp`.
  FeedStep addSweepEnd(Nanoseconds stamp);

  /// The newest wave stamp of the run (0: none yet).
  Nanoseconds newestWave() const { return newest_wave_; }

 private:
  FeedStep addRotation(Nanoseconds stamp, double angle, double rate, std::uint64_t sequence);
  FeedStep addWaveRecord(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio);
  /// After a record went into the session: a restarted run starts the feed's own state over too.
  void noteRestart(std::uint64_t restarts_before, FeedStep* step);
  void forgetRun();
  std::uint64_t droppedWaves() const;  // wave samples the session dropped (jumps, out of order)
  FeedStep endSweep();

  CalibrationSession* session_ = nullptr;
  GyroProcessor* processor_ = nullptr;
  bool watch_finish_ = false;
  bool pairs_ = false;             // the run's method is fed by generator pairs
  bool virtual_rotation_ = false;  // the run's method is fed by the precession loop's states
  GeneratorPairing pairing_;
  // The reference stream left the sweep at this stamp (0: not yet); the raw channels' newest stamp.
  Nanoseconds sweep_end_ = 0, last_channels_ = 0;
  // Watching: the latest rotation record that did not finish the run, and whether the waves have
  // reached its stamp since.
  Nanoseconds last_rotation_ = 0;
  bool waves_reached_rotation_ = true;
  Nanoseconds newest_wave_ = 0;
  Nanoseconds last_taken_wave_ = 0;  // the newest wave the session took (glitches left out)
  bool finish_pending_ = false;      // the rule ended the run on a record the waves have not reached
};

}  // namespace core
}  // namespace hrg_gyro
