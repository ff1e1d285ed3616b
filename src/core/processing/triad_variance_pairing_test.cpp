// Pairing an axis's outputs with the rate variances reported for them on another topic: in either
// order of arrival each output gets its own stamp's variance, in order; one the processor never
// reports (a flagged output) or that was lost does not hold the others up; a silent variance topic
// costs bounded memory; a loop releases what waits from before it.
#include "hrg_gyro/core/processing/triad_variance_pairing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

AxisOutput output(Nanoseconds stamp, std::uint8_t flags = 0) {
  AxisOutput o;
  o.stamp = stamp;
  o.dt = 0.005;
  o.dalpha = 1e-4 * static_cast<double>(stamp);
  o.flags = flags;
  return o;
}

double varianceOf(Nanoseconds stamp) { return 1e-6 * static_cast<double>(stamp); }

class TriadVariancePairingTest : public ::testing::Test {
 protected:
  /// The output of `stamp` arrives; so does its variance.
  void outputArrives(Nanoseconds stamp, std::uint8_t flags = 0) { pairing_.addOutput(output(stamp, flags), &ready_); }
  void varianceArrives(Nanoseconds stamp) { pairing_.addVariance(stamp, varianceOf(stamp), &ready_); }
  TriadVariancePairing pairing_;
  std::vector<AxisOutput> ready_;  // what went on to the combiner, in order
};

TEST_F(TriadVariancePairingTest, EachOutputGetsItsOwnStampsVarianceInEitherOrder) {
  for (Nanoseconds s = 1; s <= 6; ++s) {
    if (s % 2) {  // output first
      outputArrives(s);
      EXPECT_EQ(ready_.size(), static_cast<std::size_t>(s - 1)) << "an output waits for its variance";
      varianceArrives(s);
    } else {  // variance first
      varianceArrives(s);
      outputArrives(s);
    }
    ASSERT_EQ(ready_.size(), static_cast<std::size_t>(s));
    EXPECT_EQ(ready_.back().stamp, s);
    EXPECT_EQ(ready_.back().rate_variance, varianceOf(s));
    EXPECT_EQ(ready_.back().dalpha, output(s).dalpha);
  }
  EXPECT_EQ(pairing_.counters().paired, 6u);
  EXPECT_EQ(pairing_.heldOutputs() + pairing_.heldVariances(), 0u);
}

TEST_F(TriadVariancePairingTest, AFlaggedOutputGoesOnAtOnceAndInOrder) {
  outputArrives(1);
  outputArrives(2, kFlagGap);  // no variance will come for it
  EXPECT_TRUE(ready_.empty()) << "it must not overtake the output before it";
  varianceArrives(1);
  ASSERT_EQ(ready_.size(), 2u);
  EXPECT_EQ(ready_[0].rate_variance, varianceOf(1));
  EXPECT_EQ(ready_[1].stamp, 2);
  EXPECT_TRUE(std::isnan(ready_[1].rate_variance));
  outputArrives(3, kFlagReset);
  ASSERT_EQ(ready_.size(), 3u);
}

TEST_F(TriadVariancePairingTest, ALostVarianceOrALostOutputHoldsNothingUp) {
  outputArrives(1);
  outputArrives(2);
  varianceArrives(2);  // 1's variance was lost
  ASSERT_EQ(ready_.size(), 2u);
  EXPECT_TRUE(std::isnan(ready_[0].rate_variance));
  EXPECT_EQ(ready_[1].rate_variance, varianceOf(2));
  varianceArrives(3);  // 3's output was lost
  varianceArrives(4);
  outputArrives(4);
  ASSERT_EQ(ready_.size(), 3u);
  EXPECT_EQ(ready_[2].rate_variance, varianceOf(4));
  EXPECT_EQ(pairing_.counters().unmatched_variances, 1u);
  EXPECT_EQ(pairing_.counters().without_variance, 1u);
}

TEST_F(TriadVariancePairingTest, ASilentVarianceTopicCostsBoundedMemory) {
  TriadVariancePairing pairing(10);
  std::vector<AxisOutput> ready;
  for (Nanoseconds s = 1; s <= 100; ++s) {
    pairing.addOutput(output(s), &ready);
    ASSERT_LE(pairing.heldOutputs(), 10u);
  }
  ASSERT_EQ(ready.size(), 90u);
  for (Nanoseconds s = 1; s <= 90; ++s) EXPECT_EQ(ready[static_cast<std::size_t>(s - 1)].stamp, s);
  TriadVariancePairing variances_only(10);
  for (Nanoseconds s = 1; s <= 100; ++s) {
    variances_only.addVariance(s, 1e-6, &ready);
    ASSERT_LE(variances_only.heldVariances(), 10u);
  }
}

TEST_F(TriadVariancePairingTest, ALoopReleasesWhatWaitsFromBeforeIt) {
  outputArrives(100);
  outputArrives(101);
  varianceArrives(100);
  ASSERT_EQ(ready_.size(), 1u);
  // The bag loops: 101's variance will never come.
  outputArrives(5, kFlagReset);
  ASSERT_EQ(ready_.size(), 3u);
  EXPECT_EQ(ready_[1].stamp, 101);
  EXPECT_TRUE(std::isnan(ready_[1].rate_variance));
  EXPECT_EQ(ready_[2].stamp, 5);
  varianceArrives(6);
  outputArrives(6);
  ASSERT_EQ(ready_.size(), 4u);
  EXPECT_EQ(ready_[3].rate_variance, varianceOf(6));
  // A variance topic that loops drops what it held from before.
  varianceArrives(200);
  varianceArrives(7);
  EXPECT_EQ(pairing_.heldVariances(), 1u);
  outputArrives(7);
  EXPECT_EQ(ready_.back().rate_variance, varianceOf(7));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
