// One calibration run fed by two live streams (or a bag): wave angles, and the records of the
// rotation they are measured against -- turntable states, or in a field run the precession loop's
// states (the commanded virtual angle psi and rate in place of the table's; addRotationRecord takes
// either). The generator method is fed generator pairs instead.
//
// The streams arrive independently, so a wave sample is held until the rotation's stream has passed
// its stamp; it is then classified by the rotation records on either side of it: both must belong
// to the same settled plateau (a sample at a plateau boundary is skipped), and it is handed to the
// method with that plateau, the interpolated rotation angle and the reported rate. Memory is bounded:
// the wave queue and the rotation history are trimmed by age, the methods keep bins.
//
// The turntable stream always carries an angle and a rate. A stream whose angle is NaN from its start
// does not log the angle (rate-only): the table angle is then the integral of the reported rate. From
// its first finite angle a stream logs angles, and a NaN angle in it is a glitch. The plateau detector
// judges each record over a span centred on it, so records (and the wave samples between them) are
// classified half a smoothing span after they arrive.
//
// The table's records may be stamped by another computer (table_clock settings): a known offset is
// subtracted first, a fixed-rate log's stamps are put on the line through them against the record
// count (TableStampRegulariser) before anything else reads them, and every wave sample around a change
// of rate is kept to measure the offset that is left (TableClockOffsetEstimator), reported with the
// outcome and gated (table_clock/max_offset).
//
// A glitched rotation record (a non-finite or impossible rate, an infinite angle, a NaN angle or one
// the rate bound cannot reach in an angle-logging stream, a zero, duplicate or backward stamp, a
// stamp that jumps back or ahead) is dropped and counted by reason before the plateau detector sees
// it, so it cannot end a plateau; a wave sample whose stamp jumps is dropped and counted too. Both
// streams follow the one stamp rule (common/stamp_timeline.h; settings backward_reset, forward_jump,
// jump_persist), each against its own last stamp and the other stream's. A stream whose stamps go back
// for good (a looping bag) restarts the run from the prior: the bins hold the previous pass; one that
// goes ahead for good goes on across the gap. The live calibrator and hrg_bag calibrate both rely on this.
#pragma once

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_method_interface.h"
#include "hrg_gyro/core/common/ring_buffer.h"
#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/estimation/table_clock_offset.h"
#include "hrg_gyro/core/estimation/table_stamp_regulariser.h"
#include "hrg_gyro/core/model/gyro_parameters.h"

namespace hrg_gyro {
namespace core {

struct SessionCounters {
  std::uint64_t rotation_records = 0;        ///< rotation records received (turntable or precession states)
  std::uint64_t wave = 0;                    ///< wave samples received
  std::uint64_t used = 0;                    ///< handed to the method
  std::uint64_t unsettled = 0;               ///< not on a settled plateau (ramps, settling, boundaries)
  std::uint64_t unsynchronized = 0;          ///< no rotation record around the stamp (or too far away)
  std::uint64_t out_of_order = 0;            ///< wave samples dropped: zero, duplicate or slightly backward stamps
  std::uint64_t wave_jumps = 0;              ///< wave samples dropped: the stamp jumped (a glitch), all runs
  RotationRecordRejects rejected;            ///< rotation records dropped (glitches), all runs of the session
  std::uint64_t restarts = 0;                ///< a stream went back for good: the run started over
  std::uint64_t rotation_records_total = 0;  ///< rotation records received, all runs of the session
};

class CalibrationSession {
 public:
  CalibrationSession(const CalibrationSettings& settings, const GyroParameters& prior);

  /// A record of the rotation: a turntable state (the table's angle, NaN if not logged, and rate), or
  /// in a field run a precession state (the commanded virtual angle psi and rate). Returns false when
  /// the record was dropped (counted in counters().rejected). `sequence`: the record's header
  /// sequence number (TableStampRegulariser::kNoSequence when there is none); the stamps of a
  /// fixed-rate table log are regularised with it (table_clock settings).
  bool addRotationRecord(Nanoseconds stamp, double angle, double rate,
                         std::uint64_t sequence = TableStampRegulariser::kNoSequence);
  /// quadrature_ratio: B/A of the wave (NaN if unknown), averaged for the defect diagnosis.
  void addWave(Nanoseconds stamp, double theta, double frequency, double quadrature_ratio = NAN);
  void addGeneratorPair(Nanoseconds stamp, const ChannelVector& raw, const ChannelVector& reference);
  /// The generator stream has moved past its sweep (told by that same stream, so it cannot be
  /// confused by another stream's lag): the correction-matrix run may finish.
  void generatorSweepEnded();
  /// A triad's axis on the table: the method fits the Earth's horizontal rate of up to `slots` fixture
  /// positions, and `tag` gives each settled sample its slot and the platter's heading (before any
  /// record; kept over a restart). False when the method does not model it.
  bool modelHorizontalEarthRate(int slots, std::function<void(PlateauSample*)> tag);

  const CalibrationSettings& settings() const { return settings_; }
  const GyroParameters& prior() const { return prior_; }
  const SessionCounters& counters() const { return counters_; }
  CalibrationProgress progress() const { return method_->progress(); }
  bool complete() const { return method_->complete(); }
  /// Auto-finish rule: the data are complete and the table has rested for auto_finish_idle s (for
  /// the correction matrix: the generator sweep has ended).
  bool shouldFinish() const;
  /// Fits, applies the gates and builds the new parameters (does not write anything). When the
  /// method found too few samples on settled plateaus (or too little coverage, for a named cause),
  /// a failed `plateaus` gate comes first and says why, from what the session saw.
  CalibrationOutcome finish() const;
  /// Why few wave samples landed on settled plateaus, in the test engineer's terms, from the
  /// counters and the detector's measurements. *names_a_cause: false when it can only say how much
  /// of the data lay on settled plateaus.
  std::string plateauDiagnosis(bool* names_a_cause = nullptr) const;

 private:
  struct WaveRecord {
    Nanoseconds stamp;
    double theta, frequency;
  };
  void drain();
  /// Whether the values of a rotation record are possible; counts the reason when not.
  bool plausible(Nanoseconds stamp, double angle, double rate);
  /// The stream went back for good: drop what the run gathered, start over from the prior.
  void restart();
  void classify(const WaveRecord& w);
  /// The table clock's report and gate, from the regulariser and the changes of rate.
  void reportTableClock(CalibrationOutcome* outcome) const;
  /// Variance (rad^2) the regularised stamps leave on the table angle at this rate, smooth in time.
  double regularisedAngleError(double rate) const;

  CalibrationSettings settings_;
  GyroParameters prior_;
  std::unique_ptr<CalibrationMethod> method_;
  int horizontal_slots_ = 0;  // modelHorizontalEarthRate's, for a restarted method
  std::function<void(PlateauSample*)> horizontal_tag_;
  PlateauDetector detector_;
  RingBuffer<PlateauRecord> rotation_;  // judged rotation records
  std::vector<PlateauRecord> judged_;   // scratch: records the detector has just judged
  RingBuffer<WaveRecord> pending_;
  TableStampRegulariser regulariser_;
  TableClockOffsetEstimator clock_offset_;
  SessionCounters counters_;
  StampTimeline rotation_timeline_;
  StampTimeline wave_timeline_;
  Nanoseconds last_wave_stamp_ = 0;
  int bad_angle_run_ = 0;       // rotation records in a row whose angle the rate bound cannot reach
  bool has_last_good_ = false;  // the last rotation record accepted, for the angle bound
  Nanoseconds last_good_stamp_ = 0;
  double last_good_angle_ = NAN;
  Nanoseconds last_generator_stamp_ = 0;
  bool generator_ended_ = false;
  double quadrature_sum_ = 0.0;  // of |B/A|, for the diagnosis's F factor
  std::uint64_t quadrature_count_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
