// The one stillness test of a resting gyro or base: its rates averaged over blocks of `block` s,
// per channel, and how far those block means spread within a rest. A gyro at rest sees a constant
// rate (the Earth's and its bias), so its block means agree to the noise; one that turns, leans or
// is knocked spreads them. The test is the largest half-spread, (max - min) / 2 of a channel's block
// means, against a limit (max_motion). Judged as data come, so a caller refuses at once.
//
// The turn-on bias capture (bias_capture.h: one axis over its capture) and the gyrocompass's
// still-base fit (gyrocompass_solver.h: the channels of each rest of the window) both judge their
// stillness with it. No ROS.
#pragma once

#include <array>
#include <cstddef>

namespace hrg_gyro {
namespace core {

class BlockMeanStillness {
 public:
  static constexpr std::size_t kMaxChannels = 3;
  /// `channels` in 1..3; `block` s, positive.
  BlockMeanStillness(std::size_t channels, double block);

  /// One sample: its dt (s) and `channels` increments (rad). A block closes once its dt reaches `block`.
  void add(double dt, const double* increment);
  /// Closes the block under way when it holds more than `fraction` of a block (the end of a capture).
  void closePartialBlock(double fraction);
  /// A new rest begins: the block under way is dropped and the spread starts again; the worst so far stays.
  void restart();

  bool hasBlock() const { return has_block_; }
  /// rad/s, the smallest and largest block mean of a channel in this rest (valid once hasBlock()).
  double lowestMean(std::size_t channel) const { return low_[channel]; }
  double highestMean(std::size_t channel) const { return high_[channel]; }
  /// rad/s, the largest half-spread of any channel's block means within a rest, over every rest so far.
  double worstHalfSpread() const { return worst_; }
  /// The test: the block means spread beyond +-max_motion (rad/s) within a rest.
  bool moved(double max_motion) const { return worst_ > max_motion; }

 private:
  void closeBlock();

  std::size_t channels_;
  double block_;
  double block_dt_ = 0.0;
  std::array<double, kMaxChannels> block_sum_{{0.0, 0.0, 0.0}}, low_{{0.0, 0.0, 0.0}}, high_{{0.0, 0.0, 0.0}};
  bool has_block_ = false;
  double worst_ = 0.0;
};

}  // namespace core
}  // namespace hrg_gyro
