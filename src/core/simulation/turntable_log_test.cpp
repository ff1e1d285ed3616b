// The turntable side of a real session, generated: drive ripple in the true motion, what the
// controller logs (encoder noise and counts, a differenced rate, its own log rate), lost messages,
// gaps and glitched records, each checked against what was asked and reproducible by seed.
#include "hrg_gyro/core/simulation/turntable_log.h"

#include <gtest/gtest.h>

#include <cmath>

#include "hrg_gyro/core/simulation/gyro_simulator.h"

namespace hrg_gyro {
namespace core {
namespace {

YamlField parse(const std::string& text) { return YamlField(YAML::Load(text), ""); }

/// A short session: rest, a ramp and a plateau at `rate` rad/s.
SimulationConfig plateauScenario(double rate, double duration) {
  SimulationConfig c;
  c.resonator.periods_per_output = 25;  // 200 Hz
  c.resonator.samples_per_period = 8;
  c.profile.append(1.0, 0.0, 0.0, "rest");
  c.profile.append(rate / 0.5, 0.0, 0.5, "ramp");
  c.profile.append(duration, rate, 0.0, "plateau");
  return c;
}

/// Amplitude of the sine of frequency f (Hz) that best fits y(t) (least squares on sin and cos).
double fittedAmplitude(const std::vector<double>& t, const std::vector<double>& y, double f) {
  double ss = 0, cc = 0, sc = 0, ys = 0, yc = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    const double s = std::sin(kTwoPi * f * t[i]), c = std::cos(kTwoPi * f * t[i]);
    ss += s * s, cc += c * c, sc += s * c, ys += y[i] * s, yc += y[i] * c;
  }
  const double det = ss * cc - sc * sc;
  const double a = (ys * cc - yc * sc) / det, b = (yc * ss - ys * sc) / det;
  return std::hypot(a, b);
}

TEST(TurntableLogTest, RippleIsInTheTrueRateAndItsAngleIsTheExactIntegral) {
  TurntableProfile p;
  p.append(2.0, 0.0, 0.25, "ramp");
  p.append(40.0, 0.5, 0.0, "plateau");
  p.append(2.0, 0.5, -0.25, "ramp");
  p.setRipple(0.002, 0.37, 0.4);
  // The rate is the commanded one times 1 + a sin(2 pi f t + phi); the angle is its integral
  // (checked by central differences across every piece boundary).
  const double h = 1e-4;
  for (double t = 0.05; t < 43.9; t += 0.0973) {
    double a1, a2, rate, ignored;
    p.evaluate(t, &ignored, &rate);
    p.evaluate(t - h, &a1, &ignored);
    p.evaluate(t + h, &a2, &ignored);
    const double commanded = t < 2.0 ? 0.25 * t : t < 42.0 ? 0.5 : 0.5 - 0.25 * (t - 42.0);
    EXPECT_NEAR(rate, commanded * (1.0 + 0.002 * std::sin(kTwoPi * 0.37 * t + 0.4)), 1e-12) << t;
    EXPECT_NEAR((a2 - a1) / (2 * h), rate, 1e-9) << t;
  }
  // Comes to rest: no ripple at or after the end.
  double angle, rate;
  p.evaluate(50.0, &angle, &rate);
  EXPECT_EQ(rate, 0.0);
}

TEST(TurntableLogTest, SimulatedTruthAndLogCarryTheAskedRipple) {
  SimulationConfig c = plateauScenario(0.5, 30.0);
  c.ripple = {0.002, 0.37, 0.0};
  GyroSimulator sim(c);
  SimulationSample s;
  std::vector<double> t, relative, logged;
  while (sim.next(&s)) {
    if (*s.truth.segment != "plateau") continue;
    t.push_back(toSeconds(s.stamp) - c.start_time);
    relative.push_back(s.truth.table_rate / 0.5 - 1.0);
    ASSERT_EQ(s.turntable.size(), 1u);
    logged.push_back(s.turntable[0].rate / 0.5 - 1.0);
    // The logged angle is the true one (default log): it holds the ripple's angle.
    EXPECT_EQ(s.turntable[0].angle, s.truth.table_angle);
  }
  ASSERT_GT(t.size(), 5000u);
  const double amplitude = fittedAmplitude(t, relative, 0.37);
  std::printf("[ measured ] ripple in the true rate: %.6g of the rate at 0.37 Hz (asked 0.002)\n", amplitude);
  EXPECT_NEAR(amplitude, 0.002, 1e-9);
  EXPECT_NEAR(fittedAmplitude(t, logged, 0.37), 0.002, 1e-9);
  // Nothing else: the relative rate is exactly the asked sine (t is the profile's time).
  for (std::size_t i = 0; i < t.size(); ++i) {
    ASSERT_NEAR(relative[i], 0.002 * std::sin(kTwoPi * 0.37 * t[i]), 1e-12) << t[i];
  }
}

TEST(TurntableLogTest, EncoderNoiseAndQuantisationOfTheLoggedAngle) {
  TurntableLogConfig noisy;
  noisy.angle_noise = 2e-6;
  TurntableLogConfig counted;
  counted.angle_resolution = 1e-6;
  TurntableLogger a(noisy, 3), b(counted, 3);
  std::vector<TurntableLogRecord> ra, rb;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const double t = k * 0.01, angle = 0.0513717 * t + 0.3;
    a.log(t, toNanoseconds(1.0 + t), angle, 0.05, &ra);
    b.log(t, toNanoseconds(1.0 + t), angle, 0.05, &rb);
  }
  ASSERT_EQ(ra.size(), static_cast<std::size_t>(n));
  double sum2 = 0.0, worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double angle = 0.0513717 * (k * 0.01) + 0.3;
    sum2 += std::pow(ra[k].angle - angle, 2);
    EXPECT_EQ(ra[k].rate, 0.05);  // the drive's rate, untouched by the encoder
    const double counts = rb[k].angle / 1e-6;
    EXPECT_NEAR(counts, std::round(counts), 1e-6);
    worst = std::max(worst, std::abs(rb[k].angle - angle));
  }
  const double std_measured = std::sqrt(sum2 / n);
  std::printf("[ measured ] logged angle noise std %.4g rad (asked 2e-6); largest quantisation error %.4g rad\n",
              std_measured, worst);
  EXPECT_NEAR(std_measured, 2e-6, 2e-6 * 5 / std::sqrt(2.0 * n));
  EXPECT_LE(worst, 0.5e-6 + 1e-12);
  EXPECT_GT(worst, 0.45e-6);  // the counts are really 1e-6 apart
}

TEST(TurntableLogTest, DifferencedRateIsTheLoggedAngleDifferencedAtTheLogRate) {
  SimulationConfig c = plateauScenario(0.05, 5.0);
  c.turntable_log.rate = 100.0;
  c.turntable_log.angle_noise = 2e-6;
  c.turntable_log.angle_resolution = 1e-7;
  c.turntable_log.logged_rate = LoggedRate::kDifferencedAngle;
  GyroSimulator sim(c);
  SimulationSample s;
  std::vector<TurntableLogRecord> records;
  while (sim.next(&s)) {
    for (const TurntableLogRecord& r : s.turntable) {
      EXPECT_LE(r.stamp, s.stamp);  // logged no later than the sample that carries it
      records.push_back(r);
    }
  }
  // One record every 10 ms from the start, stamped at its own time.
  ASSERT_EQ(records.size(), static_cast<std::size_t>(std::floor(sim.elapsed() * 100.0 - 0.5)) + 1);
  double scatter = 0.0;
  int on_plateau = 0;
  for (std::size_t k = 0; k < records.size(); ++k) {
    EXPECT_EQ(records[k].stamp, toNanoseconds(c.start_time + k / 100.0));
    if (k == 0) continue;
    EXPECT_NEAR(records[k].rate, (records[k].angle - records[k - 1].angle) * 100.0, 1e-9) << k;
    if (records[k].time > 1.2 + 0.1) {
      scatter += std::pow(records[k].rate - 0.05, 2);
      ++on_plateau;
    }
  }
  // Two independent angle errors of 2e-6 rad over 10 ms: sqrt(2) 2e-4 rad/s of rate scatter.
  const double std_rate = std::sqrt(scatter / on_plateau);
  std::printf("[ measured ] differenced rate scatter %.4g rad/s on the 0.05 rad/s plateau (%.2f %%)\n", std_rate,
              100.0 * std_rate / 0.05);
  EXPECT_NEAR(std_rate, std::sqrt(2.0) * 2e-4, 0.1 * std::sqrt(2.0) * 2e-4);
}

TEST(TurntableLogTest, DropsAndGapsAreCountedAndReproducibleBySeed) {
  DeliveryConfig d;
  d.drop_probability = 0.01;
  d.gaps = {{100.0, 5.0}};
  auto count = [&](std::uint64_t seed, std::vector<int>* lost) {
    StreamDelivery delivery(d, seed);
    int in_gap_delivered = 0;
    for (int k = 0; k < 100000; ++k) {
      const double t = k * 0.002;
      const bool ok = delivery.delivered(t);
      if (!ok) lost->push_back(k);
      if (ok && t >= 100.0 && t < 105.0) ++in_gap_delivered;
    }
    return in_gap_delivered;
  };
  std::vector<int> lost1, lost2, lost3;
  EXPECT_EQ(count(5, &lost1), 0);
  count(5, &lost2);
  count(6, &lost3);
  EXPECT_EQ(lost1, lost2);
  EXPECT_NE(lost1, lost3);
  // 2500 messages in the gap; of the other 97500 about 1 % are dropped (5 sigma = 156).
  const double random_drops = static_cast<double>(lost1.size()) - 2500.0;
  std::printf("[ measured ] %zu of 100000 messages lost (2500 in the gap, %.0f dropped at random, 975 expected)\n",
              lost1.size(), random_drops);
  EXPECT_NEAR(random_drops, 975.0, 156.0);
}

TEST(TurntableLogTest, GlitchedRecordsOfEachKindByTheirRateAndSeed) {
  TurntableLogConfig c;
  c.glitches.per_record = {1e-3, 2e-3, 1e-3, 1e-3, 3e-3};
  auto run = [&](std::uint64_t seed, std::vector<TurntableLogRecord>* out) {
    TurntableLogger logger(c, seed);
    for (int k = 0; k < 200000; ++k) {
      const double t = k * 0.01;
      logger.log(t, toNanoseconds(1.0 + t), 0.05 * t, 0.05, out);
    }
    return logger.counters();
  };
  std::vector<TurntableLogRecord> r1, r2;
  const TurntableLogCounters a = run(11, &r1), b = run(11, &r2);
  EXPECT_EQ(a.glitches, b.glitches);
  ASSERT_EQ(r1.size(), 200000u);
  for (int k = 0; k < kTurntableGlitchKinds; ++k) {
    const double expected = 200000 * c.glitches.per_record[k];
    std::printf("[ measured ] glitch kind %d: %llu records (%.0f expected)\n", k,
                static_cast<unsigned long long>(a.glitches[k]), expected);
    EXPECT_NEAR(static_cast<double>(a.glitches[k]), expected, 5 * std::sqrt(expected)) << k;
  }
  std::array<std::uint64_t, kTurntableGlitchKinds> seen{};
  for (std::size_t k = 0; k < r1.size(); ++k) {
    const TurntableLogRecord& r = r1[k];
    const Nanoseconds true_stamp = toNanoseconds(1.0 + k * 0.01);
    switch (r.glitch) {
      case TurntableGlitch::kNanRate:
        EXPECT_TRUE(std::isnan(r.rate));
        break;
      case TurntableGlitch::kAbsurdRate:
        EXPECT_EQ(r.rate, kAbsurdTableRate);
        break;
      case TurntableGlitch::kInfiniteAngle:
        EXPECT_TRUE(std::isinf(r.angle));
        break;
      case TurntableGlitch::kZeroStamp:
        EXPECT_EQ(r.stamp, 0);
        break;
      case TurntableGlitch::kBackwardStamp:
        EXPECT_EQ(r.stamp, true_stamp - toNanoseconds(kBackwardStampJump));
        break;
      case TurntableGlitch::kNone:
        EXPECT_EQ(r.stamp, true_stamp);
        EXPECT_EQ(r.rate, 0.05);
        continue;
    }
    ++seen[static_cast<int>(r.glitch)];
  }
  EXPECT_EQ(seen, a.glitches);
  for (std::size_t k = 0; k < r1.size(); ++k) EXPECT_EQ(r1[k].index, k);
}

TEST(TurntableLogTest, DefaultLogIsTheExactStateWithEverySample) {
  SimulationConfig c = plateauScenario(0.1, 2.0);
  c.channels.drop_probability = 0.0;
  GyroSimulator sim(c);
  SimulationSample s;
  while (sim.next(&s)) {
    ASSERT_EQ(s.turntable.size(), 1u);
    EXPECT_TRUE(s.channels_delivered);
    EXPECT_EQ(s.turntable[0].stamp, s.stamp);
    EXPECT_EQ(s.turntable[0].angle, s.truth.table_angle);
    EXPECT_EQ(s.turntable[0].rate, s.truth.table_rate);
    EXPECT_EQ(s.turntable[0].index, s.index);  // the records' sequence is the samples'
  }
  EXPECT_EQ(sim.turntableLogCounters().lost, 0u);
}

TEST(TurntableLogTest, LostChannelSamplesAreFlaggedAndStillCounted) {
  SimulationConfig c = plateauScenario(0.1, 4.0);
  c.channels.drop_probability = 0.05;
  c.channels.gaps = {{2.0, 0.5}};
  GyroSimulator sim(c);
  SimulationSample s;
  std::uint64_t lost = 0, samples = 0, in_gap = 0;
  while (sim.next(&s)) {
    EXPECT_EQ(s.index, samples++);
    const double t = toSeconds(s.stamp) - c.start_time;
    if (!s.channels_delivered) ++lost;
    if (t >= 2.0 && t < 2.5) {
      EXPECT_FALSE(s.channels_delivered);
      ++in_gap;
    }
  }
  EXPECT_EQ(in_gap, 100u);
  const double expected = 0.05 * (samples - in_gap);
  std::printf("[ measured ] %llu of %llu channel samples lost (%llu in the gap, %.0f drops expected)\n",
              static_cast<unsigned long long>(lost), static_cast<unsigned long long>(samples),
              static_cast<unsigned long long>(in_gap), expected);
  EXPECT_NEAR(static_cast<double>(lost - in_gap), expected, 5 * std::sqrt(expected));
}

TEST(TurntableLogTest, ScenarioKeysAreParsedAndBadOnesNamed) {
  const std::string base = "turntable:\n  profile:\n    - {type: rate, rate: 0.1, duration: 2}\n";
  const SimulationConfig c = SimulationConfig::parse(
      parse(base +
            "  ripple: {amplitude: 0.002, frequency: 0.37}\n"
            "  log: {rate: 100, angle_noise: 2.0e-6, angle_resolution: 1.0e-7, logged_rate: differenced_angle,\n"
            "        drop_probability: 0.001, gaps: [[10, 2]], glitches: {nan_rate: 0.001, backward_stamp: 0.002}}\n"
            "channels: {drop_probability: 0.01, gaps: [[3, 1], [5, 0.5]]}\n"));
  EXPECT_EQ(c.ripple.amplitude, 0.002);
  EXPECT_EQ(c.ripple.frequency, 0.37);
  EXPECT_EQ(c.turntable_log.rate, 100.0);
  EXPECT_EQ(c.turntable_log.angle_noise, 2e-6);
  EXPECT_EQ(c.turntable_log.angle_resolution, 1e-7);
  EXPECT_EQ(c.turntable_log.logged_rate, LoggedRate::kDifferencedAngle);
  EXPECT_EQ(c.turntable_log.delivery.drop_probability, 0.001);
  ASSERT_EQ(c.turntable_log.delivery.gaps.size(), 1u);
  EXPECT_EQ(c.turntable_log.glitches.per_record[static_cast<int>(TurntableGlitch::kNanRate)], 0.001);
  EXPECT_EQ(c.turntable_log.glitches.per_record[static_cast<int>(TurntableGlitch::kBackwardStamp)], 0.002);
  EXPECT_EQ(c.channels.drop_probability, 0.01);
  EXPECT_EQ(c.channels.gaps.size(), 2u);

  auto key = [&](const std::string& extra) {
    try {
      SimulationConfig::parse(parse(base + extra));
    } catch (const ConfigError& e) {
      return e.key();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(key("  ripple: {amplitude: -0.1, frequency: 1}\n"), "turntable.ripple.amplitude");
  EXPECT_EQ(key("  ripple: {amplitude: 0.01}\n"), "turntable.ripple.frequency");
  EXPECT_EQ(key("  ripple: {amplitude: 0.01, frequency: 1, phse: 0}\n"), "turntable.ripple.phse");
  EXPECT_EQ(key("  log: {rate: -1}\n"), "turntable.log.rate");
  EXPECT_EQ(key("  log: {angle_noise: -1.0e-6}\n"), "turntable.log.angle_noise");
  EXPECT_EQ(key("  log: {angle_resolution: .nan}\n"), "turntable.log.angle_resolution");
  EXPECT_EQ(key("  log: {logged_rate: encoder}\n"), "turntable.log.logged_rate");
  EXPECT_EQ(key("  log: {drop_probability: 1.0}\n"), "turntable.log.drop_probability");
  EXPECT_EQ(key("  log: {gaps: [[1, 0]]}\n"), "turntable.log.gaps[0]");
  EXPECT_EQ(key("  log: {glitches: {nan_rate: 2}}\n"), "turntable.log.glitches.nan_rate");
  EXPECT_EQ(key("  log: {glitches: {nan_rate: 0.6, zero_stamp: 0.6}}\n"), "turntable.log.glitches");
  EXPECT_EQ(key("  log: {glitches: {nan: 0.1}}\n"), "turntable.log.glitches.nan");
  EXPECT_EQ(key("channels: {drop_probability: -0.1}\n"), "channels.drop_probability");
  EXPECT_EQ(key("channels: {gaps: [[-1, 1]]}\n"), "channels.gaps[0]");
  EXPECT_EQ(key("channels: {gap: []}\n"), "channels.gap");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
