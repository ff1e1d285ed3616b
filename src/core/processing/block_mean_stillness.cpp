#include "hrg_gyro/core/processing/block_mean_stillness.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace hrg_gyro {
namespace core {

BlockMeanStillness::BlockMeanStillness(std::size_t channels, double block) : channels_(channels), block_(block) {
  if (channels < 1 || channels > kMaxChannels) throw std::invalid_argument("stillness: 1 to 3 channels");
  if (!(block > 0.0) || !std::isfinite(block)) throw std::invalid_argument("stillness: the block must be positive (s)");
}

void BlockMeanStillness::add(double dt, const double* increment) {
  block_dt_ += dt;
  for (std::size_t c = 0; c < channels_; ++c) block_sum_[c] += increment[c];
  if (block_dt_ >= block_) closeBlock();
}

void BlockMeanStillness::closePartialBlock(double fraction) {
  if (block_dt_ > fraction * block_) closeBlock();
}

void BlockMeanStillness::restart() {
  block_dt_ = 0.0;
  block_sum_ = {{0.0, 0.0, 0.0}};
  has_block_ = false;
}

void BlockMeanStillness::closeBlock() {
  for (std::size_t c = 0; c < channels_; ++c) {
    const double rate = block_sum_[c] / block_dt_;
    if (!has_block_) {
      low_[c] = high_[c] = rate;
    } else {
      low_[c] = std::min(low_[c], rate);
      high_[c] = std::max(high_[c], rate);
    }
    worst_ = std::max(worst_, 0.5 * (high_[c] - low_[c]));
  }
  has_block_ = true;
  block_dt_ = 0.0;
  block_sum_ = {{0.0, 0.0, 0.0}};
}

}  // namespace core
}  // namespace hrg_gyro
