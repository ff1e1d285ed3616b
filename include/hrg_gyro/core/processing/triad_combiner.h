// Three gyros as one IMU: each axis's compensated outputs of the same stamp combined into one
// body-frame sample, through the triad file's matrix and bias (triad_parameters.h):
//
//   delta_angle_body = M dalpha - bias dt            rad, body frame
//   angular_velocity = delta_angle_body / dt         rad/s (as delta times 1/dt: one division a sample)
//   covariance       = M diag(sigma_i^2) M^T         (rad/s)^2, of angular_velocity
//
// dalpha = (dalpha_1, dalpha_2, dalpha_3) in the order of the file's `axes`, each the axis
// processor's output (GyroOutput.dalpha) for the interval dt ending at the stamp; sigma_i^2 the
// variance of that axis's rate (its processor's Imu angular_velocity_covariance[8]).
//
// The three resonators are sampled by one clock, so each stamp should come from every axis. The
// combiner holds each axis's outputs in a FIFO and merges the three streams by stamp:
//   - a stamp that every axis has (within the stamp tolerance), over the same interval dt, is
//     combined;
//   - a stamp that an axis skipped (its processor dropped that sample: the axis's next output,
//     already here, spans it) is not emitted: the other axes' increments of that stamp are carried
//     into the next stamp, which is combined over both intervals (dt the sum) when every axis's
//     interval then agrees. The output skips the stamp as the processor's own output skips a
//     dropped sample, and nothing is lost from the angle;
//   - a stamp that an axis lacks otherwise (not delivered when its wait runs out), or whose
//     intervals differ, or that carries an axis's gap or reset flag, gives a sample with FLAG_GAP
//     (or FLAG_RESET), no increment and no rate: never a mix of stale and fresh axes;
//   - while an axis has nothing buffered the others wait for it, up to max_wait seconds of their
//     stamps or max_pending samples each; then the waiting stamps are emitted as gaps (an axis
//     that stopped costs bounded memory and delay).
// Given the same three streams, the output is the same whatever order the axes' samples arrive in
// (the live node's three subscriptions, the offline tool's bag order), unless a wait runs out.
// Each axis's stamps follow the one stamp rule (common/stamp_timeline.h: backward_reset,
// forward_jump, jump_persist), against its own last sample and the other axes' newest: a zero,
// duplicate or out-of-order stamp, or a single sample whose stamp jumps back or ahead (a stray
// message), is dropped and counted, and the axis goes on where it was. Only a jump back that persists
// (a bag loop, after which the processor flags a reset) starts a new epoch of that axis: its samples
// are compared with the other axes' of the same epoch, and the first triad sample of a new epoch
// carries FLAG_RESET, so the emitted stamps only go back with it. A sample that is no measurement
// (dt below 1 ns, dt or dalpha not finite, |dalpha| / dt above max_rate) is dropped, and a variance
// outside [1e-20, 1e12] (rad/s)^2 is not taken. Nothing non-finite is ever emitted. No ROS.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <vector>

#include "hrg_gyro/core/common/ring_buffer.h"
#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/triad_parameters.h"

namespace hrg_gyro {
namespace core {

/// One compensated output of one axis: the fields of GyroOutput the triad uses.
struct AxisOutput {
  Nanoseconds stamp = 0;
  double dt = 0.0;         ///< s, the interval the increment covers, ending at stamp
  double dalpha = 0.0;     ///< rad, the compensated inertial increment about the axis
  std::uint8_t flags = 0;  ///< GyroOutput's flags (OutputFlags in gyro_processor.h)
  /// (rad/s)^2, the variance of this axis's rate at this sample; NaN (or not positive) when none
  /// came with it: the axis's last one stands.
  double rate_variance = NAN;
};

constexpr std::uint8_t kAllTriadAxes = 0x7;  ///< a bit per axis

/// Flags of a triad sample (the same bits as TriadOutput.msg).
enum TriadFlags : std::uint8_t {
  kTriadFlagGap = 1,          ///< an axis lacked this stamp, its interval differed, or it flagged a gap
  kTriadFlagReset = 2,        ///< an axis reset, or the stamps went back for good (a new epoch)
  kTriadFlagAxisFlagged = 4,  ///< an axis's output carried a frequency flag (values still combined)
  kTriadFlagPrecessing = 8,   ///< an axis's wave was turned on command: its rate is not the body's
};

struct TriadBodySample {
  TriadBodySample() = default;
  struct Unset {};
  /// The vectors and the matrix left unset, for the combiner, which writes every field.
  explicit TriadBodySample(Unset) : delta_angle(), angular_velocity(), covariance() {}

  Nanoseconds stamp = 0;  ///< the first axis's stamp (all within the stamp tolerance)
  /// s: a combined sample's is the first axis's dt; a gap's the time since the previous triad
  /// sample (or, with none before it in the same epoch, the smallest dt of its axes).
  double dt = 0.0;
  Eigen::Vector3d delta_angle = Eigen::Vector3d::Zero();       ///< rad, body frame; 0 with GAP or RESET
  Eigen::Vector3d angular_velocity = Eigen::Vector3d::Zero();  ///< rad/s, delta_angle / dt
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();        ///< (rad/s)^2, symmetric positive definite
  std::uint8_t flags = 0;                                      ///< TriadFlags
  std::uint8_t missing_axes = 0;                               ///< bit i: axis i had no sample at this stamp

  bool integrated() const { return (flags & (kTriadFlagGap | kTriadFlagReset)) == 0; }
};

struct TriadCombinerSettings {
  /// s; the largest difference between the axes' stamps (and intervals) of one sample. 0: a
  /// quarter of the sample period (the smallest dt of the samples compared).
  double stamp_tolerance = 0.0;
  /// s of stamps a sample waits for an axis that has nothing buffered, before it is a gap.
  double max_wait = 1.0;
  /// Samples held per axis at most while waiting (a bound on memory whatever the stamps).
  std::size_t max_pending = 100000;
  /// (rad/s)^2, an axis's rate variance until its first sample that carries one.
  double initial_rate_variance = 1e-4;
  /// rad/s: an axis sample whose |dalpha| / dt is above this is no measurement (dropped).
  double max_rate = 100.0;
  /// The stamp rule of each axis's stream (s, s, samples).
  double backward_reset = 0.5;
  double forward_jump = 0.1;
  int jump_persist = 5;
  /// Throws ConfigError (yaml_field.h) naming the triad node's parameter (stamp_tolerance,
  /// max_wait, max_pending, initial_angular_velocity_variance, max_rate, backward_reset,
  /// forward_jump, jump_persist).
  void validate() const;
};

struct TriadAxisCounters {
  std::uint64_t received = 0;
  std::uint64_t invalid = 0;       ///< dropped: dt below 1 ns, dt or dalpha not finite, |dalpha| / dt above max_rate
  std::uint64_t bad_stamp = 0;     ///< dropped: zero or negative stamp
  std::uint64_t duplicate = 0;     ///< dropped: the stamp of the axis's previous sample again
  std::uint64_t out_of_order = 0;  ///< dropped: behind the axis's previous sample by at most backward_reset
  std::uint64_t stamp_jumps = 0;   ///< dropped: the stamp jumped back or ahead (a glitch until it persists)
  std::uint64_t missing = 0;       ///< triad stamps this axis had no sample for
  std::uint64_t flagged = 0;       ///< its samples with a gap, reset or frequency flag
  std::uint64_t mismatched = 0;    ///< its samples whose dt differed from the other two axes'
  std::uint64_t epochs = 0;        ///< times its stamps went back for good (jump_persist samples)
};

struct TriadCounters {
  std::uint64_t samples = 0;       ///< triad samples emitted
  std::uint64_t integrated = 0;    ///< of them, combined from three axes (no GAP, no RESET)
  std::uint64_t gaps = 0;          ///< with FLAG_GAP
  std::uint64_t resets = 0;        ///< with FLAG_RESET
  std::uint64_t axis_flagged = 0;  ///< with FLAG_AXIS_FLAGGED
  std::uint64_t precessing = 0;    ///< with FLAG_PRECESSING
  std::uint64_t timeouts = 0;      ///< emitted because an axis was waited for too long (max_wait, max_pending)
  std::uint64_t non_finite = 0;    ///< combinations that overflowed (emitted as gaps)
  /// Stamps not emitted: an axis delivered them after a later stamp had gone out (as a gap, once its
  /// wait ran out), or they belong to an epoch already left. Emitted stamps only go back with RESET.
  std::uint64_t late = 0;
  /// Stamps an axis skipped whose other axes' increments were carried into the next stamp.
  std::uint64_t carried = 0;
  std::array<TriadAxisCounters, 3> axes;
};

class TriadCombiner {
 public:
  /// Throws std::invalid_argument on bad settings (via validate) or a matrix or bias that is not
  /// finite.
  TriadCombiner(const TriadCombinerSettings& settings, std::shared_ptr<const TriadParameters> triad);

  /// M and bias for the samples combined from now on (a reload between two samples).
  void setParameters(std::shared_ptr<const TriadParameters> triad);
  const TriadParameters& parameters() const { return *triad_; }
  const std::shared_ptr<const TriadParameters>& sharedParameters() const { return triad_; }
  const TriadCombinerSettings& settings() const { return settings_; }

  /// One output of axis `axis` (0, 1, 2: the order of the file's `axes`), in that axis's order.
  /// The triad samples it completes are appended to *completed, in stamp order (none while an
  /// axis is still awaited; several when a wait ran out).
  void add(std::size_t axis, const AxisOutput& output, std::vector<TriadBodySample>* completed);
  /// Emits every stamp still held, as gaps (the end of a recording).
  void flush(std::vector<TriadBodySample>* completed);

  std::size_t pending(std::size_t axis) const { return queues_[axis].size() + ((staged_mask_ >> axis) & 1u); }
  /// The axis's rate variance in force, (rad/s)^2.
  double rateVariance(std::size_t axis) const { return variance_[axis]; }
  const TriadCounters& counters() const { return counters_; }

 private:
  struct Held {
    Nanoseconds stamp;
    std::uint64_t epoch;
    double dt, dalpha, variance;
    std::uint8_t flags;
  };
  /// A sample's stamp through its axis's timeline: false when it is dropped (counted); a jump back
  /// that persists starts a new epoch of the axis.
  bool admitStamp(std::size_t axis, Nanoseconds stamp);
  /// admitStamp() beyond the usual case (the next stamp of the axis).
  __attribute__((noinline)) bool admitUnusual(std::size_t axis, Nanoseconds stamp, StampVerdict verdict);
  /// add() beyond the usual case: through the queues.
  __attribute__((noinline)) void addQueued(std::size_t axis, const Held& held, std::vector<TriadBodySample>* completed);
  /// Moves the staged samples to the queues (they are the oldest of their axes).
  void unstage();
  /// False when the sample just added to `axis` cannot have ended a wait (the usual case, cheaply).
  bool mayHaveEndedAWait(std::size_t axis) const;
  /// Emits what the heads of the queues decide; with `force`, also stamps still awaited.
  void resolve(bool force, std::vector<TriadBodySample>* completed);
  /// The axis whose head comes first (epoch, then stamp); the queues must not all be empty.
  std::size_t earliestHead() const;
  /// Whether the stamp `head` has been awaited long enough: max_wait of later stamps in its epoch
  /// seen on any axis, or an axis holding max_pending samples.
  bool waitedOut(const Held& head) const;
  /// Pops the heads in `present` (a bit per axis) and appends their triad sample.
  void emit(std::uint8_t present, std::vector<TriadBodySample>* completed);
  /// Whether the stamp of the heads in `present` was skipped by every other axis, whose next
  /// sample (its head) spans it: then their increments are carried (and popped), nothing emitted.
  bool carryOver(std::uint8_t present, Nanoseconds tolerance);
  /// Appends the triad sample of `heads` (null: the axis lacks the stamp); pops nothing.
  void emitHeads(const std::array<const Held*, 3>& heads, std::uint8_t present,
                 std::vector<TriadBodySample>* completed);
  /// A stamp every axis has: combined unless a flag or the intervals say otherwise.
  void combineAligned(const Held& h0, const Held& h1, const Held& h2, TriadBodySample* out);
  /// A stamp some axis lacks: a gap (null heads are the missing axes).
  void combinePartial(const std::array<const Held*, 3>& heads, TriadBodySample* out);
  /// The axis's variance from now on, if `h` carries one.
  void takeVariance(std::size_t axis, const Held& h);
  /// M diag(sigma_i^2) M^T of the variances in force.
  void writeCovariance(TriadBodySample* out) const;
  /// Flags, and for a gap or reset no increment over the time since the previous sample.
  void endSample(std::uint8_t flags, double smallest_dt, std::uint64_t epoch, TriadBodySample* out);

  TriadCombinerSettings settings_;
  std::shared_ptr<const TriadParameters> triad_;
  Eigen::Matrix3d m_;
  Eigen::Vector3d bias_;
  std::array<std::array<double, 6>, 3> outer_;  // m_k m_k^T: xx, xy, xz, yy, yz, zz
  Nanoseconds max_wait_ns_ = 0;
  std::array<RingBuffer<Held>, 3> queues_;
  // The samples of one stamp, one per axis, while the queues are empty (the usual case).
  bool staging_ = true;
  std::uint8_t staged_mask_ = 0;
  Nanoseconds staged_stamp_ = 0;  // the staged samples' stamp and epoch
  std::uint64_t staged_epoch_ = 0;
  std::array<Held, 3> staged_;
  std::array<double, 3> variance_;
  std::array<StampTimeline, 3> timelines_;
  double min_dt_ = 1e-9;  // s: below one stamp tick, no interval
  std::array<bool, 3> seen_{{false, false, false}};
  std::array<Nanoseconds, 3> last_stamp_{{0, 0, 0}};
  std::array<std::uint64_t, 3> epoch_{{0, 0, 0}};
  // The increments of stamps an axis skipped, per axis, to be added to its next sample.
  std::uint8_t carry_mask_ = 0;
  std::array<double, 3> carry_dalpha_{{0.0, 0.0, 0.0}}, carry_dt_{{0.0, 0.0, 0.0}};
  bool has_previous_ = false;
  Nanoseconds previous_stamp_ = 0;
  std::uint64_t previous_epoch_ = 0;
  TriadCounters counters_;
};

inline bool TriadCombiner::admitStamp(std::size_t axis, Nanoseconds stamp) {
  const Nanoseconds others = std::max(last_stamp_[axis == 0 ? 1 : 0], last_stamp_[axis == 2 ? 1 : 2]);
  const StampVerdict verdict = timelines_[axis].check(stamp, others);
  if (verdict != StampVerdict::kNext) return admitUnusual(axis, stamp, verdict);
  seen_[axis] = true;
  last_stamp_[axis] = stamp;
  return true;
}

// The per-sample entry point, inline: the usual case costs no call until a stamp is complete.
inline void TriadCombiner::add(std::size_t axis, const AxisOutput& in, std::vector<TriadBodySample>* completed) {
  if (axis >= 3) throw std::out_of_range("triad combiner: axis index must be 0, 1 or 2");
  TriadAxisCounters& c = counters_.axes[axis];
  ++c.received;
  // Also false for NaN: dt in [1 ns, inf), |dalpha| <= max_rate dt.
  if (!(in.dt >= min_dt_) || !(in.dt < INFINITY) || !(std::abs(in.dalpha) <= settings_.max_rate * in.dt)) {
    ++c.invalid;  // left out: the stamp is then missing on this axis, a gap
    return;
  }
  if (!admitStamp(axis, in.stamp)) return;
  if (in.flags != 0) ++c.flagged;
  const std::uint8_t bit = static_cast<std::uint8_t>(1u << axis);
  // The usual case (one clock): the samples of one stamp arrive one per axis while nothing else is
  // held. They are staged, not queued, and combined when the third arrives: what the queues would
  // do, without them. Anything else goes to the queues (the staged samples first, being older).
  if (staging_ &&
      (staged_mask_ == 0 || (!(staged_mask_ & bit) && in.stamp == staged_stamp_ && epoch_[axis] == staged_epoch_))) {
    staged_[axis] = Held{in.stamp, epoch_[axis], in.dt, in.dalpha, in.rate_variance, in.flags};
    staged_stamp_ = in.stamp;
    staged_epoch_ = epoch_[axis];
    staged_mask_ |= bit;
    if (staged_mask_ != kAllTriadAxes) return;
    staged_mask_ = 0;
    emitHeads({{&staged_[0], &staged_[1], &staged_[2]}}, kAllTriadAxes, completed);
    return;
  }
  addQueued(axis, Held{in.stamp, epoch_[axis], in.dt, in.dalpha, in.rate_variance, in.flags}, completed);
}

}  // namespace core
}  // namespace hrg_gyro
