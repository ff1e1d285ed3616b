// The measurement pipeline for one channel-amplitude sample:
//   Z -> (E - P) Z -> wave state -> unwrapped theta -> dalpha = (dtheta - D dt) / K -> alpha.
// It also owns the rules for bad input, so that the live node, the nodelet and `hrg_bag process`
// behave identically (and give bit-identical numbers):
//   - stamps follow the one stamp rule (common/stamp_timeline.h) with backward_reset, max_gap as
//     its forward jump and jump_persist: zero stamps, duplicates and small backward steps (out of
//     order) are dropped; a single sample stamped further back or more than max_gap ahead is a
//     glitch, dropped and counted (stamp_jumps), and the stream goes on where it was;
//   - a jump back that persists for jump_persist samples (a bag loop, a restarted driver) resets the
//     state: alpha restarts at 0 and the next output carries FLAG_RESET;
//   - a jump ahead that persists (a gap: the source stopped, messages were lost) is not integrated
//     across: the sample re-anchors the angle, its output has dalpha = 0 and FLAG_GAP;
//   - non-finite, empty, degenerate (A ~ B) or implausible-amplitude channels are rejected;
//   - a wave-angle step implying more than max_rate of body rate is rejected as a glitch (a channel
//     sign flip, say); after max_consecutive_jumps such samples the new angle is accepted as a
//     re-anchor (FLAG_GAP).
// Rejected samples are counted by reason; the next output reports how many preceded it. Nothing
// that is rejected reaches the integrated angle, and no output is ever NaN.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include "hrg_gyro/core/common/stamp_timeline.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/processing/compensator.h"
#include "hrg_gyro/core/signal/theta_unwrapper.h"
#include "hrg_gyro/core/signal/wave_estimator.h"

namespace hrg_gyro {
namespace core {

struct ProcessorConfig {
  WaveLimits limits;
  double max_gap = 0.1;         ///< s
  double backward_reset = 0.5;  ///< s
  int jump_persist = 5;         ///< samples in a row that make a stamp jump real (common/stamp_timeline.h)
  double max_rate = 20.0;       ///< rad/s of body rate
  int max_consecutive_jumps = 5;
};

/// The one rule set for the processor's limits, shared by the processor node and `hrg_bag`:
/// max_gap, backward_reset and max_rate finite and positive; jump_persist in [1, 1000];
/// max_consecutive_jumps >= 0;
/// 0 < min_anisotropy < 1; 0 <= min_amplitude < max_amplitude, both finite. Throws ConfigError
/// (yaml_field.h) whose key() is the node's parameter name (max_gap, min_amplitude, ...).
void validate(const ProcessorConfig& config);

struct ChannelSample {
  Nanoseconds stamp = 0;
  ChannelVector z = ChannelVector::Zero();
  double frequency = NAN;    ///< Hz
  double temperature = NAN;  ///< degC
};

/// Output flags (the same bits as GyroOutput.msg).
enum OutputFlags : std::uint8_t {
  kFlagGap = 1,
  kFlagReset = 2,
  kFlagFrequencyOutOfRange = 4,
  kFlagFrequencyUnknown = 8,
  kFlagPrecessing = 16,
};

enum class SampleVerdict : std::uint8_t {
  kAccepted,       ///< wave state and (except for the first sample) an output
  kFirst,          ///< wave state, no increment yet
  kRejectedValue,  ///< see wave_status
  kRejectedStamp,  ///< zero or negative stamp
  kDuplicate,
  kOutOfOrder,
  kRejectedJump,  ///< the wave angle jumped (max_rate)
  kStampJump,     ///< the stamp jumped back or ahead (a glitch until it persists)
};

struct ProcessorResult {
  SampleVerdict verdict = SampleVerdict::kRejectedValue;
  WaveStatus wave_status = WaveStatus::kOk;
  bool has_wave = false;
  WaveState wave;  ///< corrected, theta continuous
  bool has_output = false;
  AngleIncrement increment;
  double alpha = 0.0;  ///< integrated inertial angle after this sample, rad
  std::uint8_t flags = 0;
  std::uint32_t rejected_before = 0;
};

struct ProcessorCounters {
  std::uint64_t received = 0, accepted = 0, outputs = 0;
  std::uint64_t non_finite = 0, no_signal = 0, degenerate = 0, amplitude_out_of_range = 0;
  std::uint64_t zero_stamp = 0, duplicate = 0, out_of_order = 0, jumps = 0;
  std::uint64_t stamp_jumps = 0;  ///< samples whose stamp jumped back or ahead, dropped
  std::uint64_t gaps = 0, resets = 0, frequency_out_of_range = 0, frequency_unknown = 0;
  double largest_gap = 0.0;  ///< s
  std::uint64_t rejected() const {
    return non_finite + no_signal + degenerate + amplitude_out_of_range + zero_stamp + duplicate + out_of_order +
           jumps + stamp_jumps;
  }
};

class GyroProcessor {
 public:
  GyroProcessor(const ProcessorConfig& config, std::shared_ptr<const GyroParameters> parameters);

  /// Takes effect from the next sample; the angle, its unwrapping and alpha carry on. When the
  /// correction matrix changes, the previous sample is re-read through the new P, so the increment
  /// across the swap compares two angles measured the same way (no spurious step).
  void setParameters(std::shared_ptr<const GyroParameters> parameters);
  const GyroParameters& parameters() const { return compensator_.parameters(); }
  const std::shared_ptr<const GyroParameters>& sharedParameters() const { return compensator_.sharedParameters(); }
  const ProcessorConfig& config() const { return config_; }

  ProcessorResult process(const ChannelSample& sample);
  /// The same step writing into a caller's result (every field is set, whatever the verdict): the
  /// form to use in a loop, since it reuses the caller's storage.
  void process(const ChannelSample& sample, ProcessorResult* result);
  /// Processes n queued samples in order: out[i] is bit for bit what process(in[i]) would return,
  /// counters and state included, so a batch can be split anywhere. For offline tools and for a
  /// live node that drains a queue; in and out must not overlap.
  void processBatch(const ChannelSample* in, std::size_t n, ProcessorResult* out);

  const ProcessorCounters& counters() const { return counters_; }
  /// Forgets the state (next sample is a first sample, alpha restarts at 0, the stamps start
  /// afresh); counters are kept.
  void reset();

 private:
  void countRejection(WaveStatus status);
  /// reset() but for the stamps' timeline.
  void resetState();
  /// The body of both process() forms, inlined into each: the by-value form (the live node's) then
  /// makes no second call.
  void processInto(const ChannelSample& in, ProcessorResult* result);
  /// Everything after the wave estimate, in order (the estimate depends on the sample alone, so
  /// processBatch computes a block of them ahead): status is estimateWave's on (E - P) z, and wave
  /// may be result->wave itself. With `deferred`, an integrated step's inputs are queued there and
  /// its increment, and alpha, are left to the caller (processBatch).
  void advance(const ChannelSample& in, WaveStatus status, WaveState* wave, ProcessorResult* result,
               StepBatch* deferred);
  // The phases of process(), in its order.
  /// Counts a rejected sample toward the next output's rejected_before.
  void reject(SampleVerdict verdict, ProcessorResult* r);
  /// The stamp rule: zero, duplicate, out-of-order and jumped stamps are rejected (false); a jump
  /// back that persists resets the state. *dt_ns: the step from the previous sample (left at 0
  /// without one).
  bool admitStamp(Nanoseconds stamp, Nanoseconds* dt_ns, ProcessorResult* r);
  /// The first sample (after a start or reset) anchors the unwrapped angle; no output.
  void anchor(const ChannelSample& in, WaveState* wave, ProcessorResult* r);
  /// Gap and glitch rules on the unwrapped angle step: false for a rejected jump; *integrate false
  /// (and kFlagGap) for a gap or a persistent jump, which re-anchor the angle.
  bool admitStep(double dt, double step, std::uint8_t* flags, bool* integrate);
  /// kFlagFrequencyUnknown / kFlagFrequencyOutOfRange for a frequency-dependent model, counted.
  std::uint8_t frequencyFlags(double f_mid);
  /// The output across a re-anchor: dalpha = 0, K and D evaluated at the new angle.
  AngleIncrement reanchorIncrement(double theta, double dt, double f_mid, const WaveState& wave);
  /// The accepted sample becomes the previous one.
  void remember(const ChannelSample& in, const WaveState& wave);

  ProcessorConfig config_;
  StampTimeline timeline_;
  Compensator compensator_;
  double max_abs_k0_;  // |K0| for the glitch limit on the wave-angle step
  ThetaUnwrapper unwrapper_;
  ProcessorCounters counters_;
  bool has_previous_ = false;
  Nanoseconds previous_stamp_ = 0;
  double previous_frequency_ = NAN;
  ChannelVector previous_z_ = ChannelVector::Zero();  // raw, for re-reading under a new P
  double previous_cos_ = 1.0, previous_sin_ = 0.0;    // of the previous (unwrapped) theta
  double alpha_ = 0.0;
  std::uint8_t pending_flags_ = 0;
  std::uint32_t rejected_since_output_ = 0;
  int consecutive_jumps_ = 0;
};

}  // namespace core
}  // namespace hrg_gyro
