// A triad calibrated on a single-axis rate table, the multi-position way: the three gyros sit in a
// fixture that the operator turns through positions (which body axis points along the table axis, up
// or down, and tilted ones), each with its table profile, and the bench logs the fixture's position.
//
// Three stages, all from one session, each in a file of its own:
//  1. Each axis's K(theta) and D(theta): today's dual-rate method, fed with the axis's wave angle and
//     the table while the axis points along the table axis (up, or down with the table angle's sign
//     turned and the Earth's vertical rate with it), one single-axis CalibrationSession per axis
//     (here: fitAxes). An axis leans off the table's axis by its misalignment and the fixture's
//     error, so it also senses the Earth's horizontal rate turning with the table; each position's
//     lean is fitted with K and D (two unknowns per position and axis, the session's horizontal
//     slots, up to kHorizontalSlots positions per axis), so that rate does not land in D(theta).
//  2. The axes' directions A in the body frame: in every fixture position, each axis's compensated
//     increments (stage 1's K and D applied to its wave angle: triad_position_samples.h) against the
//     table angle give its response c_i,p = A_i . u_p to the table's rate (u_p: the table axis in the
//     body frame, from the position's logged orientation); A_i is then the least-squares solution
//     over the positions: at least three independent table-axis directions are needed (refused
//     otherwise, the missing body axes named). M = A^-1 (triad_axis_directions.h).
//  3. The body bias: in every rest of a locked position, the axes' mean compensated rates through M
//     against the Earth's 3-D rate in the body frame (latitude from the axes' parameter files, the
//     table's azimuth from the settings, the table angle at rest from the log), with its standard
//     error (triad_body_bias.h).
//
// A fixture position off by a small rotation makes u_p, and so the responses of that position, off by
// it: the error enters A as the least-squares image of the positions' errors (docs/triad.md).
//
// Every record goes through its stream's stamp rule first (common/stamp_timeline.h, the axes'
// settings backward_reset, forward_jump and jump_persist, each stream against its own last stamp and
// the others' newest): a record whose stamp jumps is dropped and counted, as is a fixture orientation
// that is no rotation and a non-finite wave angle; the outcome's notes say how many. A stream that
// goes back for good (a recording across a restarted driver) starts the calibration over.
//
// Memory: stage 1 is streamed (the sessions' sums); stages 2 and 3 keep each axis's wave angle and the
// table's angle as block means at `store_rate`, and the fixture's timeline. No ROS.
#pragma once

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <vector>

#include "hrg_gyro/core/calibration/calibration_session.h"
#include "hrg_gyro/core/calibration/triad/triad_calibration_settings.h"
#include "hrg_gyro/core/calibration/triad/triad_outcome.h"
#include "hrg_gyro/core/calibration/triad/triad_position_samples.h"

namespace hrg_gyro {
namespace core {

/// The input streams of a triad calibration, in the order records of equal stamps are taken.
enum TriadStream : int { kFixtureStream = 0, kTableStream = 1, kAxisStream0 = 2, kTriadStreamCount = 5 };

/// The records of one input stream that were dropped, by reason.
struct TriadStreamRejects {
  std::uint64_t bad_stamp = 0;     ///< zero or negative
  std::uint64_t bad_value = 0;     ///< a non-finite wave angle, or a fixture orientation that is no rotation
  std::uint64_t out_of_order = 0;  ///< a duplicate, or behind the last good stamp by at most backward_reset
  std::uint64_t stamp_jump = 0;    ///< further back or ahead: a glitch (or the first records of a real jump)
  std::uint64_t total() const { return bad_stamp + bad_value + out_of_order + stamp_jump; }
  /// Whether a record of this stamp verdict (common/stamp_timeline.h) goes on: kNext, kResumedAhead
  /// and kNewTimeline do; any other is dropped, and counted here.
  bool admits(StampVerdict verdict);
};

/// The fixture's position as the bench logs it (hrg_gyro/FixturePosition).
struct FixtureRecord {
  Nanoseconds stamp = 0;
  std::uint32_t index = 0;
  std::string name;
  Eigen::Quaterniond body_to_table = Eigen::Quaterniond::Identity();
  bool locked = false;
};

/// The fixture record's orientation checked as a rotation: false when the quaternion is not finite
/// or its norm is off 1 by more than 1e-3 (not a rotation: the record is not used); otherwise it is
/// normalised in place.
bool acceptFixtureOrientation(FixtureRecord* record);

class TriadCalibration {
 public:
  /// `axis_settings`: the dual-rate settings of stage 1 (method is forced to dual_rate); `priors`:
  /// each axis's parameter file in the triad's axis order (their P is kept; their latitude is the
  /// site's); `prior_triad`: the triad file whose frame_id and axis names the result keeps.
  TriadCalibration(const CalibrationSettings& axis_settings, const TriadCalibrationSettings& settings,
                   const std::array<GyroParameters, 3>& priors, const TriadParameters& prior_triad);
  // The sessions call back into this object: it stays where it was made.
  TriadCalibration(const TriadCalibration&) = delete;
  TriadCalibration& operator=(const TriadCalibration&) = delete;

  /// Positions per axis whose lean stage 1 fits (a later one's horizontal Earth rate is not modelled,
  /// and the outcome says so).
  static constexpr int kHorizontalSlots = 8;

  /// The orientation is checked (acceptFixtureOrientation): one that is no rotation is dropped.
  void addFixture(FixtureRecord record);
  /// The table's records (one stream for the whole fixture); sequence as in CalibrationSession.
  void addTurntable(Nanoseconds stamp, double angle, double rate,
                    std::uint64_t sequence = TableStampRegulariser::kNoSequence);
  /// Axis `axis` (0..2, the triad's order)'s wave angle from its processor (prior P applied).
  void addWave(int axis, Nanoseconds stamp, double theta, double frequency = NAN);

  /// Runs the three stages; writes nothing.
  TriadOutcome finish() const;

  /// Records of stream `stream` (TriadStream) dropped so far, this run and earlier ones.
  const TriadStreamRejects& rejects(int stream) const { return rejects_[stream]; }
  /// Times a stream went back for good and the calibration started over.
  std::uint64_t restarts() const { return restarts_; }

 private:
  /// The stamp rule of `stream`; false when the record is dropped (counted). A stream that went
  /// back for good starts the calibration over, this record first.
  bool admit(int stream, Nanoseconds stamp);
  /// Forgets every record: a new timeline.
  void restart();
  /// Axis `axis`'s session for a new run, fitting each position's horizontal Earth rate.
  std::unique_ptr<CalibrationSession> makeSession(int axis);
  /// A settled sample of axis `axis`: the slot of its fixture position and the platter's heading.
  void tagHorizontal(int axis, PlateauSample* sample);
  /// Each axis's lean per position from its stage-1 horizontal Earth rate (and a note for positions
  /// beyond the slots).
  void measureTilts(TriadOutcome* o) const;
  /// The notes on dropped records and restarts.
  void noteRejects(TriadOutcome* o) const;
  /// Why a refusal for want of positions may lie in the fixture records dropped ("" when none was).
  std::string fixtureDrops() const;
  /// Stage 1: each axis's outcome and gate into *o; the axes' parameters, calibrated where accepted.
  std::array<GyroParameters, 3> fitAxes(TriadOutcome* o) const;
  /// The locked positions with their samples, for stages 2 and 3.
  std::vector<TriadLockedPosition> lockedPositions(const std::array<GyroParameters, 3>& params) const;
  /// Samples averaged over blocks of 1 / store_rate s (not picked): the stored series keeps the noise
  /// reduction of every sample. A block ends at its length, at a gap or at a stamp that goes back.
  struct BlockMean {
    Nanoseconds start = 0, last = 0;
    double time = 0.0, value = 0.0, rate = 0.0;  // sums: s from start, the value, the rate
    int count = 0;
  };
  /// Adds a sample to `block`; a completed block's mean goes to `out` (and its mean rate to `rates`).
  void addToBlock(BlockMean* block, Nanoseconds stamp, double value, double rate, StampedSeries* out,
                  std::vector<double>* rates) const;
  /// The fixture record in force at `stamp` (nullptr: none yet).
  const FixtureRecord* fixtureAt(Nanoseconds stamp) const;
  /// +1 or -1 when axis `axis` points up or down the table axis in `fixture`, 0 otherwise.
  int verticalSign(const FixtureRecord& fixture, int axis) const;

  CalibrationSettings axis_settings_;
  TriadCalibrationSettings settings_;
  std::array<GyroParameters, 3> priors_;
  TriadParameters prior_triad_;
  std::array<std::unique_ptr<CalibrationSession>, 3> sessions_;
  std::vector<FixtureRecord> fixtures_;  // every change of the fixture's state, in order
  std::array<StampedSeries, 3> waves_;   // each axis's wave angle, thinned
  StampedSeries table_;                  // the table angle, thinned
  std::vector<double> table_rates_;      // the reported rate of each stored table sample
  std::array<BlockMean, 3> wave_blocks_;
  BlockMean table_block_;
  double table_unwrapped_ = NAN;  // the last table angle, unwrapped
  Nanoseconds origin_ = 0;        // first stamp seen: the Earth-rate term's time origin
  std::array<StampTimeline, kTriadStreamCount> timelines_;
  std::array<TriadStreamRejects, kTriadStreamCount> rejects_;
  std::array<std::vector<std::size_t>, 3> slot_records_;  // per axis, the fixtures_ index of each slot
  std::array<std::uint64_t, 3> unslotted_{};              // samples of positions beyond the slots
  std::uint64_t restarts_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
