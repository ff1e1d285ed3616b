// The calibration session against glitched turntable records and wave samples: each kind is dropped
// and counted, none ends a plateau, and the result matches the same session without them; zero
// stamps and lone stamps far back or ahead do not restart the run, a persisting backward timeline (a
// bag loop) does. The glitches are injected here into a clean angle-level stream, independently of
// the simulator.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "core/testing/angle_level_session.h"
#include "core/testing/method_test_settings.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::AngleLevelGyro;
using testing::calibrateAngleLevel;
using testing::constantRateProfile;
using testing::dualRateProfile;
using testing::methodSettings;
using testing::referenceGyro;
using testing::referencePrior;

AngleLevelGyro noisyReferenceGyro() {
  AngleLevelGyro g = testing::referenceGyro();
  g.noise = 1e-6;
  return g;
}

enum Glitch {
  kNanRate,
  kAbsurdRate,
  kInfAngle,
  kZeroStamp,
  kDuplicate,
  kSlightlyBack,
  kFarAhead,
  kFarBack,
  kGlitchKinds
};

struct Injected {
  std::uint64_t count[kGlitchKinds] = {};
  std::uint64_t wave_jumps = 0;  ///< wave samples stamped 1000 s ahead or 100 s back
};

// Feeds the session; about one turntable record in `one_in` (random, seeded) is replaced by a glitch,
// the kinds in turn, and about one wave sample in `one_in` by the same sample stamped 1000 s ahead or
// 100 s back.
CalibrationOutcome run(const TurntableProfile& profile, CalibrationMethodKind method, int one_in, Injected* injected,
                       SessionCounters* counters = nullptr) {
  CalibrationSession session(methodSettings(method), referencePrior());
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
          session.addRotationRecord(t, angle, NAN);
          break;
        case kAbsurdRate:
          session.addRotationRecord(t, angle, 1e6);
          break;
        case kInfAngle:
          session.addRotationRecord(t, INFINITY, rate);
          break;
        case kZeroStamp:
          session.addRotationRecord(0, angle, rate);
          break;
        case kDuplicate:
          session.addRotationRecord(previous, angle, rate);
          break;
        case kSlightlyBack:
          session.addRotationRecord(previous - toNanoseconds(0.0005), angle, rate);
          break;
        case kFarAhead:
          session.addRotationRecord(t + toNanoseconds(100.0), angle, rate);
          break;
        default:
          if (t <= toNanoseconds(100.0)) {  // not a stamp at all this early: a zero-stamp glitch
            --injected->count[kFarBack];
            ++injected->count[kZeroStamp];
          }
          session.addRotationRecord(t - toNanoseconds(100.0), angle, rate);
          break;
      }
    } else {
      session.addRotationRecord(t, angle, rate);
      previous = t;
    }
    if (one_in > 0 && pick(random) == 0) {
      const bool back = injected->wave_jumps % 2 == 1 && t > toNanoseconds(100.0);
      ++injected->wave_jumps;
      session.addWave(t + toNanoseconds(back ? -100.0 : 1000.0), theta, NAN);
    } else {
      session.addWave(t, theta, NAN);
    }
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
  EXPECT_EQ(o.rotation_rejected.bad_rate, in.count[kNanRate] + in.count[kAbsurdRate]);
  EXPECT_EQ(o.rotation_rejected.bad_angle, in.count[kInfAngle]);
  EXPECT_EQ(o.rotation_rejected.bad_stamp, in.count[kZeroStamp]);
  EXPECT_EQ(o.rotation_rejected.duplicate, in.count[kDuplicate]);
  EXPECT_EQ(o.rotation_rejected.out_of_order, in.count[kSlightlyBack]);
  EXPECT_EQ(o.rotation_rejected.stamp_jump, in.count[kFarAhead] + in.count[kFarBack]);
  EXPECT_EQ(o.restarts, 0u);
}

TEST(CalibrationSessionTest, DualRateIgnoresOneGlitchedTurntableRecordInAThousand) {
  const TurntableProfile p = testing::dualRateProfile(0.05, -0.05, 120.0);
  Injected none, glitches;
  const CalibrationOutcome clean = run(p, CalibrationMethodKind::kDualRate, 0, &none);
  SessionCounters counters;
  const CalibrationOutcome glitched = run(p, CalibrationMethodKind::kDualRate, 1000, &glitches, &counters);
  for (int k = 0; k < kGlitchKinds; ++k) EXPECT_GT(glitches.count[k], 15u) << "kind " << k;
  EXPECT_GT(glitches.wave_jumps, 200u);
  EXPECT_EQ(counters.wave_jumps, glitches.wave_jumps);
  expectCounted(glitched, glitches);
  EXPECT_EQ(glitched.plateaus.size(), clean.plateaus.size());
  expectSameWithin(clean, glitched, 1.0);
  EXPECT_EQ(clean.rotation_rejected.total(), 0u);
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
  EXPECT_NE(report.find("turntable_rejected: {bad_rate: " + std::to_string(glitched.rotation_rejected.bad_rate)),
            std::string::npos)
      << report.substr(0, 2000);
}

TEST(CalibrationSessionTest, ZeroStampsAndLoneBackwardStampsDoNotRestartTheRun) {
  CalibrationSession session(methodSettings(CalibrationMethodKind::kDualRate), referencePrior());
  for (int i = 1; i <= 3000; ++i) {
    const Nanoseconds t = toNanoseconds(200.0 + i * 1e-3);
    session.addRotationRecord(t, 0.0, 0.0);
    if (i == 1000) {
      for (int z = 0; z < 20; ++z) session.addRotationRecord(0, 0.0, 0.0);  // a burst of zero stamps
    }
    if (i == 2000) session.addRotationRecord(t - toNanoseconds(100.0), 0.0, 0.0);  // one stamp far back
  }
  EXPECT_EQ(session.counters().restarts, 0u);
  EXPECT_EQ(session.counters().rejected.bad_stamp, 20u);
  EXPECT_EQ(session.counters().rejected.stamp_jump, 1u);
  EXPECT_EQ(session.counters().rotation_records, 3021u);
}

TEST(CalibrationSessionTest, APersistingBackwardTimelineRestartsTheRun) {
  // A bag loop: the first 100 s of the session, then the whole session from its start again. The
  // run restarts once and ends as the single pass does.
  const AngleLevelGyro g = noisyReferenceGyro();
  const TurntableProfile p = testing::dualRateProfile(0.05, -0.05, 120.0);
  const CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  const CalibrationOutcome single = testing::calibrateAngleLevel(g, p, s, referencePrior());
  CalibrationSession session(s, referencePrior());
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    if (toSeconds(t) > 100.0) return;
    session.addRotationRecord(t, angle, rate);
    session.addWave(t, theta, NAN);
  });
  EXPECT_EQ(session.counters().restarts, 0u);
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    session.addRotationRecord(t, angle, rate);
    session.addWave(t, theta, NAN);
  });
  EXPECT_EQ(session.counters().restarts, 1u);
  // The records of the new timeline before it was recognised (jump_persist - 1) are dropped.
  EXPECT_EQ(session.counters().rejected.stamp_jump, static_cast<std::uint64_t>(s.jump_persist - 1));
  const CalibrationOutcome looped = session.finish();
  EXPECT_EQ(looped.restarts, 1u);
  expectSameWithin(single, looped, 1.0);
}

TEST(CalibrationSessionTest, JumpPersistOfOneRestartsOnAnyLongJump) {
  CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  s.jump_persist = 1;
  CalibrationSession session(s, referencePrior());
  session.addRotationRecord(toNanoseconds(10.0), 0.0, 0.0);
  session.addRotationRecord(toNanoseconds(9.8), 0.0, 0.0);  // within backward_reset: a glitch
  EXPECT_EQ(session.counters().restarts, 0u);
  EXPECT_TRUE(session.addRotationRecord(toNanoseconds(2.0), 0.0, 0.0));
  EXPECT_EQ(session.counters().restarts, 1u);
}

// ------------------------------------------------------------------------------------------------
// Turntable streams as a table controller logs them: records at log_hz (the wave stays at 1 kHz), the
// angle with encoder noise or not logged at all (NaN), the rate exact or the logged angle differenced.
struct TableLog {
  double log_hz = 100.0;
  double encoder_noise = 0.0;  ///< rad
  bool differenced_rate = false;
  bool log_angle = true;
  double rate_noise = 0.0;  ///< rad/s, white, on the reported rate
};

CalibrationOutcome runLogged(const AngleLevelGyro& g, const TurntableProfile& p, const CalibrationSettings& s,
                             const TableLog& log, SessionCounters* counters = nullptr, bool feed_wave = true,
                             double wave_offset = 0.0) {
  CalibrationSession session(s, referencePrior());
  std::mt19937_64 random(11);
  std::normal_distribution<double> normal;
  const long every = std::lround(g.rate_hz / log.log_hz);
  long i = 0;
  double previous = NAN;
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    if (i++ % every == 0) {
      const double logged = angle + log.encoder_noise * normal(random);
      const double reported =
          log.differenced_rate ? (std::isnan(previous) ? 0.0 : (logged - previous) * log.log_hz) : rate;
      previous = logged;
      session.addRotationRecord(t, log.log_angle ? logged : NAN, reported + log.rate_noise * normal(random));
    }
    if (feed_wave) session.addWave(t + toNanoseconds(wave_offset), theta, NAN);
  });
  if (counters) *counters = session.counters();
  return session.finish();
}

// The number that follows `after` in `text` (NaN if absent).
double numberAfter(const std::string& text, const std::string& after) {
  const std::size_t at = text.find(after);
  return at == std::string::npos ? NAN : std::stod(text.substr(at + after.size()));
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(CalibrationSessionTest, EncoderNoiseWithTheRateDifferencedKeepsThePlateaus) {
  // 2 urad of encoder noise at 100 Hz with the rate differenced: 0.57 % of rate scatter at 0.05 rad/s.
  const TurntableProfile p = testing::dualRateProfile(0.05, -0.05, 120.0);
  CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  s.gates.max_rate_noise = 0.02;  // that gate judges the raw reported rate; not what is tested here
  SessionCounters clean_counters, angle_counters, rate_counters;
  const CalibrationOutcome clean = runLogged(noisyReferenceGyro(), p, s, TableLog(), &clean_counters);
  TableLog noisy;
  noisy.encoder_noise = 2e-6;
  noisy.differenced_rate = true;
  const CalibrationOutcome with_angle = runLogged(noisyReferenceGyro(), p, s, noisy, &angle_counters);
  noisy.log_angle = false;
  const CalibrationOutcome rate_only = runLogged(noisyReferenceGyro(), p, s, noisy, &rate_counters);
  ASSERT_TRUE(clean.accepted) << clean.reason;
  EXPECT_TRUE(with_angle.accepted) << with_angle.reason;
  EXPECT_TRUE(rate_only.accepted) << rate_only.reason;
  std::printf("[ measured ] wave samples used: clean %llu, angle logged %llu, rate only %llu\n",
              static_cast<unsigned long long>(clean_counters.used),
              static_cast<unsigned long long>(angle_counters.used),
              static_cast<unsigned long long>(rate_counters.used));
  EXPECT_GE(angle_counters.used, clean_counters.used * 99 / 100);
  EXPECT_GE(rate_counters.used, clean_counters.used * 99 / 100);
  expectSameWithin(clean, with_angle, 2.0);
  expectSameWithin(clean, rate_only, 2.0);
}

TEST(CalibrationSessionTest, RefusalNamesTheRateScatterThatHidesThePlateaus) {
  // The same stream, rate only, judged record by record (no smoothing): refused, and the reason
  // names the scatter, measured, and what to do.
  CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  s.plateau.smoothing_span = 0.0;
  TableLog noisy;
  noisy.encoder_noise = 2e-6;
  noisy.differenced_rate = true;
  noisy.log_angle = false;
  const CalibrationOutcome o = runLogged(noisyReferenceGyro(), testing::dualRateProfile(0.05, -0.05, 120.0), s, noisy);
  ASSERT_FALSE(o.accepted);
  std::printf("[ measured ] %s\n", o.reason.c_str());
  ASSERT_FALSE(o.gates.empty());
  EXPECT_EQ(o.gates.front().name, "plateaus");
  EXPECT_TRUE(contains(o.reason, "plateaus: reported rate scatter ")) << o.reason;
  EXPECT_TRUE(contains(o.reason, "log the angle")) << o.reason;
  EXPECT_TRUE(contains(o.reason, "plateau/relative_tolerance")) << o.reason;
  // sqrt(2) 2 urad / 10 ms / 0.05 rad/s = 0.57 %
  EXPECT_NEAR(numberAfter(o.reason, "reported rate scatter "), 0.566, 0.06) << o.reason;
  EXPECT_NEAR(numberAfter(o.reason, "tolerance of "), 0.6, 1e-9) << o.reason;
}

TEST(CalibrationSessionTest, RefusalNamesTheScatterLeftAfterSmoothingARateOnlyStream) {
  // White noise of 3e-3 rad/s on a rate-only log at 100 Hz: 6 % at 0.05 rad/s, still 0.6 % once
  // averaged over the 1 s span, as wide as the tolerance.
  TableLog noisy;
  noisy.log_angle = false;
  noisy.rate_noise = 3e-3;
  const CalibrationOutcome o = runLogged(noisyReferenceGyro(), testing::dualRateProfile(0.05, -0.05, 120.0),
                                         methodSettings(CalibrationMethodKind::kDualRate), noisy);
  ASSERT_FALSE(o.accepted);
  std::printf("[ measured ] %s\n", o.reason.c_str());
  EXPECT_TRUE(contains(o.reason, "plateaus: reported rate scatter ")) << o.reason;
  EXPECT_TRUE(contains(o.reason, " averaged over plateau/smoothing_span, 1 s)")) << o.reason;
  EXPECT_TRUE(contains(o.reason, "log the angle, lengthen plateau/smoothing_span")) << o.reason;
  EXPECT_NEAR(numberAfter(o.reason, "reported rate scatter "), 6.0, 0.6) << o.reason;
  EXPECT_NEAR(numberAfter(o.reason, " % ("), 0.6, 0.1) << o.reason;
}

TEST(CalibrationSessionTest, RefusalNamesPlateausShorterThanTheSettleTime) {
  CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  const CalibrationOutcome o =
      runLogged(noisyReferenceGyro(), testing::dualRateProfile(0.05, -0.05, 1.5, 20), s, TableLog());
  ASSERT_FALSE(o.accepted);
  std::printf("[ measured ] %s\n", o.reason.c_str());
  EXPECT_TRUE(contains(o.reason,
                       "plateaus: no settled plateau at a moving rate: the rate never stayed within "
                       "tolerance for plateau/settle_time (2 s)"))
      << o.reason;
  const double longest = numberAfter(o.reason, "the longest plateau lasted ");
  EXPECT_GT(longest, 0.3);
  EXPECT_LT(longest, 1.5);
}

TEST(CalibrationSessionTest, RefusalNamesAMissingOrUnsynchronizedWave) {
  const TurntableProfile p = testing::dualRateProfile(0.05, -0.05, 30.0);
  const CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  const CalibrationOutcome no_wave = runLogged(noisyReferenceGyro(), p, s, TableLog(), nullptr, false);
  ASSERT_FALSE(no_wave.accepted);
  EXPECT_TRUE(contains(no_wave.reason, "plateaus: turntable records arrived without the wave (")) << no_wave.reason;
  const CalibrationOutcome late_wave = runLogged(noisyReferenceGyro(), p, s, TableLog(), nullptr, true, 1000.0);
  ASSERT_FALSE(late_wave.accepted);
  EXPECT_TRUE(contains(late_wave.reason, "wave samples had no turntable record around their stamp"))
      << late_wave.reason;
  std::printf("[ measured ] %s\n[ measured ] %s\n", no_wave.reason.c_str(), late_wave.reason.c_str());
}

TEST(CalibrationSessionTest, ANanAngleIsRateOnlyFromTheStartAndAGlitchAfterALoggedAngle) {
  CalibrationSession rate_only(methodSettings(CalibrationMethodKind::kDualRate), referencePrior());
  for (int i = 1; i <= 100; ++i) EXPECT_TRUE(rate_only.addRotationRecord(toNanoseconds(i * 0.01), NAN, 0.05));
  EXPECT_EQ(rate_only.counters().rejected.total(), 0u);
  CalibrationSession logged(methodSettings(CalibrationMethodKind::kDualRate), referencePrior());
  for (int i = 1; i <= 100; ++i) {
    const double t = i * 0.01;
    EXPECT_EQ(logged.addRotationRecord(toNanoseconds(t), i == 50 ? NAN : 0.05 * t, 0.05), i != 50) << i;
  }
  EXPECT_EQ(logged.counters().rejected.bad_angle, 1u);
  EXPECT_EQ(logged.counters().rejected.total(), 1u);
}

TEST(CalibrationSessionTest, StepMethodOnARateOnlyStreamUsesTheRateIntegral) {
  // The step method measures each step by the table angle: from a rate-only stream, the integral of
  // the reported rate. It agrees with the angle-logging stream.
  AngleLevelGyro g = testing::referenceGyro();
  g.noise = 1.1e-5;
  TurntableProfile p;
  p.append(15.0, 0.0, 0.0, "rest");
  for (int i = 0; i < 18; ++i) {
    p.append(0.349, 0.0, 0.5, "ramp");
    p.append(1.651, 0.1745, 0.0, "move");
    p.append(0.349, 0.1745, -0.5, "ramp");
    p.append(15.0, 0.0, 0.0, "rest");
  }
  CalibrationSettings s = methodSettings(CalibrationMethodKind::kStep);
  s.bins = 64;
  const CalibrationOutcome with_angle = runLogged(g, p, s, TableLog());
  TableLog rate_only;
  rate_only.log_angle = false;
  const CalibrationOutcome without = runLogged(g, p, s, rate_only);
  ASSERT_TRUE(with_angle.accepted) << with_angle.reason;
  ASSERT_TRUE(without.accepted) << without.reason;
  const HarmonicFitResult& k = with_angle.scale_factor[0];
  EXPECT_NEAR(k.mean, -0.56, 5 * k.mean_std + 1e-7);
  EXPECT_NEAR(k.cos[1], 2e-3, 5 * k.cos_std[1] + 1e-7);
  expectSameWithin(with_angle, without, 5.0);
}

// A field run's table stream is the precession loop's state: what the session says of that stream
// (glitches dropped, wave samples without it, the plateau cause) names it so, never "turntable".
TEST(CalibrationSessionTest, AFieldRunCallsItsStreamThePrecessionState) {
  auto note = [](const CalibrationOutcome& o, const std::string& part) {
    for (const std::string& n : o.notes) {
      if (contains(n, part)) return n;
    }
    return std::string();
  };
  auto mentions = [](const CalibrationOutcome& o, const std::string& word) {
    bool found = contains(o.reason, word);
    for (const std::string& n : o.notes) found = found || contains(n, word);
    return found;
  };
  const TurntableProfile p = testing::dualRateProfile(0.2, -0.2, 30.0);
  for (const CalibrationMethodKind method : {CalibrationMethodKind::kField, CalibrationMethodKind::kDualRate}) {
    const bool field = method == CalibrationMethodKind::kField;
    // The wave 1000 s after the stream: no sample has the stream around it.
    const CalibrationOutcome late =
        runLogged(noisyReferenceGyro(), p, methodSettings(method), TableLog(), nullptr, true, 1000.0);
    ASSERT_FALSE(late.accepted);
    std::printf("[ measured ] %s: %s\n", nameOf(method).c_str(), late.reason.c_str());
    EXPECT_NE(note(late, field ? " wave samples had no precession state around them and were not used"
                               : " wave samples had no turntable state around them and were not used"),
              "");
    EXPECT_TRUE(contains(late.reason, field ? "had no precession state record around their stamp"
                                            : "had no turntable record around their stamp"))
        << late.reason;
    EXPECT_EQ(mentions(late, "turntable"), !field);
    // The report keeps its key (turntable_records) and says what it counts in a field run.
    const std::string report = emitCalibrationReport(late);
    const std::size_t key = report.find("\nturntable_records: ");
    ASSERT_NE(key, std::string::npos) << report;
    const std::string line = report.substr(key + 1, report.find('\n', key + 1) - key - 1);
    EXPECT_EQ(contains(line, "# precession states (the field method's stream)"), field) << line;

    // One record in a hundred has a NaN rate: dropped and counted under the stream's name.
    CalibrationSession session(methodSettings(method), referencePrior());
    long i = 0;
    testing::runAngleLevel(noisyReferenceGyro(), p, [&](Nanoseconds t, double angle, double rate, double theta) {
      session.addRotationRecord(t, angle, ++i % 100 == 0 ? NAN : rate);
      session.addWave(t, theta, NAN);
    });
    const CalibrationOutcome glitched = session.finish();
    const std::string dropped =
        note(glitched, field ? " glitched precession states dropped (" : " glitched turntable records dropped (");
    EXPECT_NE(dropped, "") << nameOf(method);
    EXPECT_EQ(numberAfter(dropped, ""), static_cast<double>(glitched.rotation_rejected.total()));
    EXPECT_GT(glitched.rotation_rejected.bad_rate, 0u);
    if (field) {
      EXPECT_FALSE(mentions(glitched, "turntable")) << glitched.reason;
    }
  }
}

TEST(CalibrationSessionTest, NoTurntableDataMeansNoCalibration) {
  CalibrationSession session(methodSettings(CalibrationMethodKind::kDualRate), GyroParameters());
  // Samples wait up to 60 s for a turntable state, then are dropped (bounded memory).
  for (int i = 0; i < 100000; ++i) session.addWave(toNanoseconds(1.0 + i * 1e-3), 0.2 - 0.028 * i * 1e-3, NAN);
  EXPECT_EQ(session.counters().used, 0u);
  EXPECT_GT(session.counters().unsynchronized, 39000u);
  const CalibrationOutcome o = session.finish();
  EXPECT_FALSE(o.accepted);
}

TEST(CalibrationSessionTest, SynchronisesStreamsArrivingOutOfStep) {
  // The same session with the turntable stream delayed by 300 ms gives the same result.
  const AngleLevelGyro g = referenceGyro();
  const TurntableProfile p = dualRateProfile(0.05, -0.05, 120.0);
  const CalibrationOutcome direct =
      calibrateAngleLevel(g, p, methodSettings(CalibrationMethodKind::kDualRate), referencePrior());
  CalibrationSession session(methodSettings(CalibrationMethodKind::kDualRate), referencePrior());
  std::deque<std::tuple<Nanoseconds, double, double>> delayed;
  testing::runAngleLevel(g, p, [&](Nanoseconds t, double angle, double rate, double theta) {
    session.addWave(t, theta, NAN);
    delayed.emplace_back(t, angle, rate);
    if (delayed.size() > 300) {
      session.addRotationRecord(std::get<0>(delayed.front()), std::get<1>(delayed.front()),
                                std::get<2>(delayed.front()));
      delayed.pop_front();
    }
  });
  for (const auto& d : delayed) session.addRotationRecord(std::get<0>(d), std::get<1>(d), std::get<2>(d));
  const CalibrationOutcome late = session.finish();
  ASSERT_TRUE(late.accepted) << late.reason;
  EXPECT_EQ(late.samples, direct.samples);
  EXPECT_DOUBLE_EQ(late.scale_factor[0].cos[1], direct.scale_factor[0].cos[1]);
}

TEST(CalibrationSessionTest, AutoFinishWaitsForRestAfterCompleteData) {
  const AngleLevelGyro g = referenceGyro();
  CalibrationSettings s = methodSettings(CalibrationMethodKind::kDualRate);
  s.auto_finish_idle = 10.0;
  CalibrationSession session(s, referencePrior());
  double finished_at = -1.0;
  testing::runAngleLevel(g, dualRateProfile(0.05, -0.05, 120.0), [&](Nanoseconds t, double a, double r, double th) {
    session.addRotationRecord(t, a, r);
    session.addWave(t, th, NAN);
    if (finished_at < 0 && session.shouldFinish()) finished_at = toSeconds(t);
  });
  // Plateaus end at ~5 + 0.1 + 120 + 0.2 + 120 + 0.1 = 245.4 s (+ the 1 s stamp offset); then 10 s of rest,
  // found up to half a smoothing span after the table stopped and judged half a span later.
  EXPECT_NEAR(finished_at, 1.0 + 245.4 + 10.0 + s.plateau.smoothing_span, 0.5);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
