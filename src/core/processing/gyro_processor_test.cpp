// The processor's handling of bad input and time: reject, count, flag, recover, never NaN.
#include "hrg_gyro/core/processing/gyro_processor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <utility>
#include <vector>

#include "core/testing/faulty_channel_stream.h"
#include "core/testing/same_bits.h"
#include "hrg_gyro/core/common/yaml_field.h"

namespace hrg_gyro {
namespace core {
namespace {

constexpr Nanoseconds kMs = 1000000;

class GyroProcessorTest : public ::testing::Test {
 protected:
  GyroProcessorTest() : params_(std::make_shared<GyroParameters>()), proc_(ProcessorConfig{}, params_) {}

  // A wave turning at a constant electrical rate: theta = 0.1 + rate t.
  ChannelSample at(Nanoseconds t, double theta_rate = -0.028) const {
    ChannelSample s;
    s.stamp = t;
    s.z = idealChannels({1.0, 0.02, 0.1 + theta_rate * toSeconds(t), 0.3});
    s.frequency = 5000.0;
    return s;
  }
  void expectFinite(const ProcessorResult& r) {
    for (double v : {r.alpha, r.increment.dalpha, r.increment.dt, r.increment.scale_factor, r.wave.theta}) {
      EXPECT_TRUE(std::isfinite(v));
    }
  }

  std::shared_ptr<GyroParameters> params_;
  GyroProcessor proc_;
};

TEST_F(GyroProcessorTest, IntegratesACleanStream) {
  EXPECT_EQ(proc_.process(at(1000 * kMs)).verdict, SampleVerdict::kFirst);
  ProcessorResult r;
  for (int i = 1; i <= 1000; ++i) r = proc_.process(at((1000 + i) * kMs));
  EXPECT_EQ(r.verdict, SampleVerdict::kAccepted);
  EXPECT_NEAR(r.alpha, -0.028 * 1.0 / -0.56, 1e-12);  // 1 s at 0.05 rad/s
  EXPECT_EQ(proc_.counters().outputs, 1000u);
  EXPECT_EQ(proc_.counters().rejected(), 0u);
}

TEST_F(GyroProcessorTest, RejectsBadValuesCountsThemAndRecovers) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  proc_.process(at(1000 * kMs));
  proc_.process(at(1001 * kMs));
  ChannelSample bad = at(1002 * kMs);
  bad.z[kAs] = nan;
  EXPECT_EQ(proc_.process(bad).verdict, SampleVerdict::kRejectedValue);
  bad = at(1003 * kMs);
  bad.z.setZero();
  EXPECT_EQ(proc_.process(bad).wave_status, WaveStatus::kNoSignal);
  bad = at(1004 * kMs);
  bad.z = idealChannels({1.0, 1.0, 0.3, 0.0});
  EXPECT_EQ(proc_.process(bad).wave_status, WaveStatus::kDegenerate);
  bad = at(1005 * kMs);
  bad.z *= 1e300;  // finite, but its energy overflows: out of range
  EXPECT_EQ(proc_.process(bad).wave_status, WaveStatus::kAmplitudeOutOfRange);
  const ProcessorResult r = proc_.process(at(1006 * kMs));
  ASSERT_TRUE(r.has_output);
  expectFinite(r);
  EXPECT_EQ(r.rejected_before, 4u);
  EXPECT_NEAR(r.increment.dt, 0.005, 1e-15);            // the increment spans the rejected samples
  EXPECT_NEAR(r.alpha, -0.028 * 0.006 / -0.56, 1e-12);  // nothing lost
  EXPECT_EQ(proc_.counters().non_finite, 1u);
  EXPECT_EQ(proc_.counters().amplitude_out_of_range, 1u);
  EXPECT_EQ(proc_.counters().no_signal, 1u);
  EXPECT_EQ(proc_.counters().degenerate, 1u);
}

TEST_F(GyroProcessorTest, DropsZeroDuplicateAndOutOfOrderStamps) {
  proc_.process(at(1000 * kMs));
  proc_.process(at(1001 * kMs));
  EXPECT_EQ(proc_.process(at(0)).verdict, SampleVerdict::kRejectedStamp);
  EXPECT_EQ(proc_.process(at(1001 * kMs)).verdict, SampleVerdict::kDuplicate);
  EXPECT_EQ(proc_.process(at(1000 * kMs + kMs / 2)).verdict, SampleVerdict::kOutOfOrder);
  const ProcessorResult r = proc_.process(at(1002 * kMs));
  EXPECT_EQ(r.verdict, SampleVerdict::kAccepted);
  EXPECT_EQ(r.rejected_before, 3u);
  EXPECT_EQ(proc_.counters().zero_stamp, 1u);
  EXPECT_EQ(proc_.counters().duplicate, 1u);
  EXPECT_EQ(proc_.counters().out_of_order, 1u);
}

TEST_F(GyroProcessorTest, BackwardJumpThatPersistsResetsAndFlags) {
  for (int i = 0; i < 100; ++i) proc_.process(at((5000 + i) * kMs));
  // Bag looped: the first jump_persist - 1 samples of the new timeline are dropped as jumps, the
  // jump_persist-th starts over.
  const int persist = ProcessorConfig{}.jump_persist;
  for (int i = 0; i < persist - 1; ++i) {
    EXPECT_EQ(proc_.process(at((1000 + i) * kMs)).verdict, SampleVerdict::kStampJump) << i;
  }
  EXPECT_EQ(proc_.process(at((1000 + persist - 1) * kMs)).verdict, SampleVerdict::kFirst);
  const ProcessorResult r = proc_.process(at((1000 + persist) * kMs));
  EXPECT_TRUE(r.flags & kFlagReset);
  EXPECT_NEAR(r.alpha, r.increment.dalpha, 1e-18);  // alpha restarted
  EXPECT_EQ(proc_.counters().resets, 1u);
  EXPECT_EQ(proc_.counters().stamp_jumps, static_cast<std::uint64_t>(persist - 1));
  EXPECT_FALSE(proc_.process(at((1001 + persist) * kMs)).flags & kFlagReset);
}

TEST_F(GyroProcessorTest, DoesNotIntegrateAcrossAGap) {
  proc_.process(at(1000 * kMs));
  const double alpha_before = proc_.process(at(1001 * kMs)).alpha;
  // 1 s later (above max_gap), for good: a gap, taken at the jump_persist-th sample after it.
  const int persist = ProcessorConfig{}.jump_persist;
  for (int i = 0; i < persist - 1; ++i) {
    EXPECT_EQ(proc_.process(at((2001 + i) * kMs)).verdict, SampleVerdict::kStampJump) << i;
  }
  const Nanoseconds resumed = (2001 + persist - 1) * kMs;
  const ProcessorResult r = proc_.process(at(resumed));
  EXPECT_TRUE(r.flags & kFlagGap);
  EXPECT_EQ(r.increment.dalpha, 0.0);
  EXPECT_EQ(r.alpha, alpha_before);
  EXPECT_EQ(proc_.counters().gaps, 1u);
  EXPECT_NEAR(proc_.counters().largest_gap, toSeconds(resumed - 1001 * kMs), 1e-12);
  const ProcessorResult next = proc_.process(at(resumed + kMs));
  EXPECT_FALSE(next.flags & kFlagGap);
  EXPECT_NEAR(next.alpha - alpha_before, -0.028 * 0.001 / -0.56, 1e-12);
}

TEST_F(GyroProcessorTest, OneSampleStampedAheadOrFarBackCostsThatSampleOnly) {
  // The same stream with and without single glitched stamps (1000 s ahead, 0.2 s ahead, 100 s back):
  // every other sample gives the same output, and alpha ends the same.
  GyroProcessor clean(ProcessorConfig{}, params_);
  ProcessorResult a, b;
  int glitches = 0;
  for (int i = 0; i < 2000; ++i) {
    const Nanoseconds t = (500000 + i) * kMs;  // 500 s: 100 s back is still a stamp
    if (i == 500 || i == 900 || i == 1300) {
      const Nanoseconds off = i == 500 ? 1000000 * kMs : i == 900 ? 200 * kMs : -100000 * kMs;
      ChannelSample glitched = at(t);
      glitched.stamp = t + off;
      EXPECT_EQ(proc_.process(glitched).verdict, SampleVerdict::kStampJump) << i;
      ++glitches;
      continue;  // the glitched sample replaces the good one of its instant
    }
    a = clean.process(at(t));
    b = proc_.process(at(t));
    if (i == 501 || i == 901 || i == 1301) {
      EXPECT_EQ(b.rejected_before, 1u);
      EXPECT_EQ(b.flags, 0u) << "no gap, no reset after a glitch";
      EXPECT_NEAR(b.increment.dt, 0.002, 1e-15);  // the increment spans the dropped sample
    }
  }
  EXPECT_EQ(proc_.counters().stamp_jumps, 3u);
  EXPECT_EQ(proc_.counters().gaps + proc_.counters().resets, 0u);
  EXPECT_NEAR(b.alpha, a.alpha, 1e-15);  // nothing lost
  EXPECT_EQ(glitches, 3);
}

TEST_F(GyroProcessorTest, RejectsAChannelSignFlipAsAGlitchThenReanchors) {
  proc_.process(at(1000 * kMs));
  proc_.process(at(1001 * kMs));
  ChannelSample flip = at(1002 * kMs);
  flip.z[kAs] = -flip.z[kAs];  // one channel inverted: theta -> -theta
  flip.z[kBs] = -flip.z[kBs];
  EXPECT_EQ(proc_.process(flip).verdict, SampleVerdict::kRejectedJump);
  EXPECT_EQ(proc_.process(at(1003 * kMs)).verdict, SampleVerdict::kAccepted);
  // A persistent jump is accepted after max_consecutive_jumps as a re-anchor.
  ProcessorResult r;
  for (int i = 0; i < 6; ++i) {
    flip = at((1004 + i) * kMs);
    flip.z[kAs] = -flip.z[kAs];
    flip.z[kBs] = -flip.z[kBs];
    r = proc_.process(flip);
  }
  EXPECT_EQ(r.verdict, SampleVerdict::kAccepted);
  EXPECT_TRUE(r.flags & kFlagGap);
  EXPECT_EQ(proc_.counters().jumps, 6u);
  expectFinite(r);
}

TEST_F(GyroProcessorTest, ModelSwapTakesEffectOnTheNextSample) {
  proc_.process(at(1000 * kMs));
  const ProcessorResult a = proc_.process(at(1001 * kMs));
  auto doubled = std::make_shared<GyroParameters>(*params_);
  doubled->scale_factor = HarmonicModel(-1.12);
  proc_.setParameters(doubled);
  const ProcessorResult b = proc_.process(at(1002 * kMs));
  EXPECT_NEAR(b.increment.dalpha, a.increment.dalpha / 2.0, 1e-15);
  EXPECT_NEAR(b.alpha, a.alpha * 1.5, 1e-15);  // carries on, no reset
}

TEST_F(GyroProcessorTest, FlagsMissingOrOutOfRangeFrequency) {
  auto p = std::make_shared<GyroParameters>();
  Eigen::MatrixXd v(1, 2);
  v << -0.56, -0.57;
  p->scale_factor = HarmonicModel({}, FrequencyInterpolator({4990.0, 5010.0}), v);
  GyroProcessor proc(ProcessorConfig{}, p);
  ChannelSample s = at(1000 * kMs);
  proc.process(s);
  s = at(1001 * kMs);
  s.frequency = NAN;
  EXPECT_TRUE(proc.process(s).flags & kFlagFrequencyUnknown);
  s = at(1002 * kMs);
  s.frequency = 6000.0;
  const ProcessorResult r = proc.process(s);
  EXPECT_TRUE(r.flags & kFlagFrequencyUnknown);  // the previous sample had none: the midpoint is unknown
  s = at(1003 * kMs);
  s.frequency = 6000.0;
  EXPECT_TRUE(proc.process(s).flags & kFlagFrequencyOutOfRange);
}

TEST_F(GyroProcessorTest, ModelWithFrequencyNodesInKOnlyIsInRangeInsideTheNodes) {
  // D frequency independent (one constant node): only K's nodes bound the valid range.
  auto p = std::make_shared<GyroParameters>();
  Eigen::MatrixXd v(1, 2);
  v << -0.56, -0.57;
  p->scale_factor = HarmonicModel({}, FrequencyInterpolator({4990.0, 5010.0}), v);
  ASSERT_FALSE(p->drift.frequencyDependent());
  GyroProcessor proc(ProcessorConfig{}, p);
  proc.process(at(1000 * kMs));
  for (int i = 1; i <= 20; ++i) {
    const ProcessorResult r = proc.process(at((1000 + i) * kMs));  // 5000 Hz, inside the nodes
    ASSERT_TRUE(r.has_output);
    EXPECT_FALSE(r.flags & kFlagFrequencyOutOfRange) << i;
  }
  EXPECT_EQ(proc.counters().frequency_out_of_range, 0u);
  ChannelSample s = at(1021 * kMs);
  s.frequency = 5020.0;  // midpoint 5010: still the last node
  EXPECT_FALSE(proc.process(s).flags & kFlagFrequencyOutOfRange);
  s = at(1022 * kMs);
  s.frequency = 5030.0;
  EXPECT_TRUE(proc.process(s).flags & kFlagFrequencyOutOfRange);
  // The same with the roles swapped: nodes in D only.
  auto q = std::make_shared<GyroParameters>();
  Eigen::MatrixXd dv(1, 2);
  dv << 1e-5, 2e-5;
  q->drift = HarmonicModel({}, FrequencyInterpolator({4990.0, 5010.0}), dv);
  GyroProcessor proc_d(ProcessorConfig{}, q);
  proc_d.process(at(1000 * kMs));
  EXPECT_FALSE(proc_d.process(at(1001 * kMs)).flags & kFlagFrequencyOutOfRange);
}

TEST(FrequencyInterpolatorRangeTest, ASingleNodeIsValidAtEveryFiniteFrequency) {
  const FrequencyInterpolator constant;
  EXPECT_TRUE(constant.inRange(5000.0));
  EXPECT_TRUE(constant.inRange(0.0));
  EXPECT_FALSE(constant.inRange(NAN));
  const FrequencyInterpolator nodes({4990.0, 5010.0});
  EXPECT_TRUE(nodes.inRange(5000.0));
  EXPECT_FALSE(nodes.inRange(5011.0));
}

TEST(GyroProcessorModelSwapTest, ANewCorrectionMatrixDoesNotStepTheAngle) {
  auto p = std::make_shared<GyroParameters>();
  GyroProcessor proc(ProcessorConfig{}, p);
  // Raw channels through a misplacement-like map: the new P rotates theta by ~1e-3 rad.
  auto z = [](double theta) { return idealChannels({1.0, 0.0, theta, 0.2}); };
  proc.process({toNanoseconds(1.000), z(0.300), NAN, NAN});
  const double alpha1 = proc.process({toNanoseconds(1.001), z(0.299), NAN, NAN}).alpha;
  auto with_p = std::make_shared<GyroParameters>(*p);
  with_p->correction.p = {0.0, 0.0, 1e-3, -1e-3};
  proc.setParameters(with_p);
  const ProcessorResult r = proc.process({toNanoseconds(1.002), z(0.298), NAN, NAN});
  // The increment is the wave's real motion (seen through the same P), not the rotation by P.
  // (P also shears the motion slightly, by ~1e-3 relative; without the re-read the step would be 1.8e-3.)
  EXPECT_NEAR(r.alpha - alpha1, -0.001 / -0.56, 1e-5);
  EXPECT_FALSE(r.flags & kFlagGap);
}

// The limits' one rule set (the node and hrg_bag both apply it): each refusal names its key.
TEST(ProcessorConfigTest, AcceptsTheDefaultsAndNamesTheKeyOfEachRefusal) {
  EXPECT_NO_THROW(validate(ProcessorConfig{}));
  const double inf = std::numeric_limits<double>::infinity(), nan = std::numeric_limits<double>::quiet_NaN();
  struct Case {
    const char* key;
    void (*spoil)(ProcessorConfig&);
  };
  const Case cases[] = {
      {"max_gap", [](ProcessorConfig& c) { c.max_gap = 0.0; }},
      {"max_gap", [](ProcessorConfig& c) { c.max_gap = -1.0; }},
      {"backward_reset", [](ProcessorConfig& c) { c.backward_reset = -5.0; }},
      {"jump_persist", [](ProcessorConfig& c) { c.jump_persist = 0; }},
      {"jump_persist", [](ProcessorConfig& c) { c.jump_persist = 1001; }},
      {"max_rate", [](ProcessorConfig& c) { c.max_rate = 0.0; }},
      {"max_consecutive_jumps", [](ProcessorConfig& c) { c.max_consecutive_jumps = -1; }},
      {"min_anisotropy", [](ProcessorConfig& c) { c.limits.min_anisotropy = 2.0; }},
      {"min_anisotropy", [](ProcessorConfig& c) { c.limits.min_anisotropy = 0.0; }},
      {"min_amplitude", [](ProcessorConfig& c) { c.limits.min_amplitude = -1.0; }},
      {"max_amplitude", [](ProcessorConfig& c) { c.limits.max_amplitude = 0.0; }},
      {"max_amplitude",
       [](ProcessorConfig& c) {
         c.limits.min_amplitude = 5.0;
         c.limits.max_amplitude = 1.0;
       }},
  };
  for (const Case& k : cases) {
    ProcessorConfig c;
    k.spoil(c);
    try {
      validate(c);
      ADD_FAILURE() << "accepted a bad " << k.key;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), k.key) << e.what();
    }
  }
  for (double bad : {inf, nan}) {
    ProcessorConfig c;
    c.max_rate = bad;
    EXPECT_THROW(validate(c), ConfigError);
    c = ProcessorConfig{};
    c.limits.max_amplitude = bad;
    EXPECT_THROW(validate(c), ConfigError);
    c = ProcessorConfig{};
    c.limits.min_anisotropy = bad;
    EXPECT_THROW(validate(c), ConfigError);
  }
}

// Every field of two results, bit for bit (NaN included).
void expectIdentical(const ProcessorResult& a, const ProcessorResult& b, std::size_t i) {
  ASSERT_EQ(a.verdict, b.verdict) << i;
  ASSERT_EQ(a.wave_status, b.wave_status) << i;
  ASSERT_EQ(a.has_wave, b.has_wave) << i;
  ASSERT_EQ(a.has_output, b.has_output) << i;
  ASSERT_EQ(a.flags, b.flags) << i;
  ASSERT_EQ(a.rejected_before, b.rejected_before) << i;
  ASSERT_TRUE(sameWaveBits(a.wave, b.wave)) << i;
  ASSERT_TRUE(sameIncrementBits(a.increment, b.increment)) << i;
  ASSERT_TRUE(sameBits(a.alpha, b.alpha)) << i << ": alpha " << a.alpha << " vs " << b.alpha;
}

// K with four harmonics, depending on the frequency or not (then processBatch computes the
// increments four at a time; Compensator::steps), D with two.
std::shared_ptr<GyroParameters> batchTestParameters(double p3, bool frequency_dependent) {
  auto p = std::make_shared<GyroParameters>();
  Eigen::MatrixXd k(9, 3);
  for (int j = 0; j < 3; ++j) {
    k(0, j) = -0.56 * (1.0 + 1e-4 * j);
    for (int i = 0; i < 4; ++i) {
      k(1 + i, j) = 1e-4 / (i + 1) * (1.0 + 0.1 * j);
      k(5 + i, j) = -0.5e-4 / (i + 1) * (1.0 - 0.1 * j);
    }
  }
  if (frequency_dependent) {
    p->scale_factor = HarmonicModel({2, 4, 6, 8}, FrequencyInterpolator({4990.0, 5000.0, 5010.0}), k);
  } else {
    p->scale_factor = HarmonicModel({2, 4, 6, 8}, k(0, 0), {k(1, 0), k(2, 0), k(3, 0), k(4, 0)},
                                    {k(5, 0), k(6, 0), k(7, 0), k(8, 0)});
  }
  p->drift = HarmonicModel({2, 4}, 1e-5, {2e-5, 1e-6}, {-1e-5, 0.0});
  p->correction.p = {1e-3, -2e-3, p3, 0.5e-3};
  return p;
}

// The batch entry point against one call per sample over a long stream with every kind of fault,
// batches of random lengths and parameter reloads between batches: the same results bit for bit, the
// same counters.
void expectBatchMatchesOneCallPerSample(bool frequency_dependent) {
  const std::vector<ChannelSample> in = testing::faultyChannelStream(60000, 16);
  GyroProcessor single(ProcessorConfig{}, batchTestParameters(1e-3, frequency_dependent));
  GyroProcessor batch(ProcessorConfig{}, batchTestParameters(1e-3, frequency_dependent));
  const GyroParameters& models = batch.parameters();
  EXPECT_EQ(ModelPairEvaluator(models.scale_factor, models.drift).lanesApply(), !frequency_dependent);
  std::vector<ProcessorResult> out(in.size());
  std::mt19937 lengths(7);
  std::size_t begin = 0, reloads = 0;
  while (begin < in.size()) {
    const std::size_t n = std::min<std::size_t>(1 + lengths() % 400, in.size() - begin);
    batch.processBatch(in.data() + begin, n, out.data() + begin);
    for (std::size_t i = begin; i < begin + n; ++i) expectIdentical(single.process(in[i]), out[i], i);
    if (::testing::Test::HasFatalFailure()) return;
    begin += n;
    if (lengths() % 8 == 0) {  // a reload: a new P and a new model on both
      const auto reloaded = batchTestParameters(1e-3 * static_cast<double>(++reloads % 3), frequency_dependent);
      single.setParameters(reloaded);
      batch.setParameters(reloaded);
    }
  }
  EXPECT_GT(reloads, 10u);
  const ProcessorCounters &a = single.counters(), &b = batch.counters();
  EXPECT_EQ(a.received, in.size());
  EXPECT_EQ(a.accepted, b.accepted);
  EXPECT_EQ(a.outputs, b.outputs);
  EXPECT_EQ(a.rejected(), b.rejected());
  EXPECT_EQ(a.gaps, b.gaps);
  EXPECT_EQ(a.resets, b.resets);
  EXPECT_EQ(a.frequency_unknown, b.frequency_unknown);
  EXPECT_EQ(a.frequency_out_of_range, b.frequency_out_of_range);
  // The stream really exercises every rule (the frequency ones only bind a frequency-dependent model).
  for (std::uint64_t count : {a.non_finite, a.no_signal, a.degenerate, a.amplitude_out_of_range, a.zero_stamp,
                              a.duplicate, a.out_of_order, a.jumps, a.gaps, a.resets, a.stamp_jumps}) {
    EXPECT_GT(count, 0u);
  }
  if (frequency_dependent) {
    EXPECT_GT(a.frequency_unknown, 0u);
    EXPECT_GT(a.frequency_out_of_range, 0u);
  }
  EXPECT_GT(a.outputs, in.size() / 2);
}

TEST(GyroProcessorBatchTest, MatchesOneCallPerSampleBitForBit) { expectBatchMatchesOneCallPerSample(false); }

TEST(GyroProcessorBatchTest, MatchesOneCallPerSampleBitForBitWithFrequencyDependentModels) {
  expectBatchMatchesOneCallPerSample(true);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
