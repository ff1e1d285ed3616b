// Pairing an axis's outputs with the rate variances reported for them on another topic: in either
// order of arrival each output gets its own stamp's variance, in order; one the processor never
// reports (a flagged output) or that was lost does not hold the others up; a silent variance topic
// costs bounded memory; a loop releases what waits from before it.
#include "hrg_gyro/core/processing/rate_variance_pairing.h"

#include <gtest/gtest.h>

#include <cmath>

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

TEST(RateVariancePairingTest, EachOutputGetsItsOwnStampsVarianceInEitherOrder) {
  RateVariancePairing pairing;
  std::vector<AxisOutput> ready;
  for (Nanoseconds s = 1; s <= 6; ++s) {
    if (s % 2) {  // output first
      pairing.addOutput(output(s), &ready);
      EXPECT_EQ(ready.size(), static_cast<std::size_t>(s - 1)) << "an output waits for its variance";
      pairing.addVariance(s, varianceOf(s), &ready);
    } else {  // variance first
      pairing.addVariance(s, varianceOf(s), &ready);
      pairing.addOutput(output(s), &ready);
    }
    ASSERT_EQ(ready.size(), static_cast<std::size_t>(s));
    EXPECT_EQ(ready.back().stamp, s);
    EXPECT_EQ(ready.back().rate_variance, varianceOf(s));
    EXPECT_EQ(ready.back().dalpha, output(s).dalpha);
  }
  EXPECT_EQ(pairing.counters().paired, 6u);
  EXPECT_EQ(pairing.heldOutputs() + pairing.heldVariances(), 0u);
}

TEST(RateVariancePairingTest, AFlaggedOutputGoesOnAtOnceAndInOrder) {
  RateVariancePairing pairing;
  std::vector<AxisOutput> ready;
  pairing.addOutput(output(1), &ready);
  pairing.addOutput(output(2, kFlagGap), &ready);  // no variance will come for it
  EXPECT_TRUE(ready.empty()) << "it must not overtake the output before it";
  pairing.addVariance(1, varianceOf(1), &ready);
  ASSERT_EQ(ready.size(), 2u);
  EXPECT_EQ(ready[0].rate_variance, varianceOf(1));
  EXPECT_EQ(ready[1].stamp, 2);
  EXPECT_TRUE(std::isnan(ready[1].rate_variance));
  pairing.addOutput(output(3, kFlagReset), &ready);
  ASSERT_EQ(ready.size(), 3u);
}

TEST(RateVariancePairingTest, ALostVarianceOrALostOutputHoldsNothingUp) {
  RateVariancePairing pairing;
  std::vector<AxisOutput> ready;
  pairing.addOutput(output(1), &ready);
  pairing.addOutput(output(2), &ready);
  pairing.addVariance(2, varianceOf(2), &ready);  // 1's variance was lost
  ASSERT_EQ(ready.size(), 2u);
  EXPECT_TRUE(std::isnan(ready[0].rate_variance));
  EXPECT_EQ(ready[1].rate_variance, varianceOf(2));
  pairing.addVariance(3, varianceOf(3), &ready);  // 3's output was lost
  pairing.addVariance(4, varianceOf(4), &ready);
  pairing.addOutput(output(4), &ready);
  ASSERT_EQ(ready.size(), 3u);
  EXPECT_EQ(ready[2].rate_variance, varianceOf(4));
  EXPECT_EQ(pairing.counters().unmatched_variances, 1u);
  EXPECT_EQ(pairing.counters().without_variance, 1u);
}

TEST(RateVariancePairingTest, ASilentVarianceTopicCostsBoundedMemory) {
  RateVariancePairing pairing(10);
  std::vector<AxisOutput> ready;
  for (Nanoseconds s = 1; s <= 100; ++s) {
    pairing.addOutput(output(s), &ready);
    ASSERT_LE(pairing.heldOutputs(), 10u);
  }
  ASSERT_EQ(ready.size(), 90u);
  for (Nanoseconds s = 1; s <= 90; ++s) EXPECT_EQ(ready[static_cast<std::size_t>(s - 1)].stamp, s);
  RateVariancePairing variances_only(10);
  for (Nanoseconds s = 1; s <= 100; ++s) {
    variances_only.addVariance(s, 1e-6, &ready);
    ASSERT_LE(variances_only.heldVariances(), 10u);
  }
}

TEST(RateVariancePairingTest, ALoopReleasesWhatWaitsFromBeforeIt) {
  RateVariancePairing pairing;
  std::vector<AxisOutput> ready;
  pairing.addOutput(output(100), &ready);
  pairing.addOutput(output(101), &ready);
  pairing.addVariance(100, varianceOf(100), &ready);
  ASSERT_EQ(ready.size(), 1u);
  // The bag loops: 101's variance will never come.
  pairing.addOutput(output(5, kFlagReset), &ready);
  ASSERT_EQ(ready.size(), 3u);
  EXPECT_EQ(ready[1].stamp, 101);
  EXPECT_TRUE(std::isnan(ready[1].rate_variance));
  EXPECT_EQ(ready[2].stamp, 5);
  pairing.addVariance(6, varianceOf(6), &ready);
  pairing.addOutput(output(6), &ready);
  ASSERT_EQ(ready.size(), 4u);
  EXPECT_EQ(ready[3].rate_variance, varianceOf(6));
  // A variance topic that loops drops what it held from before.
  pairing.addVariance(200, varianceOf(200), &ready);
  pairing.addVariance(7, varianceOf(7), &ready);
  EXPECT_EQ(pairing.heldVariances(), 1u);
  pairing.addOutput(output(7), &ready);
  EXPECT_EQ(ready.back().rate_variance, varianceOf(7));
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
