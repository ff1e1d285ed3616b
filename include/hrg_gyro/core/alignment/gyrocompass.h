// North-finding from the Earth's rate (gyrocompassing): the one object the gyrocompass node and the
// offline tool feed with the records of a window, each stream in stamp order, and read the result
// from. Same records, same result, bit for bit.
//
// Streams, by mode (alignment_settings.h says what each mode resolves):
//   static   addTriad (the triad combiner's body samples), a gravity reference;
//   indexed  addTriad, or addAxis for one gyro (single_gyro), and addIndexer (the indexer's or rate
//            table's state: stamp, angle, rate), a gravity reference;
//   sweep    addSweepAxis per axis (each axis processor's outputs, PRECESSING flags and all) and
//            addPrecession per axis (its driver's precession state: the commanded rate and angle),
//            the triad's file for M and the body bias, a gravity reference;
//   gravity  addAccelerometer (an IMU on the same mount, its mounting a setting), or a declared level.
//
// The window is `duration` s of gyro stamps from the first sample's start; complete() says when
// it is full. finish() fits, levels, finds the heading and its error budget, and applies the gates:
//   latitude    above max_latitude (checked at once: the object starts refused);
//   motion      the base moved beyond what the still-base fit carries (too many steps, too much of the
//               window in transitions, block mean rates spread beyond 2 max_motion within a rest) and
//               no tracking estimator could answer, or the wave was turned on command outside the
//               sweep mode (motion_gate.h);
//   stillness   the residuals scatter beyond max_scatter times the noise model's prediction, per
//               point or per block mean (a sway), and no tracking estimator could answer;
//   level       no gravity reference, or |f| not g;
//   design      the data cannot resolve the heading: one gyro at two positions (one horizontal
//               component), positions that do not differ, a sweep that does not turn both ways;
//   earth_rate  the horizontal rate measured is not the Earth's (a gross bias, a wrong latitude);
//   earth_check the measured Earth rate's length, its part along the measured up, or its angle to
//               the up disagrees with the declared latitude beyond max_earth_sigmas (earth_checks.h);
//   tracking    estimator tracking asked for and not possible;
//   attitude    the body's x axis too close to vertical for a heading.
// Which estimator answers, the still-base fit or the tracking one: gyrocompass_solver.h.
//
// Time: every stream follows the one stamp rule (stamp_timeline.h; backward_reset 0.5 s, forward_jump
// 1 s, jump_persist 5): a glitched stamp is dropped and counted, costing its sample only; a gyro
// stream that goes back for good restarts the window on its new timeline (counted in `restarts`),
// an accelerometer's or indexer's that does drops its old records. A gyro sample whose dt does not
// match its stamps (beyond half of it) is dropped as a glitch, never integrated. Records of the
// other streams older than the window are not kept.
// Each fit is on the integrated angles (integrated_angle_fit.h), in segments: a gap or reset, an
// indexer position, a commanded rate each start a new one. In the indexed mode a channel with
// sensitive direction d (platform frame) at indexer angle psi senses
//     b_c + w_x (d_x cos psi - d_y sin psi) + w_y (d_x sin psi + d_y cos psi) + d_z (v + psi')
// (w the Earth's rate in the indexer's zero frame, v its vertical part); the known table rate psi' is
// removed, v goes into the channel's bias b_c, and (w_x, w_y, v) is levelled. In the sweep mode
// each axis's output is fitted as omega_i t + g_i psi_cmd(t) + sum_k (s_k sin k psi_cmd + c_k cos k
// psi_cmd) (the commanded angle psi_cmd, executed with the gain G_v / K0 = g_i and its harmonics),
// within segments of one commanded rate, settle s after each change left out, and the body rate is
// M omega - bias. The vehicle's own travel over the Earth is out of scope. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "hrg_gyro/core/alignment/alignment_result.h"
#include "hrg_gyro/core/alignment/alignment_settings.h"
#include "hrg_gyro/core/alignment/gyrocompass_records.h"
#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/triad_parameters.h"
#include "hrg_gyro/core/processing/precession_watch.h"
#include "hrg_gyro/core/processing/triad_combiner.h"

namespace hrg_gyro {
namespace core {

struct AlignmentProgress {
  double seconds = 0.0;   ///< of gyro stamps in the window so far
  double duration = 0.0;  ///< the window's
  bool complete = false;  ///< full, or refused
  bool refused = false;   ///< refused before the end (latitude, motion, a commanded wave, abort)
  std::string reason;
  std::uint64_t samples = 0;   ///< gyro samples taken (per channel)
  std::uint64_t gaps = 0;      ///< gaps and resets in the gyro input
  std::uint64_t dropped = 0;   ///< records dropped: out of order, duplicate, not finite, a glitched stamp or dt
  std::uint64_t restarts = 0;  ///< the window restarted: the gyro stream went back to a new timeline
  std::uint64_t indexer = 0, accelerometer = 0, precession = 0;  ///< records taken
  std::uint64_t held = 0;  ///< indexer, accelerometer and precession records held in memory now
};

class Gyrocompass {
 public:
  /// Throws ConfigError (naming the key) for bad settings, and for a noise term or level sigma not
  /// given (AlignmentSettings::requireComplete): a residual bias not given is the triad file's
  /// largest bias_std when that file is calibrated (bias_std not all 0). `triad`: the triad's file,
  /// used by the sweep mode (M and the body bias applied to the axes' outputs).
  explicit Gyrocompass(const AlignmentSettings& settings, const TriadParameters& triad = TriadParameters());

  void addTriad(const TriadBodySample& sample);
  void addAxis(const AxisOutput& output);
  void addSweepAxis(std::size_t axis, const AxisOutput& output);
  void addPrecession(std::size_t axis, const PrecessionStateRecord& record);
  void addIndexer(const IndexerRecord& record);
  void addAccelerometer(const AccelerometerRecord& record);

  /// The window is full (a gyro stamp reached its end on every stream), or the alignment was refused.
  bool complete() const;
  /// Ends it with a reason (a service call, shutdown, the input stopped).
  void abort(const std::string& reason);
  AlignmentProgress progress() const;
  /// Solves with what the window holds (complete or not) and applies the gates.
  AlignmentResult finish() const;

  const AlignmentSettings& settings() const { return settings_; }
  /// The window's start and end, gyro stamps (0 before the first sample).
  Nanoseconds windowStart() const { return records_.start; }
  Nanoseconds windowEnd() const { return records_.end; }

 private:
  // What the intake keeps of one gyro stream beside its records: a break pending, full, its stamp rule.
  struct StreamIntake {
    bool pending_break = false;
    bool full = false;
    StampTimeline timeline{gyrocompassStampRule()};
  };
  static StampRule gyrocompassStampRule();

  bool admit(std::size_t stream, Nanoseconds stamp, double dt, const double* increment, std::size_t channels, bool gap,
             bool precessing);
  bool timed(std::size_t stream, Nanoseconds stamp, double dt);
  void restartWindow();
  void startWindow(Nanoseconds stamp, double dt);
  // The one stamp rule for a record stream (accelerometer, indexer, precession): false to drop it;
  // a stream gone back for good loses its old records.
  template <typename Record>
  bool takeRecord(StampTimeline* timeline, std::vector<Record>* records, Nanoseconds stamp);
  bool beforeWindow(Nanoseconds stamp) const;  // older than the window by more than a second: not kept
  void refuse(const std::string& gate, const std::string& reason);
  void resolveNoise();

  AlignmentSettings settings_;
  GyrocompassRecords records_;  // what finish() hands the solver
  std::array<StreamIntake, 3> intake_;
  StampTimeline indexer_time_{gyrocompassStampRule()}, accelerometer_time_{gyrocompassStampRule()};
  std::array<StampTimeline, 3> precession_time_{{StampTimeline(gyrocompassStampRule()),
                                                 StampTimeline(gyrocompassStampRule()),
                                                 StampTimeline(gyrocompassStampRule())}};
  std::uint64_t gaps_ = 0, dropped_ = 0, restarts_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
