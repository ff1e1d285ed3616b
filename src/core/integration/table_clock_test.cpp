// The dual-rate calibration with a table controller that logs on its own computer's clock, against
// the exact injected model: stamps offset from the gyro's by 100 ms with 2 ms of jitter at the
// controller's own 100 Hz, a clock that steps, an offset too large for the plateaus to be judged
// by, and over 20 seeds whether the reported sigmas (the offset's included) cover the errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "core/testing/angle_level_session.h"
#include "core/testing/model_errors.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelGyro;
using testing::TableImperfections;

CalibrationSettings settings() {
  CalibrationSettings s;
  s.method = CalibrationMethodKind::kDualRate;
  return s;
}

/// A controller on its own clock: 100 Hz, a 2 urad encoder, the drive's rate, offset and jitter.
TableImperfections ownClock(double offset, double jitter) {
  TableImperfections t;
  t.log_hz = 100.0;
  t.encoder_noise = 2e-6;
  t.encoder_step = 2.0 * kPi / (1 << 23);
  t.clock_offset = offset;
  t.clock_jitter = jitter;
  return t;
}

TEST(TableClockTest, AnOffsetAndJitterAreMeasuredAndLeaveKWithin1Ppm) {
  const TurntableProfile profile = testing::dualRateProfile(0.05, -0.05, 226.0, 2);
  const AngleLevelGyro g = testing::nominalGyro(21);
  const TableImperfections table = ownClock(0.1, 2e-3);
  const CalibrationOutcome o = testing::calibrateTableSession(g, table, profile, settings(), testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  const double peak = testing::peakErrorPpm(toModel(o.scale_factor[0]), g.k);
  const TableClockReport& c = o.table_clock;
  CalibrationSettings as_logged = settings();
  as_logged.table_clock.regularise = false;
  const CalibrationOutcome raw =
      testing::calibrateTableSession(g, table, profile, as_logged, testing::referencePrior());
  std::printf(
      "table at 100 Hz, offset 100 ms, jitter 2 ms: peak K error %.2f ppm (sigma %.3f ppm); offset %.3f +- "
      "%.3f ms from %zu changes, jitter %.3f ms; stamps as logged: %s\n",
      peak, testing::maxHarmonicStdPpm(o.scale_factor[0]), 1e3 * c.offset.offset, 1e3 * c.offset.offset_std,
      c.offset.transitions.size(), 1e3 * c.stamps.jitter, raw.reason.c_str());
  EXPECT_LE(peak, 1.0);
  EXPECT_TRUE(c.stamps.fixed_rate) << c.stamps.note;
  EXPECT_TRUE(c.stamps.used_sequence);
  EXPECT_NEAR(c.stamps.jitter, 2e-3, 0.2e-3);
  ASSERT_TRUE(c.offset.estimated) << c.offset.note;
  EXPECT_EQ(c.offset.transitions.size(), 5u);  // rest -> + -> - -> + -> - -> rest
  EXPECT_NEAR(c.offset.offset, 0.1, 3.0 * c.offset.offset_std);
  EXPECT_LT(c.offset.offset_std, 1e-3);
  EXPECT_FALSE(c.offset.changed);
  // With the stamps as logged, 2 ms of jitter puts 100 urad on every table angle: the angle's slope
  // over the 1 s smoothing span scatters, and the plateaus themselves are lost.
  EXPECT_FALSE(raw.accepted);
  EXPECT_EQ(raw.reason.rfind("plateaus: the table angle's slope", 0), 0u) << raw.reason;
}

TEST(TableClockTest, AClockStepIsFollowedAndShowsInTheOffsets) {
  const TurntableProfile profile = testing::dualRateProfile(0.05, -0.05, 226.0, 2);
  const AngleLevelGyro g = testing::nominalGyro(22);
  TableImperfections table = ownClock(0.05, 1e-3);
  table.clock_step_at = 480.0;  // between the second and the third plateau
  table.clock_step = 0.025;     // two and a half records: a whole number would look like lost records
  const CalibrationOutcome o = testing::calibrateTableSession(g, table, profile, settings(), testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  const TableClockReport& c = o.table_clock;
  std::printf("clock step of 25 ms: %llu step(s) found, offsets: %s; peak K error %.2f ppm\n",
              static_cast<unsigned long long>(c.stamps.clock_steps), c.offset.note.c_str(),
              testing::peakErrorPpm(toModel(o.scale_factor[0]), g.k));
  EXPECT_EQ(c.stamps.clock_steps, 1u);
  EXPECT_TRUE(c.offset.changed) << c.offset.note;
  ASSERT_EQ(c.offset.transitions.size(), 5u);
  EXPECT_NEAR(c.offset.transitions.front().offset, 0.05, 1e-3);
  EXPECT_NEAR(c.offset.transitions.back().offset, 0.075, 1e-3);
  EXPECT_LE(testing::peakErrorPpm(toModel(o.scale_factor[0]), g.k), 1.0);
}

TEST(TableClockTest, AClockRunningAtAnotherRateIsMeasuredAndKUndoneOfIt) {
  // A table computer whose clock runs 10 ppm fast: the table angle is stretched by 10 ppm against the
  // gyro's time, and K with it. The offsets' drift over the session measures it.
  const TurntableProfile profile = testing::dualRateProfile(0.05, -0.05, 226.0, 2);
  const AngleLevelGyro g = testing::nominalGyro(24);
  TableImperfections table = ownClock(0.05, 1e-3);
  table.clock_rate_error = 1e-5;
  const CalibrationOutcome o = testing::calibrateTableSession(g, table, profile, settings(), testing::referencePrior());
  ASSERT_TRUE(o.accepted) << o.reason;
  const TableClockReport& c = o.table_clock;
  const double k0_error = 1e6 * (o.scale_factor[0].mean - g.k.meanAt(NAN)) / 0.56;
  std::printf(
      "table clock 10 ppm fast: rate error %.3f +- %.3f ppm measured, K scaled by %.8f; K0 error %.3f ppm "
      "(sigma %.3f), peak %.2f ppm\n",
      1e6 * c.offset.rate_error, 1e6 * c.offset.rate_error_std, c.k_scaled, k0_error,
      1e6 * o.scale_factor[0].mean_std / 0.56, testing::peakErrorPpm(toModel(o.scale_factor[0]), g.k));
  ASSERT_TRUE(c.offset.rate_estimated);
  EXPECT_NEAR(c.offset.rate_error, 1e-5, 3.0 * c.offset.rate_error_std + 1e-7);
  EXPECT_LE(std::abs(k0_error), 3.0 * 1e6 * o.scale_factor[0].mean_std / 0.56);
  EXPECT_LE(testing::peakErrorPpm(toModel(o.scale_factor[0]), g.k), 1.0);
  EXPECT_FALSE(c.offset.changed);
}

TEST(TableClockTest, AnOffsetBeyondTheLimitIsRefusedWithTheValueToSet) {
  const TurntableProfile profile = testing::dualRateProfile(0.05, -0.05, 150.0, 1);
  const AngleLevelGyro g = testing::nominalGyro(23);
  const TableImperfections table = ownClock(0.8, 1e-3);
  const CalibrationOutcome o = testing::calibrateTableSession(g, table, profile, settings(), testing::referencePrior());
  std::printf("offset 800 ms: %s\n", o.reason.c_str());
  EXPECT_FALSE(o.accepted);
  EXPECT_EQ(o.reason.rfind("table_clock: the table's stamps are 8", 0), 0u) << o.reason;
  EXPECT_NE(o.reason.find("set table_clock/offset to 0.8"), std::string::npos) << o.reason;
  // Told the offset, the session is accepted and what is left of it is nothing.
  CalibrationSettings told = settings();
  told.table_clock.offset = 0.8;
  const CalibrationOutcome corrected =
      testing::calibrateTableSession(g, table, profile, told, testing::referencePrior());
  ASSERT_TRUE(corrected.accepted) << corrected.reason;
  EXPECT_NEAR(corrected.table_clock.offset.offset, 0.0, 1e-3);
}

TEST(TableClockTest, ReportedSigmasCoverTheErrorOver20Seeds) {
  const TurntableProfile profile = testing::dualRateProfile(0.05, -0.05, 150.0, 2);
  int within = 0, total = 0, offsets_within = 0;
  double worst_peak = 0.0;
  for (int seed = 1; seed <= 20; ++seed) {
    const AngleLevelGyro g = testing::nominalGyro(2000 + seed);
    const CalibrationOutcome o =
        testing::calibrateTableSession(g, ownClock(0.1, 2e-3), profile, settings(), testing::referencePrior());
    ASSERT_TRUE(o.accepted) << "seed " << seed << ": " << o.reason;
    const HarmonicFitResult& k = o.scale_factor[0];
    double truth[64];
    g.k.coefficientsAt(NAN, truth);
    const std::size_t n = g.k.orders().size();
    auto count = [&](double error, double sigma) {
      ++total;
      if (std::abs(error) <= 3.0 * sigma) ++within;
    };
    count(k.mean - truth[0], k.mean_std);
    for (std::size_t j = 0; j < k.orders.size(); ++j) {
      count(k.cos[j] - truth[1 + j], k.cos_std[j]);
      count(k.sin[j] - truth[1 + n + j], k.sin_std[j]);
    }
    const TableClockOffsetResult& off = o.table_clock.offset;
    if (off.estimated && std::abs(off.offset - 0.1) <= 3.0 * off.offset_std) ++offsets_within;
    worst_peak = std::max(worst_peak, testing::peakErrorPpm(toModel(k), g.k));
  }
  const double share = static_cast<double>(within) / total;
  std::printf(
      "offset 100 ms, jitter 2 ms, 20 seeds: %d of %d K coefficients within 3 sigma (%.1f %%), offsets %d of "
      "20, worst peak %.2f ppm\n",
      within, total, 100.0 * share, offsets_within, worst_peak);
  EXPECT_GE(share, 0.95);
  EXPECT_GE(offsets_within, 19);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
