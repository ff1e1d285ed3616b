// The calibration session against glitched turntable records: each kind is dropped and counted, none
// ends a plateau, and the result matches the same session without them; zero stamps and lone
// backward stamps do not restart the run, a persisting backward timeline (a bag loop) does. The
// glitches are injected here into a clean angle-level stream, independently of the simulator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "core/testing/angle_level_session.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelGyro;

AngleLevelGyro noisyReferenceGyro() {
  AngleLevelGyro g = testing::referenceGyro();
  g.noise = 1e-6;
  return g;
}

GyroParameters prior() {
  GyroParameters p;
  p.earth_rate.latitude = 0.9;
  return p;
}

CalibrationSettings settings(CalibrationMethodKind method) {
  CalibrationSettings s;
  s.method = method;
  s.scale_factor_orders = {2, 4};
  s.drift_orders = {2};
  return s;
}

TurntableProfile constantRateProfile() {
  TurntableProfile p;
  p.append(30.0, 0.0, 0.0, "rest");
  p.append(0.1, 0.0, 0.5, "ramp");
  p.append(250.0, 0.05, 0.0, "turn");
  p.append(0.1, 0.05, -0.5, "ramp");
  p.append(25.0, 0.0, 0.0, "rest");
  return p;
}

enum Glitch { kNanRate, kAbsurdRate, kInfAngle, kZeroStamp, kDuplicate, kSlightlyBack, kGlitchKinds };

struct Injected {
  std::uint64_t count[kGlitchKinds] = {};
};

// Feeds the session; about one turntable record in `one_in` (random, seeded) is replaced by a glitch,
// the kinds in turn. The wave samples stay clean.
CalibrationOutcome run(const TurntableProfile& profile, CalibrationMethodKind method, int one_in, Injected* injected,
                       SessionCounters* counters = nullptr) {
  CalibrationSession session(settings(method), prior());
  std::mt19937_64 random(42);
  std::uniform_int_distribution<int> pick(0, one_in - 1);
  int next_kind = 0;
  Nanoseconds previous = 0;
  testing::runAngleLevel(noisyReferenceGyro(), profile, [&](Nanoseconds t, double angle, double rate, double theta) {
    if (one_in > 0 && pick(random) == 0) {
      const Glitch kind = static_cast<Glitch>(next_kind++ % kGlitchKinds);
      ++injected->count[kind];
      switch (kind) {
        case kNanRate:
          session.addTurntable(t, angle, NAN);
          break;
        case kAbsurdRate:
          session.addTurntable(t, angle, 1e6);
          break;
        case kInfAngle:
          session.addTurntable(t, INFINITY, rate);
          break;
        case kZeroStamp:
          session.addTurntable(0, angle, rate);
          break;
        case kDuplicate:
          session.addTurntable(previous, angle, rate);
          break;
        default:
          session.addTurntable(previous - toNanoseconds(0.0005), angle, rate);
          break;
      }
    } else {
      session.addTurntable(t, angle, rate);
      previous = t;
    }
    session.addWave(t, theta, NAN);
  });
  if (counters) *counters = session.counters();
  return session.finish();
}

// The estimates of two runs agree to `ppm` of |K0|: K0, every K and D harmonic.
void expectSameWithin(const CalibrationOutcome& a, const CalibrationOutcome& b, double ppm) {
  ASSERT_TRUE(a.accepted) << a.reason;
  ASSERT_TRUE(b.accepted) << b.reason;
  const double k0 = std::abs(a.scale_factor[0].mean);
  EXPECT_NEAR(a.scale_factor[0].mean, b.scale_factor[0].mean, ppm * 1e-6 * k0);
  for (std::size_t i = 0; i < a.scale_factor[0].cos.size(); ++i) {
    EXPECT_NEAR(a.scale_factor[0].cos[i], b.scale_factor[0].cos[i], ppm * 1e-6 * k0) << "K cos " << i;
    EXPECT_NEAR(a.scale_factor[0].sin[i], b.scale_factor[0].sin[i], ppm * 1e-6 * k0) << "K sin " << i;
  }
  if (!a.drift.empty() && !b.drift.empty()) {
    EXPECT_NEAR(a.drift[0].mean, b.drift[0].mean, ppm * 1e-6 * k0);
  }
  double worst = std::abs(a.scale_factor[0].mean - b.scale_factor[0].mean);
  for (std::size_t i = 0; i < a.scale_factor[0].cos.size(); ++i) {
    worst = std::max({worst, std::abs(a.scale_factor[0].cos[i] - b.scale_factor[0].cos[i]),
                      std::abs(a.scale_factor[0].sin[i] - b.scale_factor[0].sin[i])});
  }
  std::printf("[ measured ] largest difference of K0 and the K harmonics from the clean run: %.3g ppm of |K0|\n",
              worst / k0 * 1e6);
}

void expectCounted(const CalibrationOutcome& o, const Injected& in) {
  EXPECT_EQ(o.turntable_rejected.bad_rate, in.count[kNanRate] + in.count[kAbsurdRate]);
  EXPECT_EQ(o.turntable_rejected.bad_angle, in.count[kInfAngle]);
  EXPECT_EQ(o.turntable_rejected.bad_stamp, in.count[kZeroStamp]);
  EXPECT_EQ(o.turntable_rejected.duplicate, in.count[kDuplicate]);
  EXPECT_EQ(o.turntable_rejected.out_of_order, in.count[kSlightlyBack]);
  EXPECT_EQ(o.restarts, 0u);
}

TEST(CalibrationSessionTest, DualRateIgnoresOneGlitchedTurntableRecordInAThousand) {
  const TurntableProfile p = testing::dualRateProfile(0.05, -0.05, 120.0);
  Injected none, glitches;
  const CalibrationOutcome clean = run(p, CalibrationMethodKind::kDualRate, 0, &none);
  const CalibrationOutcome glitched = run(p, CalibrationMethodKind::kDualRate, 1000, &glitches);
  for (int k = 0; k < kGlitchKinds; ++k) EXPECT_GT(glitches.count[k], 20u) << "kind " << k;
  expectCounted(glitched, glitches);
  EXPECT_EQ(glitched.plateaus.size(), clean.plateaus.size());
  expectSameWithin(clean, glitched, 1.0);
  EXPECT_EQ(clean.turntable_rejected.total(), 0u);
}

TEST(CalibrationSessionTest, ConstantRateIgnoresOneGlitchedTurntableRecordInAThousand) {
  Injected none, glitches;
  const CalibrationOutcome clean = run(constantRateProfile(), CalibrationMethodKind::kConstantRate, 0, &none);
  const CalibrationOutcome glitched = run(constantRateProfile(), CalibrationMethodKind::kConstantRate, 1000, &glitches);
  expectCounted(glitched, glitches);
  EXPECT_NEAR(glitched.coverage, clean.coverage, 1e-12);
  expectSameWithin(clean, glitched, 1.0);
  // The report carries the counts.
  const std::string report = emitCalibrationReport(glitched);
  EXPECT_NE(report.find("turntable_rejected: {bad_rate: " + std::to_string(glitched.turntable_rejected.bad_rate)),
            std::string::npos)
      << report.substr(0, 2000);
}

TEST(CalibrationSessionTest, ZeroStampsAndLoneBackwardStampsDoNotRestartTheRun) {
  CalibrationSession session(settings(CalibrationMethodKind::kDualRate), prior());
  for (int i = 1; i <= 3000; ++i) {
    const Nanoseconds t = toNanoseconds(200.0 + i * 1e-3);
    session.addTurntable(t, 0.0, 0.0);
    if (i == 1000) {
      for (int z = 0; z < 20; ++z) session.addTurntable(0, 0.0, 0.0);  // a burst of zero stamps
    }
    if (i == 2000) session.addTurntable(t - toNanoseconds(100.0), 0.0, 0.0);  // one stamp far back
  }
  EXPECT_EQ(session.counters().restarts, 0u);
  EXPECT_EQ(session.counters().rejected.bad_stamp, 20u);
  EXPECT_EQ(session.counters().rejected.out_of_order, 1u);
  EXPECT_EQ(session.counters().turntable, 3021u);
}

TEST(CalibrationSessionTest, APersistingBackwardTimelineRestartsTheRun) {
  // A bag loop: the first 100 s of the session, then the whole session from its start again. The
  // run restarts once and ends as the single pass does.
  const AngleLevelGyro g = noisyReferenceGyro();
  const TurntableProfile p = testing::dualRateProfile(0.05, -0.05, 120.0);
  const CalibrationSettings s = settings(CalibrationMethodKind::kDualRate);
  const CalibrationOutcome single = testing::calibrateAngleLevel(g, p, s, prior());
  CalibrationSession session(s, prior());
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    if (toSeconds(t) > 100.0) return;
    session.addTurntable(t, angle, rate);
    session.addWave(t, theta, NAN);
  });
  EXPECT_EQ(session.counters().restarts, 0u);
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    session.addTurntable(t, angle, rate);
    session.addWave(t, theta, NAN);
  });
  EXPECT_EQ(session.counters().restarts, 1u);
  // The records of the new timeline before it was recognised (backward_persist - 1) are dropped.
  EXPECT_EQ(session.counters().rejected.out_of_order, static_cast<std::uint64_t>(s.backward_persist - 1));
  const CalibrationOutcome looped = session.finish();
  EXPECT_EQ(looped.restarts, 1u);
  expectSameWithin(single, looped, 1.0);
}

TEST(CalibrationSessionTest, BackwardPersistOfOneRestartsOnAnyLongJump) {
  CalibrationSettings s = settings(CalibrationMethodKind::kDualRate);
  s.backward_persist = 1;
  CalibrationSession session(s, prior());
  session.addTurntable(toNanoseconds(10.0), 0.0, 0.0);
  session.addTurntable(toNanoseconds(9.8), 0.0, 0.0);  // within backward_reset: a glitch
  EXPECT_EQ(session.counters().restarts, 0u);
  EXPECT_TRUE(session.addTurntable(toNanoseconds(2.0), 0.0, 0.0));
  EXPECT_EQ(session.counters().restarts, 1u);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
