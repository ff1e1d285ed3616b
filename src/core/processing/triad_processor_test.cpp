// The triad's processing chain against what the live nodes do: each axis's output combined with the
// variance its processor node reports for it (none with a gap, 1e6 when the wave was turned on
// command), an output held until its axis's precession state reaches its stamp and flagged when the
// loop turned the wave, the end of the input deciding what still waits, and the processors alone
// giving a plain processor's results and combining nothing.
#include "hrg_gyro/core/processing/triad_processor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hrg_gyro/core/model/wave_parameters.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kMs = 1000000;
constexpr Nanoseconds kStart = 1000 * kMs;

/// Sample k (1 ms apart) of axis `axis`, whose wave turns at its own constant rate.
ChannelSample sampleAt(std::size_t axis, int k) {
  ChannelSample s;
  s.stamp = kStart + k * kMs;
  s.z = idealChannels({1.0, 0.02, 0.1 + (0.02 + 0.01 * axis) * 1e-3 * k, 0.3});
  s.frequency = 5000.0;
  return s;
}

std::array<GyroParameters, 3> nominalAxes() { return {{GyroParameters(), GyroParameters(), GyroParameters()}}; }

TriadProcessor nominalTriad() {
  return TriadProcessor(TriadProcessorSettings(), nominalAxes(), std::make_shared<const TriadParameters>());
}

TEST(TriadProcessorTest, EachAxisIsCombinedWithTheVarianceItsProcessorNodeReports) {
  TriadProcessor triad = nominalTriad();
  std::array<GyroProcessor, 3> plain{{GyroProcessor(ProcessorConfig(), std::make_shared<GyroParameters>()),
                                      GyroProcessor(ProcessorConfig(), std::make_shared<GyroParameters>()),
                                      GyroProcessor(ProcessorConfig(), std::make_shared<GyroParameters>())}};
  std::array<RateNoiseEstimator, 3> noise;
  std::vector<TriadAxisOutput> outputs;
  std::vector<TriadBodySample> samples;
  ProcessorResult r;
  for (int k = 0; k <= 400; ++k) {
    std::array<double, 3> dalpha{};
    for (std::size_t a = 0; a < 3; ++a) {
      outputs.clear();
      triad.process(a, sampleAt(a, k), &r);
      const ProcessorResult expected = plain[a].process(sampleAt(a, k));
      EXPECT_EQ(r.alpha, expected.alpha);
      triad.release(&outputs, &samples);
      // No precession state: nothing waits, each output goes on at once.
      ASSERT_EQ(outputs.size(), k > 0 ? 1u : 0u) << k;
      if (k == 0) continue;
      noise[a].add(expected.alpha, expected.increment.dt, expected.flags);
      const AxisOutput& o = outputs[0].output;
      EXPECT_EQ(outputs[0].axis, a);
      EXPECT_EQ(o.stamp, sampleAt(a, k).stamp);
      EXPECT_EQ(o.dalpha, expected.increment.dalpha);
      EXPECT_EQ(o.flags, 0);
      EXPECT_EQ(o.rate_variance, noise[a].variance());
      dalpha[a] = o.dalpha;
    }
    if (k == 0) continue;
    ASSERT_EQ(samples.size(), static_cast<std::size_t>(k));
    const TriadBodySample& s = samples.back();
    ASSERT_TRUE(s.integrated());
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(s.delta_angle(i), dalpha[i]);  // M = I, no bias
      EXPECT_EQ(s.covariance(i, i), noise[i].variance());
    }
  }
  EXPECT_GT(noise[0].secondDifferences(), RateNoiseEstimator::kSettledDifferences);  // measured, not initial
  EXPECT_EQ(triad.outputs(1), 400u);
  EXPECT_EQ(triad.combiner().counters().integrated, 400u);
}

TEST(TriadProcessorTest, AnOutputWaitsForItsAxisPrecessionStateAndIsFlaggedWhenTheWaveWasTurned) {
  TriadProcessor triad = nominalTriad();
  // The commanded rate of axis 1's loop at each sample's end: turning from sample 10 to 20.
  auto rate = [](int k) { return k >= 10 && k <= 20 ? 0.5 : 0.0; };
  double angle = 0.0;
  ASSERT_TRUE(triad.addPrecessionState(1, {kStart - kMs, 0.0, 0.0}));  // the loop idle before the first sample
  std::vector<TriadAxisOutput> outputs;
  std::vector<TriadBodySample> samples;
  ProcessorResult r;
  for (int k = 0; k <= 40; ++k) {
    outputs.clear();
    samples.clear();
    for (std::size_t a = 0; a < 3; ++a) {
      triad.process(a, sampleAt(a, k), &r);
      triad.release(&outputs, &samples);
    }
    // Axis 1's output waits for the state of its stamp, and the triad sample with it.
    for (const TriadAxisOutput& o : outputs) EXPECT_NE(o.axis, 1u) << k;
    EXPECT_TRUE(samples.empty()) << k;
    angle += rate(k) * 1e-3;
    outputs.clear();
    ASSERT_TRUE(triad.addPrecessionState(1, {sampleAt(1, k).stamp, rate(k), angle}));
    triad.release(&outputs, &samples);
    if (k == 0) continue;
    ASSERT_EQ(outputs.size(), 1u) << k;
    ASSERT_EQ(samples.size(), 1u) << k;
    const bool turned = rate(k - 1) != 0.0 || rate(k) != 0.0;  // in force over (k - 1, k]
    EXPECT_EQ((outputs[0].output.flags & kFlagPrecessing) != 0, turned) << k;
    EXPECT_EQ(outputs[0].output.rate_variance == kUnmeasuredRateVariance, turned) << k;
    EXPECT_EQ((samples[0].flags & kTriadFlagPrecessing) != 0, turned) << k;
    EXPECT_EQ(samples[0].covariance(1, 1) == kUnmeasuredRateVariance, turned) << k;
  }
  EXPECT_EQ(triad.precessed(1), 12u);  // samples 10 to 21
  EXPECT_EQ(triad.precessed(0) + triad.precessed(2), 0u);
  EXPECT_EQ(triad.precession(1).counters().states, 42u);
}

TEST(TriadProcessorTest, GapsAndResetsCarryNoVariance) {
  TriadProcessor triad = nominalTriad();
  std::vector<TriadAxisOutput> outputs;
  std::vector<TriadBodySample> samples;
  ProcessorResult r;
  for (int k = 0; k <= 60; ++k) {
    if (k > 20 && k < 40) continue;  // 20 ms without samples on every axis
    for (std::size_t a = 0; a < 3; ++a) {
      ChannelSample s = sampleAt(a, k);
      if (k >= 40) s.stamp += 300 * kMs;  // and then 300 ms more: beyond max_gap
      triad.process(a, s, &r);
      triad.release(&outputs, &samples);
    }
  }
  std::size_t gaps = 0;
  for (const TriadAxisOutput& o : outputs) {
    if (o.output.flags & (kFlagGap | kFlagReset)) {
      ++gaps;
      EXPECT_TRUE(std::isnan(o.output.rate_variance));
    } else {
      EXPECT_GT(o.output.rate_variance, 0.0);
    }
  }
  EXPECT_EQ(gaps, 3u);  // one per axis
}

TEST(TriadProcessorTest, TheEndOfTheInputDecidesWhatWaitsAndFlushesTheCombiner) {
  TriadProcessor triad = nominalTriad();
  ASSERT_TRUE(triad.addPrecessionState(2, {kStart, 0.0, 0.0}));
  std::vector<TriadAxisOutput> outputs;
  std::vector<TriadBodySample> samples;
  ProcessorResult r;
  for (int k = 0; k <= 10; ++k) {
    for (std::size_t a = 0; a < 3; ++a) {
      triad.process(a, sampleAt(a, k), &r);
      triad.release(&outputs, &samples);
    }
    // Axis 2's state stream stops at sample 5: its later outputs wait (within the hold).
    if (k <= 5) triad.addPrecessionState(2, {sampleAt(2, k).stamp, 0.0, 0.0});
    triad.release(&outputs, &samples);
  }
  EXPECT_EQ(samples.size(), 5u);
  EXPECT_EQ(triad.precession(2).waiting(), 5u);
  outputs.clear();
  triad.finish(&outputs, &samples);
  // Decided with what is known: the state stopped short of them, the wave may have turned.
  ASSERT_EQ(outputs.size(), 5u);
  for (const TriadAxisOutput& o : outputs) {
    EXPECT_EQ(o.axis, 2u);
    EXPECT_TRUE(o.output.flags & kFlagPrecessing);
  }
  ASSERT_EQ(samples.size(), 10u);
  for (std::size_t k = 5; k < 10; ++k) EXPECT_TRUE(samples[k].flags & kTriadFlagPrecessing) << k;
  EXPECT_EQ(triad.precession(2).counters().unknown, 5u);
}

TEST(TriadProcessorTest, TheProcessorsAloneGiveAPlainProcessorsResultsAndCombineNothing) {
  TriadProcessor processors(ProcessorConfig(), nominalAxes());
  EXPECT_FALSE(processors.combining());
  GyroProcessor plain(ProcessorConfig(), std::make_shared<GyroParameters>());
  std::vector<TriadAxisOutput> outputs;
  std::vector<TriadBodySample> samples;
  ProcessorResult r;
  for (int k = 0; k <= 50; ++k) {
    processors.process(1, sampleAt(1, k), &r);
    const ProcessorResult expected = plain.process(sampleAt(1, k));
    EXPECT_EQ(r.wave.theta, expected.wave.theta);
    EXPECT_EQ(r.alpha, expected.alpha);
    processors.release(&outputs, &samples);
  }
  processors.finish(&outputs, &samples);
  EXPECT_TRUE(outputs.empty());
  EXPECT_TRUE(samples.empty());
  EXPECT_EQ(processors.processor(1).counters().outputs, 50u);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
