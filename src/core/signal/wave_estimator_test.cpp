// Wave state from Z (docs/math.md, 'Wave angle') and unwrapping.
#include "hrg_gyro/core/signal/wave_estimator.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <random>
#include <vector>

#include "core/testing/same_bits.h"
#include "core/testing/uniform_draws.h"
#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/signal/theta_unwrapper.h"

namespace hrg_gyro {
namespace core {
namespace {

TEST(WaveEstimatorTest, RecoversRandomWaves) {
  testing::UniformDraws u(11);
  for (int trial = 0; trial < 500; ++trial) {
    WaveParameters w;
    w.amplitude = 0.2 + std::abs(u());
    w.quadrature = 0.3 * w.amplitude * u();
    w.theta = 0.499 * kPi * u();  // principal range of atan2(S, R)/2
    w.phase = 0.999 * kPi * u();
    WaveState s;
    ASSERT_EQ(estimateWave(idealChannels(w), WaveLimits{}, &s), WaveStatus::kOk);
    EXPECT_NEAR(s.theta, w.theta, 1e-12);
    EXPECT_NEAR(s.amplitude, w.amplitude, 1e-12);
    EXPECT_NEAR(s.quadrature, w.quadrature, 1e-12);
    EXPECT_NEAR(wrapToPi(s.phase - w.phase), 0.0, 1e-11);
    const double a2 = w.amplitude * w.amplitude, b2 = w.quadrature * w.quadrature;
    EXPECT_NEAR(s.energy, a2 + b2, 1e-12);
    EXPECT_NEAR(s.quadrature_product, 2.0 * w.amplitude * w.quadrature, 1e-12);  // Q = +2AB
    EXPECT_NEAR(s.cos_component, (a2 - b2) * std::cos(2 * w.theta), 1e-12);
    EXPECT_NEAR(s.sin_component, (a2 - b2) * std::sin(2 * w.theta), 1e-12);
    EXPECT_NEAR(s.phase_error, -(a2 - b2) * std::sin(2 * w.phase), 1e-12);
  }
}

TEST(WaveEstimatorTest, ThetaIsDefinedModuloPi) {
  // (A, theta + pi, tau + pi) is the same wave; rebase keeps the phase consistent.
  const WaveParameters w{1.0, 0.05, 0.4, 0.3};
  const WaveParameters flipped{1.0, 0.05, 0.4 + kPi, 0.3 + kPi};
  EXPECT_LT((idealChannels(w) - idealChannels(flipped)).norm(), 1e-14);
  WaveState s;
  ASSERT_EQ(estimateWave(idealChannels(w), WaveLimits{}, &s), WaveStatus::kOk);
  s.rebase(s.theta + 3 * kPi);
  EXPECT_NEAR(s.theta, 0.4 + 3 * kPi, 1e-12);
  EXPECT_NEAR(wrapToPi(s.phase - (0.3 + kPi)), 0.0, 1e-12);
  const WaveParameters back{s.amplitude, s.quadrature, s.theta, s.phase};
  EXPECT_LT((idealChannels(back) - idealChannels(w)).norm(), 1e-12);
}

TEST(WaveEstimatorTest, DegenerateAndBadInputNeverGiveNaN) {
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  WaveState s;
  s.theta = 123.0;  // must stay untouched on rejection
  EXPECT_EQ(estimateWave(ChannelVector(nan, 0, 1, 0), WaveLimits{}, &s), WaveStatus::kNonFinite);
  EXPECT_EQ(estimateWave(ChannelVector(inf, 0, 1, 0), WaveLimits{}, &s), WaveStatus::kNonFinite);
  // Finite but so large that the energy overflows: out of range, not "non-finite".
  EXPECT_EQ(estimateWave(ChannelVector(1e200, 1e200, 0, 0), WaveLimits{}, &s), WaveStatus::kAmplitudeOutOfRange);
  EXPECT_EQ(estimateWave(idealChannels({1e300, 1e298, 0.3, 0.1}), WaveLimits{}, &s), WaveStatus::kAmplitudeOutOfRange);
  EXPECT_EQ(estimateWave(ChannelVector(-1e300, 0, 1e300, 0), WaveLimits{}, &s), WaveStatus::kAmplitudeOutOfRange);
  EXPECT_EQ(estimateWave(ChannelVector(1e300, inf, 0, 0), WaveLimits{}, &s), WaveStatus::kNonFinite);
  EXPECT_EQ(estimateWave(ChannelVector::Zero(), WaveLimits{}, &s), WaveStatus::kNoSignal);
  // A = B: a travelling wave, theta undefined.
  EXPECT_EQ(estimateWave(idealChannels({1.0, 1.0, 0.3, 0.1}), WaveLimits{}, &s), WaveStatus::kDegenerate);
  EXPECT_EQ(estimateWave(idealChannels({1.0, 0.9, 0.3, 0.1}), WaveLimits{}, &s), WaveStatus::kDegenerate);
  WaveLimits tight;
  tight.max_amplitude = 2.0;
  EXPECT_EQ(estimateWave(idealChannels({5.0, 0.0, 0.3, 0.1}), tight, &s), WaveStatus::kAmplitudeOutOfRange);
  EXPECT_EQ(s.theta, 123.0);
  // Sign flip of every channel is tau + pi: same angle.
  ASSERT_EQ(estimateWave(-idealChannels({1.0, 0.0, 0.3, 0.1}), WaveLimits{}, &s), WaveStatus::kOk);
  EXPECT_NEAR(s.theta, 0.3, 1e-12);
}

// The general path (amplitudes beyond the fast arithmetic's range) is the fast one on amplitudes
// scaled by a power of two: the angles are the same and the amplitudes scale.
TEST(WaveEstimatorTest, HugeAndTinyAmplitudesGiveTheSameWaveScaled) {
  WaveLimits wide;
  wide.min_energy = 0.0;
  wide.min_amplitude = 0.0;
  wide.max_amplitude = 1e300;
  const ChannelVector z = idealChannels({1.0, 0.15, 0.7, -2.1});
  WaveState reference;
  ASSERT_EQ(estimateWave(z, wide, &reference), WaveStatus::kOk);
  for (int exponent : {-530, -400, -300, 260, 400, 500}) {
    WaveState s;
    ASSERT_EQ(estimateWave(std::ldexp(1.0, exponent) * z, wide, &s), WaveStatus::kOk) << exponent;
    EXPECT_EQ(s.theta, reference.theta) << exponent;
    EXPECT_EQ(s.phase, reference.phase) << exponent;
    EXPECT_EQ(s.cos_theta, reference.cos_theta) << exponent;
    EXPECT_NEAR(s.amplitude, std::ldexp(reference.amplitude, exponent), 1e-15 * std::ldexp(1.0, exponent)) << exponent;
    EXPECT_NEAR(s.quadrature, std::ldexp(reference.quadrature, exponent), 1e-15 * std::ldexp(1.0, exponent))
        << exponent;
  }
}

// 20000 channel samples, one in two odd in some way: NaN, infinite, overflowing, below the floor,
// degenerate, out of range, zero, random bits.
std::vector<ChannelVector> oddAndOrdinarySamples() {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  std::vector<ChannelVector> z;
  for (int i = 0; i < 20000; ++i) {
    const WaveParameters w{0.01 + 3.0 * std::abs(u(rng)), 0.5 * u(rng), 4.0 * u(rng), kPi * u(rng)};
    ChannelVector sample = idealChannels(w) + 1e-3 * ChannelVector(u(rng), u(rng), u(rng), u(rng));
    switch (rng() % 16) {  // one sample in two odd in some way
      case 0:
        sample[rng() % 4] = nan;
        break;
      case 1:
        sample[rng() % 4] = -inf;
        break;
      case 2:
        sample *= 1e200;  // energy overflows
        break;
      case 3:
        sample *= 1e-160;  // below the energy floor
        break;
      case 4:
        sample = idealChannels({1.0, 0.95, w.theta, w.phase});  // degenerate
        break;
      case 5:
        sample *= 1e100;  // general path, then out of range
        break;
      case 6:
        sample = ChannelVector::Zero();
        break;
      case 7: {  // random bit patterns
        for (int k = 0; k < 4; ++k) {
          const std::uint64_t bits = rng();
          std::memcpy(&sample[k], &bits, sizeof bits);
        }
        break;
      }
      default:
        break;
    }
    z.push_back(sample);
  }
  return z;
}

// estimateWaves computes four samples per instruction; each must be bit for bit estimateWave's, with
// every kind of sample side by side in one group of lanes (the processor's batch path relies on it).
TEST(WaveEstimatorTest, BatchIsBitIdenticalToOneSampleAtATime) {
  const std::vector<ChannelVector> z = oddAndOrdinarySamples();
  WaveLimits limits;
  limits.max_amplitude = 2.5;  // some ordinary samples out of range too
  CorrectionMatrix none, some;
  some.p = {1e-3, -2e-3, 3e-3, 0.5e-3};
  for (const CorrectionMatrix& correction : {none, some}) {
    for (std::size_t n : {z.size(), std::size_t{7}, std::size_t{1}}) {
      std::vector<WaveState> batch(n);
      std::vector<WaveStatus> statuses(n);
      estimateWaves(z.data(), sizeof(ChannelVector), correction, n, limits, batch.data(), sizeof(WaveState),
                    statuses.data());
      int accepted = 0;
      for (std::size_t i = 0; i < n; ++i) {
        WaveState one;
        const WaveStatus status = estimateWave(correction.apply(z[i]), limits, &one);
        ASSERT_EQ(statuses[i], status) << i;
        if (status != WaveStatus::kOk) continue;
        ++accepted;
        ASSERT_TRUE(sameWaveBits(batch[i], one)) << i;
      }
      if (n == z.size()) {
        EXPECT_GT(accepted, 8000);
        EXPECT_LT(accepted, 16000);
      }
    }
  }
}

// Channels and states as fields of larger records: the same states, the fields around the states
// untouched.
TEST(WaveEstimatorTest, BatchReadsAndWritesFieldsOfLargerRecords) {
  const std::vector<ChannelVector> z = oddAndOrdinarySamples();
  WaveLimits limits;
  limits.max_amplitude = 2.5;
  CorrectionMatrix some;
  some.p = {1e-3, -2e-3, 3e-3, 0.5e-3};
  struct Record {
    double before = -1.0;
    WaveState wave;
    char after[13] = "untouched";
  };
  struct Sample {
    double stamp;
    ChannelVector z;
  };
  std::vector<Sample> samples(z.size());
  for (std::size_t i = 0; i < z.size(); ++i) samples[i] = {1.0 * i, z[i]};
  std::vector<Record> records(z.size());
  std::vector<WaveState> packed(z.size());
  std::vector<WaveStatus> record_statuses(z.size()), packed_statuses(z.size());
  estimateWaves(&samples[0].z, sizeof(Sample), some, z.size(), limits, &records[0].wave, sizeof(Record),
                record_statuses.data());
  estimateWaves(z.data(), sizeof(ChannelVector), some, z.size(), limits, packed.data(), sizeof(WaveState),
                packed_statuses.data());
  for (std::size_t i = 0; i < z.size(); ++i) {
    ASSERT_EQ(record_statuses[i], packed_statuses[i]) << i;
    ASSERT_EQ(records[i].before, -1.0) << i;
    ASSERT_STREQ(records[i].after, "untouched") << i;
    if (packed_statuses[i] == WaveStatus::kOk) {
      ASSERT_TRUE(sameWaveBits(records[i].wave, packed[i])) << i;
    }
  }
}

TEST(ThetaUnwrapperTest, FollowsSeveralRevolutionsBothWays) {
  ThetaUnwrapper unwrapper;
  double truth = 0.2;
  for (int i = 0; i < 4000; ++i) {
    truth += (i < 2000 ? 0.01 : -0.013);
    WaveState s;
    ASSERT_EQ(estimateWave(idealChannels({1.0, 0.02, truth, 0.5}), WaveLimits{}, &s), WaveStatus::kOk);
    EXPECT_NEAR(unwrapper.unwrap(s.theta), truth, 1e-10) << i;
  }
  EXPECT_GT(std::abs(truth - 0.2), 5.0);  // many half-turns crossed
  unwrapper.reset();
  EXPECT_FALSE(unwrapper.initialized());
}

// Steps up to just under a quarter turn of the wave (pi/2 of theta) either way are taken the short
// way, thousands of half turns away from the start too.
TEST(ThetaUnwrapperTest, TakesTheShortWayForStepsUpToJustUnderPiOverTwo) {
  for (double step : {0.3, 0.49 * kPi, (0.5 - 1e-9) * kPi}) {
    for (double sign : {1.0, -1.0}) {
      ThetaUnwrapper unwrapper;
      double truth = 0.1;
      for (int i = 0; i < 5000; ++i) {
        const double principal = truth - kPi * std::round(truth / kPi);
        ASSERT_NEAR(unwrapper.unwrap(principal), truth, 1e-9 * (1.0 + std::abs(truth))) << step << " " << i;
        truth += sign * step;
      }
    }
  }
}

TEST(WaveEstimatorTest, CarriesTheUnitVectorOfThetaThroughRebase) {
  // cos/sin of theta come from half-angle identities (no trigonometry) and follow the unwrapping.
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> angle(-kPi, kPi), turns(-40.0, 40.0);
  for (int i = 0; i < 500; ++i) {
    const double theta = angle(rng);
    WaveState w;
    ASSERT_EQ(estimateWave(idealChannels({1.0, 0.02, theta, 0.3}), WaveLimits(), &w), WaveStatus::kOk);
    EXPECT_NEAR(w.cos_theta, std::cos(w.theta), 1e-14);
    EXPECT_NEAR(w.sin_theta, std::sin(w.theta), 1e-14);
    const double continuous = w.theta + kPi * std::round(turns(rng));
    w.rebase(continuous);
    EXPECT_NEAR(w.cos_theta, std::cos(continuous), 1e-12);
    EXPECT_NEAR(w.sin_theta, std::sin(continuous), 1e-12);
  }
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
