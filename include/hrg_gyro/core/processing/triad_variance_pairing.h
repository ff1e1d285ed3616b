// For the triad (its node only): an axis's outputs and the rate variances its processor reports for them arrive on two
// topics (GyroOutput on `output`; the variance in the Imu on `imu/data_raw`, angular_velocity_covariance[8]), each in
// order but in no fixed order between the two. This pairs them by stamp, so that every output goes on to the triad
// combiner with the variance of its own stamp, in the axis's order:
//   - an output the processor publishes no Imu for (a gap or reset flag) goes on at once, without;
//   - an output waits for the Imu of its stamp; an Imu of a later stamp means its own was lost, and
//     it goes on without (the combiner keeps the axis's last variance);
//   - an Imu that comes before its output waits for it; one older than the output at hand had its
//     output lost and is dropped;
//   - at most max_held of each wait (a silent Imu topic: the processor's publish_imu is false);
//     beyond that the oldest output goes on without, the oldest Imu is dropped;
//   - a stamp going backwards on either topic (a bag loop) releases, or drops, what waits from
//     before it.
// No ROS.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "hrg_gyro/core/common/ring_buffer.h"
#include "hrg_gyro/core/processing/triad_combiner.h"

namespace hrg_gyro {
namespace core {

struct TriadVariancePairingCounters {
  std::uint64_t paired = 0;               ///< outputs that went on with the variance of their stamp
  std::uint64_t without_variance = 0;     ///< outputs that went on without one (none due, lost, or waited too long)
  std::uint64_t unmatched_variances = 0;  ///< variances dropped: their output never came
};

class TriadVariancePairing {
 public:
  explicit TriadVariancePairing(std::size_t max_held = 1000);

  /// An output of the axis (its rate_variance is ignored). Outputs ready to go on, in order, with
  /// their rate_variance set (NaN: none), are appended to *ready.
  void addOutput(const AxisOutput& output, std::vector<AxisOutput>* ready);
  /// The rate variance the axis's processor reported for `stamp`, (rad/s)^2.
  void addVariance(Nanoseconds stamp, double variance, std::vector<AxisOutput>* ready);

  std::size_t heldOutputs() const { return outputs_.size(); }
  std::size_t heldVariances() const { return variances_.size(); }
  const TriadVariancePairingCounters& counters() const { return counters_; }

 private:
  struct Variance {
    Nanoseconds stamp;
    double value;
  };
  void release(AxisOutput output, double variance, std::vector<AxisOutput>* ready);
  void drain(std::vector<AxisOutput>* ready);

  std::size_t max_held_;
  RingBuffer<AxisOutput> outputs_;
  RingBuffer<Variance> variances_;
  bool has_output_ = false, has_variance_ = false;
  Nanoseconds last_output_ = 0, last_variance_ = 0;
  TriadVariancePairingCounters counters_;
};

}  // namespace core
}  // namespace hrg_gyro
