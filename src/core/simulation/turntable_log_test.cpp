// The turntable side of a real session, generated: drive ripple in the true motion, what the
// controller logs (encoder noise and counts, a differenced rate, its own log rate, its own clock),
// lost messages, gaps and glitched records, each checked against what was asked and reproducible by
// seed.
#include "hrg_gyro/core/simulation/turntable_log.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/testing/refusal.h"
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

TEST(TurntableLogTest, AStampGlitchMovesOneMessageOnly) {
  SimulationConfig c = plateauScenario(0.1, 4.0);
  c.channels.stamp_glitches = {{1.0, 1000.0}, {2.5, -100.0}};
  c.turntable_log.delivery.stamp_glitches = {{1.5, 100.0}};
  GyroSimulator sim(c);
  SimulationSample s;
  std::vector<Nanoseconds> moved_channels;
  std::vector<Nanoseconds> table_offsets;
  while (sim.next(&s)) {
    if (s.channels_stamp_offset != 0) moved_channels.push_back(s.channels_stamp_offset);
    for (const TurntableLogRecord& r : s.turntable) {
      if (r.stamp != s.stamp) table_offsets.push_back(r.stamp - s.stamp);
    }
  }
  ASSERT_EQ(moved_channels.size(), 2u);
  EXPECT_EQ(moved_channels[0], toNanoseconds(1000.0));
  EXPECT_EQ(moved_channels[1], toNanoseconds(-100.0));
  ASSERT_EQ(table_offsets.size(), 1u);
  EXPECT_EQ(table_offsets[0], toNanoseconds(100.0));
}

// Without jitter the controller's stamps are exact: the true time plus the offset, the rate error
// times the true time and every step taken at or before it (to the nanosecond the stamps round to).
TEST(TurntableLogTest, ClockOffsetRateErrorAndStepsMoveTheStamps) {
  SimulationConfig c = plateauScenario(0.1, 4.0);
  c.turntable_log.rate = 100.0;
  c.turntable_log.clock.offset = 0.05;
  c.turntable_log.clock.rate_error = 2e-5;
  c.turntable_log.clock.steps = {{2.0, 0.01}, {3.505, -0.02}};
  GyroSimulator sim(c);
  SimulationSample s;
  std::vector<TurntableLogRecord> records;
  while (sim.next(&s)) records.insert(records.end(), s.turntable.begin(), s.turntable.end());
  ASSERT_GT(records.size(), 500u);
  for (std::size_t k = 0; k < records.size(); ++k) {
    const TurntableLogRecord& r = records[k];
    EXPECT_EQ(r.index, k);
    EXPECT_EQ(r.time, k / 100.0);  // taken at the table's own rate, whatever its clock
    const double t = r.time;
    const double error = 0.05 + 2e-5 * t + (t >= 2.0 ? 0.01 : 0.0) + (t >= 3.505 ? -0.02 : 0.0);
    const double ns = static_cast<double>(r.stamp - toNanoseconds(c.start_time + t));
    ASSERT_NEAR(ns, 1e9 * error, 1.0) << k;  // each of the two roundings to whole ns is within 0.5
  }
  // The steps at the records where they fall: record 200 is taken at 2.0 s exactly, 351 first after 3.505 s.
  auto error = [&](std::size_t k) { return toSeconds(records[k].stamp - toNanoseconds(c.start_time + k / 100.0)); };
  EXPECT_NEAR(error(200) - error(199), 0.01 + 2e-5 * 0.01, 2e-9);
  EXPECT_NEAR(error(351) - error(350), -0.02 + 2e-5 * 0.01, 2e-9);
  EXPECT_NEAR(error(350) - error(349), 2e-5 * 0.01, 2e-9);
}

// One record with every sample (log rate 0): the stamp is the sample's plus the offset, exactly.
TEST(TurntableLogTest, ClockOffsetOfTheRecordsLoggedWithEverySample) {
  SimulationConfig c = plateauScenario(0.1, 2.0);
  c.turntable_log.clock.offset = -0.025;
  GyroSimulator sim(c);
  SimulationSample s;
  int n = 0;
  while (sim.next(&s)) {
    ASSERT_EQ(s.turntable.size(), 1u);
    EXPECT_EQ(s.turntable[0].stamp - s.stamp, toNanoseconds(-0.025));
    EXPECT_NEAR(s.turntable[0].time, toSeconds(s.stamp) - c.start_time, 1e-9);  // the sample's centre time
    EXPECT_EQ(s.turntable[0].angle, s.truth.table_angle);                       // the clock moves stamps only
    ++n;
  }
  EXPECT_GT(n, 600);
}

// White jitter: the stamps' deviations from the exact clock have the asked standard deviation. 100000
// records: the estimated std is within 5 sigma = 5 J / sqrt(2 N) (1.1 %) of J, the mean within 5 J / sqrt(N)
// (the rounding to whole ns adds 0.3 ns of spread, 3e-7 of J). The jitter draws from its own stream.
TEST(TurntableLogTest, ClockJitterHasTheAskedSpreadFromItsOwnStream) {
  TurntableLogConfig jittery;
  jittery.angle_noise = 2e-6;
  jittery.clock.offset = 0.03;
  jittery.clock.jitter = 1e-3;
  TurntableLogConfig steady = jittery;
  steady.clock.jitter = 0.0;
  TurntableLogger a(jittery, 5), b(steady, 5), again(jittery, 5), other(jittery, 6);
  std::vector<TurntableLogRecord> ra, rb, rc, ro;
  const int n = 100000;
  for (int k = 0; k < n; ++k) {
    const double t = k * 0.01;
    a.log(t, toNanoseconds(1.0 + t), 0.05 * t, 0.05, &ra);
    b.log(t, toNanoseconds(1.0 + t), 0.05 * t, 0.05, &rb);
    again.log(t, toNanoseconds(1.0 + t), 0.05 * t, 0.05, &rc);
    other.log(t, toNanoseconds(1.0 + t), 0.05 * t, 0.05, &ro);
  }
  double sum = 0.0, sum2 = 0.0;
  int out_of_order = 0;
  for (int k = 0; k < n; ++k) {
    const double deviation = toSeconds(ra[k].stamp - toNanoseconds(1.0 + k * 0.01)) - 0.03;
    sum += deviation;
    sum2 += deviation * deviation;
    EXPECT_EQ(ra[k].angle, rb[k].angle);  // the encoder's draws are the same with or without jitter
    EXPECT_EQ(rb[k].stamp, toNanoseconds(1.0 + k * 0.01) + toNanoseconds(0.03));
    EXPECT_EQ(ra[k].stamp, rc[k].stamp);
    if (k > 0 && ra[k].stamp < ra[k - 1].stamp) ++out_of_order;
  }
  const double mean = sum / n, std_measured = std::sqrt(sum2 / n - mean * mean);
  std::printf(
      "[ measured ] stamp jitter std %.5g s (asked 1e-3), mean %.3g s; %d of %d stamps before their "
      "predecessor's\n",
      std_measured, mean, out_of_order, n);
  EXPECT_NEAR(std_measured, 1e-3, 5 * 1e-3 / std::sqrt(2.0 * n));
  EXPECT_NEAR(mean, 0.0, 5 * 1e-3 / std::sqrt(n));
  EXPECT_EQ(out_of_order, 0);  // 10 ms apart, 1 ms of jitter: 7 sigma
  bool differs = false;
  for (int k = 0; k < n && !differs; ++k) differs = ra[k].stamp != ro[k].stamp;
  EXPECT_TRUE(differs);
}

// A table logged faster or slower than the gyro's 200 Hz, its stamps jittered by more than its record
// spacing at 1 kHz: the records come in the order they were taken (index and true time increasing),
// their stamps out of order where the jitter says so, and none is lost or repeated.
TEST(TurntableLogTest, TableClockAtHigherAndLowerLogRatesThanTheGyro) {
  for (const double log_rate : {1000.0, 50.0}) {
    SimulationConfig c = plateauScenario(0.1, 3.0);
    c.turntable_log.rate = log_rate;
    c.turntable_log.clock.offset = 0.1;
    c.turntable_log.clock.jitter = 2e-3;
    GyroSimulator sim(c);
    SimulationSample s;
    std::vector<TurntableLogRecord> records;
    while (sim.next(&s)) {
      for (const TurntableLogRecord& r : s.turntable) {
        EXPECT_LE(r.time, toSeconds(s.stamp) - c.start_time + 1e-12);  // carried by the sample after it
        records.push_back(r);
      }
    }
    // Every record up to the last sample's centre, half an output period before the end.
    const double last_centre = sim.elapsed() - 0.5 * c.outputPeriod();
    ASSERT_EQ(records.size(), static_cast<std::size_t>(std::floor(last_centre * log_rate + 1e-9)) + 1);
    int out_of_order = 0;
    for (std::size_t k = 1; k < records.size(); ++k) {
      EXPECT_EQ(records[k].index, records[k - 1].index + 1);
      EXPECT_GT(records[k].time, records[k - 1].time);
      if (records[k].stamp < records[k - 1].stamp) ++out_of_order;
    }
    std::printf(
        "[ measured ] table logged at %.0f Hz with 2 ms of jitter: %d of %zu stamps before their "
        "predecessor's\n",
        log_rate, out_of_order, records.size());
    // 1 ms apart, two jitters differing by 2.8 ms (std): P(N < -1 / 2.83) = 36 % of the stamps go
    // back (within 0.05: ~7 binomial sigmas of 0.0074, room for neighbours sharing a draw); 20 ms apart
    // is 7 sigmas: none.
    if (log_rate == 1000.0) {
      EXPECT_NEAR(static_cast<double>(out_of_order) / records.size(), 0.362, 0.05);
    } else {
      EXPECT_EQ(out_of_order, 0);
    }
  }
}

// The controller's count runs on whatever happens to the stamps: a lost record leaves a gap in it,
// nothing else does.
TEST(TurntableLogTest, RecordIndexIsContiguousExceptWhereRecordsWereLost) {
  SimulationConfig c = plateauScenario(0.1, 6.0);
  c.turntable_log.rate = 100.0;
  c.turntable_log.delivery.drop_probability = 0.05;
  c.turntable_log.delivery.gaps = {{3.0, 0.5}};
  c.turntable_log.clock.offset = 0.02;
  c.turntable_log.clock.jitter = 1e-3;
  c.turntable_log.clock.steps = {{4.0, -0.3}};
  GyroSimulator sim(c);
  SimulationSample s;
  std::vector<std::uint64_t> indices;
  while (sim.next(&s)) {
    for (const TurntableLogRecord& r : s.turntable) indices.push_back(r.index);
  }
  const TurntableLogCounters& counters = sim.turntableLogCounters();
  std::uint64_t skipped = indices.front();
  for (std::size_t k = 1; k < indices.size(); ++k) {
    ASSERT_GT(indices[k], indices[k - 1]);
    skipped += indices[k] - indices[k - 1] - 1;
  }
  skipped += counters.logged - 1 - indices.back();
  EXPECT_EQ(skipped, counters.lost);
  EXPECT_EQ(indices.size() + counters.lost, counters.logged);
  EXPECT_GE(counters.lost, 50u);  // the 0.5 s gap alone
}

// Stamp glitches spoil the controller's stamp: a zero stamp is 0, a backward one 0.5 s before the
// stamp its clock gave.
TEST(TurntableLogTest, StampGlitchesApplyAfterTheClock) {
  TurntableLogConfig c;
  c.clock.offset = 0.2;
  c.clock.rate_error = 1e-4;
  c.glitches.per_record[static_cast<int>(TurntableGlitch::kZeroStamp)] = 0.1;
  c.glitches.per_record[static_cast<int>(TurntableGlitch::kBackwardStamp)] = 0.1;
  TurntableLogger logger(c, 3);
  std::vector<TurntableLogRecord> records;
  for (int k = 0; k < 2000; ++k) logger.log(k * 0.01, toNanoseconds(1.0 + k * 0.01), 0.0, 0.0, &records);
  int zero = 0, backward = 0;
  for (const TurntableLogRecord& r : records) {
    const Nanoseconds clock = toNanoseconds(1.0 + r.time) + toNanoseconds(0.2 + 1e-4 * r.time);
    switch (r.glitch) {
      case TurntableGlitch::kZeroStamp:
        EXPECT_EQ(r.stamp, 0);
        ++zero;
        break;
      case TurntableGlitch::kBackwardStamp:
        EXPECT_EQ(r.stamp, clock - toNanoseconds(kBackwardStampJump));
        ++backward;
        break;
      default:
        EXPECT_EQ(r.stamp, clock);
    }
  }
  EXPECT_GT(zero, 100);
  EXPECT_GT(backward, 100);
}

TEST(TurntableLogTest, ScenarioKeysAreParsedAndBadOnesNamed) {
  const std::string base = "turntable:\n  profile:\n    - {type: rate, rate: 0.1, duration: 2}\n";
  const SimulationConfig c = SimulationConfig::parse(
      parse(base +
            "  ripple: {amplitude: 0.002, frequency: 0.37}\n"
            "  log: {rate: 100, angle_noise: 2.0e-6, angle_resolution: 1.0e-7, logged_rate: differenced_angle,\n"
            "        drop_probability: 0.001, gaps: [[10, 2]], glitches: {nan_rate: 0.001, backward_stamp: 0.002},\n"
            "        clock: {offset: 0.1, jitter: 0.002, rate_error: -3.0e-6, steps: [[600, 0.05], [900, -0.01]]}}\n"
            "channels: {drop_probability: 0.01, gaps: [[3, 1], [5, 0.5]], stamp_glitches: [[4, 1000], [6, -100]]}\n"));
  ASSERT_EQ(c.channels.stamp_glitches.size(), 2u);
  EXPECT_EQ(c.channels.stamp_glitches[1].offset, -100.0);
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
  const TableClockConfig& clock = c.turntable_log.clock;
  EXPECT_EQ(clock.offset, 0.1);
  EXPECT_EQ(clock.jitter, 0.002);
  EXPECT_EQ(clock.rate_error, -3e-6);
  ASSERT_EQ(clock.steps.size(), 2u);
  EXPECT_EQ(clock.steps[1].at, 900.0);
  EXPECT_EQ(clock.steps[1].size, -0.01);
  EXPECT_DOUBLE_EQ(clock.errorAt(700.0), 0.1 - 3e-6 * 700.0 + 0.05);
  EXPECT_FALSE(SimulationConfig::parse(parse(base)).turntable_log.clock.enabled());

  auto parse_section = [&](const std::string& extra) { SimulationConfig::parse(parse(base + extra)); };
  const std::vector<RefusalCase> refused = {
      {"  ripple: {amplitude: -0.1, frequency: 1}\n", "turntable.ripple.amplitude"},
      {"  ripple: {amplitude: 0.01}\n", "turntable.ripple.frequency"},
      {"  ripple: {amplitude: 0.01, frequency: 1, phse: 0}\n", "turntable.ripple.phse"},
      {"  log: {rate: -1}\n", "turntable.log.rate"},
      {"  log: {angle_noise: -1.0e-6}\n", "turntable.log.angle_noise"},
      {"  log: {angle_resolution: .nan}\n", "turntable.log.angle_resolution"},
      {"  log: {logged_rate: encoder}\n", "turntable.log.logged_rate"},
      {"  log: {drop_probability: 1.0}\n", "turntable.log.drop_probability"},
      {"  log: {gaps: [[1, 0]]}\n", "turntable.log.gaps[0]"},
      {"  log: {stamp_glitches: [[1, 0]]}\n", "turntable.log.stamp_glitches[0]"},
      {"  log: {stamp_glitches: [[2, 1], [1, 1]]}\n", "turntable.log.stamp_glitches[1]"},
      {"  log: {stamp_glitches: [[1, .inf]]}\n", "turntable.log.stamp_glitches[0][1]"},
      {"  log: {glitches: {nan_rate: 2}}\n", "turntable.log.glitches.nan_rate"},
      {"  log: {glitches: {nan_rate: 0.6, zero_stamp: 0.6}}\n", "turntable.log.glitches"},
      {"  log: {glitches: {nan: 0.1}}\n", "turntable.log.glitches.nan"},
      {"  log: {clock: {offset: .nan}}\n", "turntable.log.clock.offset"},
      {"  log: {clock: {jitter: -0.001}}\n", "turntable.log.clock.jitter"},
      {"  log: {clock: {jitter: .inf}}\n", "turntable.log.clock.jitter"},
      {"  log: {clock: {rate_error: 1.5}}\n", "turntable.log.clock.rate_error"},
      {"  log: {clock: {rate_error: .nan}}\n", "turntable.log.clock.rate_error"},
      {"  log: {clock: {steps: 0.1}}\n", "turntable.log.clock.steps"},
      {"  log: {clock: {steps: [0.1, 0.2]}}\n", "turntable.log.clock.steps[0]"},
      {"  log: {clock: {steps: [[10, 0.1], [20]]}}\n", "turntable.log.clock.steps[1]"},
      {"  log: {clock: {steps: [[10, 0.1, 3]]}}\n", "turntable.log.clock.steps[0]"},
      {"  log: {clock: {steps: [[-1, 0.1]]}}\n", "turntable.log.clock.steps[0]"},
      {"  log: {clock: {steps: [[1, .inf]]}}\n", "turntable.log.clock.steps[0][1]"},
      {"  log: {clock: {ofset: 0.1}}\n", "turntable.log.clock.ofset"},
      {"  log: {clock: 0.1}\n", "turntable.log.clock"},
      {"  log: {clock: {offset: -0.05, steps: []}}\n", "accepted"},
      {"  log: {rest_angle_errors: [1.0e-4, 0.2]}\n", "turntable.log.rest_angle_errors[1]"},
      {"  log: {rest_angle_errors: 1.0e-4}\n", "turntable.log.rest_angle_errors"},
      {"  log: {rest_angle_error_std: -1.0e-5}\n", "turntable.log.rest_angle_error_std"},
      {"  log: {rest_angle_errors: [1.0e-4, -2.0e-4], rest_angle_error_std: 3.0e-5}\n", "accepted"},
      {"channels: {drop_probability: -0.1}\n", "channels.drop_probability"},
      {"channels: {gaps: [[-1, 1]]}\n", "channels.gaps[0]"},
      {"channels: {gap: []}\n", "channels.gap"},
  };
  expectRefusedKeys(parse_section, refused);
}

TEST(TurntableLogTest, EachRestStopsOffByItsGivenOrDrawnAngleError) {
  // Rests at 0, 0.6 and 1.2 rad joined by moves at 0.1 rad/s; one record a second.
  struct Record {
    double angle, rate;
  };
  std::vector<Record> motion;
  for (int k = 0; k < 40; ++k) {
    const int in = k % 15;
    const double base = 0.6 * (k / 15);
    motion.push_back(in < 10 ? Record{base, 0.0} : Record{base + 0.1 * (in - 9), 0.1});
  }
  auto logged = [&](const RestAngleErrorConfig& errors) {
    TurntableLogConfig c;
    c.rest_errors = errors;
    TurntableLogger logger(c, 7);
    std::vector<TurntableLogRecord> out;
    for (std::size_t k = 0; k < motion.size(); ++k)
      logger.log(static_cast<double>(k), toNanoseconds(1.0 + k), motion[k].angle, motion[k].rate, &out);
    return out;
  };
  const std::vector<TurntableLogRecord> a = logged({{1e-4, -2e-4}, 3e-5});
  ASSERT_EQ(a.size(), motion.size());
  const double drawn = a[30].angle - motion[30].angle;
  EXPECT_NE(drawn, 0.0);
  EXPECT_LT(std::abs(drawn), 6.0 * 3e-5);
  for (std::size_t k = 0; k < motion.size(); ++k) {
    const double error = a[k].angle - motion[k].angle;
    if (motion[k].rate != 0.0) {
      EXPECT_EQ(error, 0.0) << k;  // turning: the encoder's angle
    } else {
      EXPECT_NEAR(error, k < 15 ? 1e-4 : k < 30 ? -2e-4 : drawn, 1e-15) << k;
    }
  }
  // Giving one rest's error changes no other's draw.
  const std::vector<TurntableLogRecord> b = logged({{5e-4}, 3e-5});
  EXPECT_NEAR(b[0].angle - motion[0].angle, 5e-4, 1e-15);
  EXPECT_NEAR(b[30].angle - motion[30].angle, drawn, 1e-15);
  EXPECT_NE(b[15].angle - motion[15].angle, -2e-4);
  // None asked: the exact angle.
  const std::vector<TurntableLogRecord> exact = logged({});
  for (std::size_t k = 0; k < motion.size(); ++k) EXPECT_EQ(exact[k].angle, motion[k].angle);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
