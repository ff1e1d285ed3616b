// Demodulation of the eight-pickoff channels: the exact closed form (docs/math.md, 'Channel amplitudes').
#include "hrg_gyro/core/signal/synchronous_demodulator.h"

#include <gtest/gtest.h>

#include <random>

#include "hrg_gyro/core/common/units.h"
#include "hrg_gyro/core/model/wave_parameters.h"
#include "hrg_gyro/core/signal/pickoff_array.h"
#include "hrg_gyro/core/signal/wave_estimator.h"
#include "hrg_gyro/core/simulation/signal_synthesizer.h"

namespace hrg_gyro {
namespace core {
namespace {

WaveParameters randomWave(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  WaveParameters w;
  w.amplitude = 0.5 + 0.5 * std::abs(u(rng));
  w.quadrature = 0.2 * u(rng);
  w.theta = kPi * u(rng);
  w.phase = kPi * u(rng);
  return w;
}

// Demodulate by the textbook route: the eight sensor outputs from the deflection formula at each
// sample, channels c and s, then the discrete integrals.
ChannelVector demodulateFromSensors(const PickoffArray& pickoffs, const WaveParameters& w, int n) {
  SynchronousDemodulator demod(n);
  std::vector<double> c(n), s(n);
  for (int j = 0; j < n; ++j)
    PickoffArray::formChannels(pickoffs.sensorOutputs(w, demod.carrierPhase(j)), &c[j], &s[j]);
  return demod.demodulate(c.data(), s.data());
}

TEST(SynchronousDemodulatorTest, MatchesExactClosedFormForRandomWaves) {
  std::mt19937_64 rng(42);
  const PickoffArray ideal{PickoffDefects{}};
  for (int trial = 0; trial < 200; ++trial) {
    const WaveParameters w = randomWave(rng);
    const ChannelVector z = demodulateFromSensors(ideal, w, 8 + trial % 40);
    const ChannelVector expected = idealChannels(w);
    for (int i = 0; i < 4; ++i) EXPECT_NEAR(z[i], expected[i], 1e-14) << "channel " << i << " trial " << trial;
  }
}

TEST(SynchronousDemodulatorTest, PaperPrintedSetIsWrongForGenericWaves) {
  // The paper prints Ac = A cos th cos tau + B sin th sin tau, ..., Bs = A cos th sin tau + B sin th cos tau.
  const WaveParameters w{1.0, 0.1, 0.7, 0.4};
  const ChannelVector z = demodulateFromSensors(PickoffArray{PickoffDefects{}}, w, 32);
  const double ct = std::cos(w.theta), st = std::sin(w.theta), cp = std::cos(w.phase), sp = std::sin(w.phase);
  const double paper_bs = w.amplitude * ct * sp + w.quadrature * st * cp;
  const double paper_ac = w.amplitude * ct * cp + w.quadrature * st * sp;
  EXPECT_GT(std::abs(z[kBs] - paper_bs), 0.3);
  EXPECT_GT(std::abs(z[kAc] - paper_ac), 0.02);
}

TEST(SynchronousDemodulatorTest, FastChannelPathEqualsSensorFormula) {
  std::mt19937_64 rng(7);
  PickoffDefects d;
  for (int i = 0; i < kPickoffCount; ++i) {
    d.misplacement[i] = 1e-3 * (i - 3.5);
    d.gain_error[i] = 2e-3 * ((i * 5) % 7 - 3);
  }
  d.gap = 12.0;
  const PickoffArray pickoffs(d);
  for (int trial = 0; trial < 50; ++trial) {
    const WaveParameters w = randomWave(rng);
    const double phase = 0.37 * trial;
    double c_ref, s_ref, c, s;
    PickoffArray::formChannels(pickoffs.sensorOutputs(w, phase), &c_ref, &s_ref);
    const double u = w.amplitude * std::cos(phase + w.phase), v = w.quadrature * std::sin(phase + w.phase);
    pickoffs.channels(u * std::cos(w.theta) - v * std::sin(w.theta), u * std::sin(w.theta) + v * std::cos(w.theta), &c,
                      &s);
    EXPECT_NEAR(c, c_ref, 1e-15);
    EXPECT_NEAR(s, s_ref, 1e-15);
  }
}

TEST(SynchronousDemodulatorTest, SynthesizerEqualsSensorRouteWithoutNoise) {
  PickoffDefects d;
  d.misplacement[3] = 2e-3;
  d.gain_error[0] = -1e-3;
  d.gap = 10.0;
  SignalSynthesizer synth(d, 32, 1);
  const WaveParameters w{1.0, 0.03, 1.1, -0.6};
  const ChannelVector a = synth.period(w, w.theta);
  const ChannelVector b = demodulateFromSensors(PickoffArray(d), w, 32);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(SynchronousDemodulatorTest, FourSamplesPerPeriodAliasTheNonlinearityEightDoNot) {
  PickoffDefects d;
  d.gap = 5.0;  // A/d0 = 0.2: strong third harmonic in time
  const WaveParameters w{1.0, 0.0, 0.5, 0.2};
  const ChannelVector reference = demodulateFromSensors(PickoffArray(d), w, 256);
  const double err4 = (demodulateFromSensors(PickoffArray(d), w, 4) - reference).norm();
  const double err8 = (demodulateFromSensors(PickoffArray(d), w, 8) - reference).norm();
  EXPECT_GT(err4, 1e-3);  // the 3rd carrier harmonic folds onto the fundamental
  EXPECT_LT(err8, 1e-5);  // only the 7th/9th fold: O(a^6)
}

TEST(SynchronousDemodulatorTest, RejectsTooFewSamples) {
  EXPECT_THROW(SynchronousDemodulator(2), std::invalid_argument);
  EXPECT_NO_THROW(SynchronousDemodulator(3));
}

TEST(SynchronousDemodulatorTest, NoiseGivesTheStatedAngleNoise) {
  // Sensor noise sigma per sample -> channel-amplitude noise sigma/sqrt(2N) -> angle noise sigma/(A sqrt(2N)).
  PickoffDefects d;
  d.noise = 2e-3;
  const int n = 32;
  SignalSynthesizer synth(d, n, 99);
  const WaveParameters w{1.0, 0.0, 0.3, 0.0};
  const ChannelVector ideal = idealChannels(w);
  double sum2[4] = {0, 0, 0, 0}, theta2 = 0.0;
  const int periods = 20000;
  for (int k = 0; k < periods; ++k) {
    const ChannelVector z = synth.period(w, w.theta);
    const ChannelVector e = z - ideal;
    for (int i = 0; i < 4; ++i) sum2[i] += e[i] * e[i];
    WaveState state;
    ASSERT_EQ(estimateWave(z, WaveLimits{}, &state), WaveStatus::kOk);
    theta2 += (state.theta - w.theta) * (state.theta - w.theta);
  }
  const double expected = d.noise / std::sqrt(2.0 * n);
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(std::sqrt(sum2[i] / periods), expected, 0.03 * expected) << i;
  EXPECT_NEAR(std::sqrt(theta2 / periods), expected / w.amplitude, 0.03 * expected);
}

TEST(SynchronousDemodulatorTest, ChannelNoiseIsTheSumOfFourSensorNoises) {
  // c = (d0 - d2 + d4 - d6)/4 with independent sensor noises of sigma has sigma/2.
  PickoffDefects d;
  d.noise = 1e-3;
  EXPECT_DOUBLE_EQ(PickoffArray(d).channelNoiseSigma(), 0.5e-3);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal(0.0, d.noise);
  double sum2 = 0.0;
  const int trials = 200000;
  for (int k = 0; k < trials; ++k) {
    std::array<double, kPickoffCount> noise;
    for (double& x : noise) x = normal(rng);
    double c, s;
    PickoffArray::formChannels(noise, &c, &s);
    sum2 += c * c;
  }
  EXPECT_NEAR(std::sqrt(sum2 / trials), 0.5e-3, 0.01 * 0.5e-3);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
