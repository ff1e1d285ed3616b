// Three gyros as one IMU, from their channels: for each axis what its processor node runs, then what
// the triad node runs, in one object. `hrg_bag process --triad` runs it on a bag's channels and the
// evaluation pipeline on a simulated triad, so that their numbers are the live nodes' bit for bit;
// `hrg_bag calibrate --method triad` and the pipeline's calibration run its processors alone.
//
// Per axis, as its processor node:
//   - GyroProcessor: the channel sample to the wave angle and, for an accepted sample, the output;
//   - PrecessionWatch (precession_watch.h): an output over which the precession loop turned the wave,
//     from the axis's precession state (`<axis>/precession/state`), is flagged FLAG_PRECESSING. An
//     output waits until that stream has reached its stamp; a gyro that reports no state holds none;
//   - RateNoiseEstimator: the variance of the rate its Imu reports with the output -- 1e6 (rad/s)^2,
//     "not measured" (kUnmeasuredRateVariance), for a precessed output, and none at all for one
//     flagged GAP or RESET (the node publishes no Imu for it; the combiner keeps the axis's last).
// Then, as the triad node, the decided outputs of the three axes go to the TriadCombiner, in each
// axis's order. Without a triad (the second constructor) it is the three processors alone: their
// results carry the wave angles a triad calibration takes; nothing waits, nothing is combined. No ROS.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "hrg_gyro/core/common/ring_buffer.h"
#include "hrg_gyro/core/processing/gyro_processor.h"
#include "hrg_gyro/core/processing/precession_watch.h"
#include "hrg_gyro/core/processing/rate_noise_estimator.h"
#include "hrg_gyro/core/processing/triad_combiner.h"

namespace hrg_gyro {
namespace core {

/// (rad/s)^2: the variance a processor node reports for a rate it did not measure (REP-145 has no
/// "unknown" marker for one axis; a filter that weighs by covariance ignores it).
constexpr double kUnmeasuredRateVariance = 1e6;

struct TriadProcessorSettings {
  ProcessorConfig processor;  ///< each axis's processor node's limits
  /// s, each processor node's ~precession_hold (its backward_reset: the processor's).
  double precession_hold = PrecessionWatchSettings().hold;
  RateNoiseSettings noise;         ///< each axis's rate variance, as its processor node reports it
  TriadCombinerSettings combiner;  ///< the triad node's
};

/// An axis's output once its precession verdict is known, as its processor node publishes it.
struct TriadAxisOutput {
  std::size_t axis = 0;  ///< 0..2, the triad's axis order
  /// flags: the processor's, with FLAG_PRECESSING when precessed; rate_variance: its Imu's (NaN: none).
  AxisOutput output;
};

class TriadProcessor {
 public:
  /// The processors of `axes` (the triad's axis order) and the combiner of `triad`. Throws
  /// ConfigError or std::invalid_argument for invalid settings (as its parts do).
  TriadProcessor(const TriadProcessorSettings& settings, const std::array<GyroParameters, 3>& axes,
                 std::shared_ptr<const TriadParameters> triad);
  /// The three processors alone.
  TriadProcessor(const ProcessorConfig& processor, const std::array<GyroParameters, 3>& axes);
  ~TriadProcessor();

  /// Axis `axis`'s channel sample through its processor, into *result (GyroProcessor::process).
  /// Combining, its output then waits for its precession verdict: release() hands it on.
  void process(std::size_t axis, const ChannelSample& sample, ProcessorResult* result);
  /// A record of axis `axis`'s precession state, in the order received; false when it was dropped
  /// (counted by the axis's watch). Then release().
  bool addPrecessionState(std::size_t axis, const PrecessionStateRecord& record);
  /// Hands on every output whose verdict is known, each axis's in its order: appended to *outputs
  /// (if not null), then combined; the triad samples completed appended to *completed.
  void release(std::vector<TriadAxisOutput>* outputs, std::vector<TriadBodySample>* completed);
  /// The input has ended: every waiting output decided with the states known and handed on, then
  /// the stamps some axis never delivered emitted as gaps (TriadCombiner::flush).
  void finish(std::vector<TriadAxisOutput>* outputs, std::vector<TriadBodySample>* completed);

  bool combining() const { return combiner_ != nullptr; }
  const GyroProcessor& processor(std::size_t axis) const { return *axes_[axis].processor; }
  /// Combining only: the axis's precession watch, its outputs, of them flagged PRECESSING.
  const PrecessionWatch& precession(std::size_t axis) const { return axes_[axis].watch; }
  std::uint64_t outputs(std::size_t axis) const { return axes_[axis].outputs; }
  std::uint64_t precessed(std::size_t axis) const { return axes_[axis].precessed; }
  /// Combining only.
  const TriadCombiner& combiner() const { return *combiner_; }

 private:
  /// An output waiting for its verdict: what the combiner and the noise estimator take of it.
  struct Waiting {
    Nanoseconds stamp;
    double dt, dalpha, alpha;
    std::uint8_t flags;
  };
  struct Axis {
    explicit Axis(const TriadProcessorSettings& settings);
    std::unique_ptr<GyroProcessor> processor;
    PrecessionWatch watch;
    RateNoiseEstimator noise;
    RingBuffer<Waiting> waiting;
    Nanoseconds previous_accepted = 0;  // an output covers (the previous accepted stamp, its own]
    std::uint64_t outputs = 0, precessed = 0;
  };
  /// Hands on axis `axis`'s decided outputs.
  void releaseAxis(std::size_t axis, std::vector<TriadAxisOutput>* outputs, std::vector<TriadBodySample>* completed);

  TriadProcessorSettings settings_;
  std::array<Axis, 3> axes_;
  std::unique_ptr<TriadCombiner> combiner_;  // null: the processors alone
};

}  // namespace core
}  // namespace hrg_gyro
