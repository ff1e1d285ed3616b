#include "hrg_gyro/core/processing/block_mean_stillness.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace hrg_gyro {
namespace core {
namespace {

// Samples of 0.125 s (exact in binary: four make a 0.5 s block) at a constant rate per channel.
void feed(BlockMeanStillness* s, int samples, double r0, double r1 = 0.0, double r2 = 0.0) {
  for (int k = 0; k < samples; ++k) {
    const double increment[3] = {0.125 * r0, 0.125 * r1, 0.125 * r2};
    s->add(0.125, increment);
  }
}

TEST(BlockMeanStillness, ConstantRateIsStill) {
  BlockMeanStillness s(3, 0.5);
  EXPECT_FALSE(s.hasBlock());
  feed(&s, 32, 1e-4, -2e-5, 7e-5);
  ASSERT_TRUE(s.hasBlock());
  EXPECT_NEAR(s.lowestMean(0), 1e-4, 1e-15);
  EXPECT_NEAR(s.highestMean(2), 7e-5, 1e-15);
  EXPECT_LT(s.worstHalfSpread(), 1e-15);
  EXPECT_FALSE(s.moved(1e-9));
}

TEST(BlockMeanStillness, ATurnSpreadsTheBlockMeans) {
  BlockMeanStillness s(1, 0.5);
  feed(&s, 8, 0.0);
  feed(&s, 4, 2e-3);  // one block turning at 2e-3 rad/s
  feed(&s, 8, 0.0);
  EXPECT_NEAR(s.lowestMean(0), 0.0, 1e-15);
  EXPECT_NEAR(s.highestMean(0), 2e-3, 1e-12);
  EXPECT_NEAR(s.worstHalfSpread(), 1e-3, 1e-12);
  EXPECT_TRUE(s.moved(0.9e-3));
  EXPECT_FALSE(s.moved(1.1e-3));
}

TEST(BlockMeanStillness, ARestartJudgesTheNextRestAloneAndKeepsTheWorst) {
  BlockMeanStillness s(2, 0.5);
  feed(&s, 4, 0.0, 0.0);
  feed(&s, 4, 0.0, 4e-3);  // channel 1 spreads 4e-3 in the first rest
  s.restart();
  EXPECT_FALSE(s.hasBlock());
  feed(&s, 8, 1.0, 1.0);  // a new rest at another rate: not a spread
  EXPECT_NEAR(s.lowestMean(1), 1.0, 1e-12);
  EXPECT_NEAR(s.highestMean(1), 1.0, 1e-12);
  EXPECT_NEAR(s.worstHalfSpread(), 2e-3, 1e-12);
}

TEST(BlockMeanStillness, PartialBlockClosesOnlyPastTheFraction) {
  BlockMeanStillness s(1, 1.0);
  feed(&s, 8, 0.0);
  feed(&s, 3, 1e-2);  // 0.375 s of a block: below half, not judged
  s.closePartialBlock(0.5);
  EXPECT_LT(s.worstHalfSpread(), 1e-15);
  feed(&s, 2, 1e-2);  // 0.625 s now
  s.closePartialBlock(0.5);
  EXPECT_NEAR(s.highestMean(0), 1e-2, 1e-12);
  EXPECT_NEAR(s.worstHalfSpread(), 5e-3, 1e-12);
}

TEST(BlockMeanStillness, RefusesWhatItCannotJudge) {
  EXPECT_THROW(BlockMeanStillness(0, 0.5), std::invalid_argument);
  EXPECT_THROW(BlockMeanStillness(4, 0.5), std::invalid_argument);
  EXPECT_THROW(BlockMeanStillness(1, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
