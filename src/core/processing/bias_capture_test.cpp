// Turn-on bias capture against a wave integrated from a known gyro at rest: the captured D0 is the
// true one (harmonics of D and K and the Earth rate accounted for), and motion, constant rotation,
// gaps, a wave turned on command and bad settings are refused with a reason.
#include "hrg_gyro/core/processing/bias_capture.h"

#include <gtest/gtest.h>

#include <functional>
#include <random>

#include "hrg_gyro/core/common/yaml_field.h"
#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

// The gyro as it really is: D0 differs from the model in force by `d0_error`.
GyroParameters truth(double d0) {
  GyroParameters p;
  p.scale_factor = HarmonicModel({2, 4}, -0.56, {-6e-4, 2e-3}, {4e-4, 0.0});
  p.drift = HarmonicModel({2, 4}, d0, {2e-5, -4e-6}, {-1e-5, 3e-6});
  p.earth_rate.latitude = 0.85;
  return p;
}

// Feeds `seconds` of the wave of `real` (table rate `rate(t)`) through the compensation of
// `in_force` into the capture; theta integrated by RK4 over each 5 ms output step.
void run(BiasCapture* capture, const GyroParameters& real, const GyroParameters& in_force,
         const std::function<double(double)>& rate, double seconds, double angle_noise = 0.0) {
  Compensator compensator(std::make_shared<GyroParameters>(in_force));
  const double earth = real.earth_rate.verticalRate(), dt = 0.005;
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, angle_noise);
  double theta = 0.4, measured_previous = theta, t = 0.0;
  while (t < seconds && !capture->finished()) {
    const double h = dt / 4;
    for (int i = 0; i < 4; ++i) {
      auto f = [&](double th, double tt) { return real.scale_factor(th) * (rate(tt) + earth) + real.drift(th); };
      const double k1 = f(theta, t), k2 = f(theta + h / 2 * k1, t + h / 2), k3 = f(theta + h / 2 * k2, t + h / 2),
                   k4 = f(theta + h * k3, t + h);
      theta += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
      t += h;
    }
    const double measured = theta + (angle_noise > 0.0 ? noise(rng) : 0.0);
    capture->add(compensator.step(measured_previous, measured, dt, NAN), 0);
    measured_previous = measured;
  }
}

TEST(BiasCaptureTest, RecoversTheTrueDriftAtRest) {
  const GyroParameters real = truth(3.2e-4);
  GyroParameters in_force = real;
  in_force.drift = HarmonicModel({2, 4}, -1.0e-4, {2e-5, -4e-6}, {-1e-5, 3e-6});  // D0 off by 4.2e-4 rad/s
  BiasCaptureSettings settings;
  settings.duration = 20.0;
  BiasCapture capture(settings, in_force);
  run(
      &capture, real, in_force, [](double) { return 0.0; }, 30.0);
  ASSERT_TRUE(capture.finished());
  const BiasCaptureResult r = capture.result();
  ASSERT_TRUE(r.accepted) << r.reason;
  EXPECT_NEAR(r.seconds, 20.0, 0.01);
  EXPECT_NEAR(r.previous_d0, -1.0e-4, 1e-15);
  EXPECT_NEAR(r.new_d0, 3.2e-4, 1e-9);
  EXPECT_NEAR(r.parameters.drift.meanAt(NAN), r.new_d0, 1e-15);
  // Harmonics, K and everything else are kept.
  EXPECT_EQ(r.parameters.drift.orders(), in_force.drift.orders());
  EXPECT_EQ(r.parameters.drift.nodeValues().bottomRows(4), in_force.drift.nodeValues().bottomRows(4));
  EXPECT_EQ(r.parameters.scale_factor, in_force.scale_factor);
  // Through the refreshed model the output at rest is the Earth rate.
  BiasCapture check(settings, r.parameters);
  run(
      &check, real, r.parameters, [](double) { return 0.0; }, 30.0);
  EXPECT_NEAR(check.result().mean_rate, real.earth_rate.verticalRate(), 2e-9);
}

TEST(BiasCaptureTest, AngleNoiseAveragesOut) {
  const GyroParameters real = truth(2e-4);
  GyroParameters in_force = real;
  in_force.drift = HarmonicModel({2, 4}, 0.0, {2e-5, -4e-6}, {-1e-5, 3e-6});
  BiasCaptureSettings settings;
  settings.duration = 10.0;
  BiasCapture capture(settings, in_force);
  const double sigma = 2e-6;  // rad of angle noise per sample
  run(
      &capture, real, in_force, [](double) { return 0.0; }, 20.0, sigma);
  const BiasCaptureResult r = capture.result();
  ASSERT_TRUE(r.accepted) << r.reason;
  // White angle noise leaves sqrt(2) sigma / T on the mean rate (first and last samples only).
  EXPECT_NEAR(r.new_d0, 2e-4, 5 * std::sqrt(2.0) * sigma / 10.0 * 0.56 + 1e-9);
}

/// A capture of `duration` s on a gyro whose table turns at `rate(t)`, run for `run_for` s.
BiasCaptureResult captureWhileTurning(double duration, const std::function<double(double)>& rate, double run_for) {
  const GyroParameters real = truth(1e-4);
  BiasCaptureSettings settings;
  settings.duration = duration;
  BiasCapture capture(settings, real);
  run(&capture, real, real, rate, run_for);
  return capture.result();
}

TEST(BiasCaptureTest, RefusesMotion) {
  // Someone turns the table by 0.01 rad/s for a second in the middle.
  const BiasCaptureResult r = captureWhileTurning(
      10.0, [](double t) { return t > 4.0 && t < 5.0 ? 0.01 : 0.0; }, 20.0);
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.reason.find("moved"), std::string::npos) << r.reason;
  EXPECT_LT(r.seconds, 6.0);  // ended as soon as the motion was seen
}

TEST(BiasCaptureTest, RefusesConstantRotation) {
  const BiasCaptureResult r = captureWhileTurning(
      5.0, [](double) { return 0.02; }, 10.0);
  EXPECT_FALSE(r.accepted);
  EXPECT_NE(r.reason.find("turning"), std::string::npos) << r.reason;
}

TEST(BiasCaptureTest, RefusesGapsResetsPrecessionAndAborts) {
  const GyroParameters real = truth(1e-4);
  BiasCaptureSettings settings;
  AngleIncrement inc;
  inc.dt = 0.005;
  inc.scale_factor = -0.56;
  BiasCapture gap(settings, real);
  EXPECT_FALSE(gap.add(inc, 0));
  EXPECT_TRUE(gap.add(inc, kFlagGap));
  EXPECT_NE(gap.result().reason.find("gap"), std::string::npos);
  BiasCapture reset(settings, real);
  EXPECT_TRUE(reset.add(inc, kFlagReset));
  EXPECT_FALSE(reset.result().accepted);
  BiasCapture precessed(settings, real);
  EXPECT_FALSE(precessed.add(inc, 0));
  EXPECT_TRUE(precessed.add(inc, kFlagPrecessing));
  EXPECT_FALSE(precessed.result().accepted);
  EXPECT_NE(precessed.result().reason.find("turned on command"), std::string::npos) << precessed.result().reason;
  BiasCapture aborted(settings, real);
  aborted.abort("model reloaded during the capture");
  EXPECT_TRUE(aborted.finished());
  EXPECT_EQ(aborted.result().reason, "model reloaded during the capture");
  BiasCapture unfinished(settings, real);
  EXPECT_FALSE(unfinished.result().accepted);
}

TEST(BiasCaptureTest, SettingsAreValidated) {
  const GyroParameters real = truth(0.0);
  for (auto bad : std::vector<std::function<void(BiasCaptureSettings&)>>{
           [](BiasCaptureSettings& s) { s.duration = 0.0; }, [](BiasCaptureSettings& s) { s.duration = NAN; },
           [](BiasCaptureSettings& s) { s.block = 20.0; }, [](BiasCaptureSettings& s) { s.max_motion = -1.0; },
           [](BiasCaptureSettings& s) { s.max_bias = INFINITY; }}) {
    BiasCaptureSettings s;
    bad(s);
    EXPECT_THROW(BiasCapture(s, real), ConfigError);
  }
}

TEST(BiasCaptureTest, NotesKeepOnlyTheLatestCapture) {
  const std::string first = notesAfterBiasCapture("dual_rate on bench 3", "2026-11-25T10:00:00Z");
  EXPECT_EQ(first, "D0 from a turn-on bias capture at 2026-11-25T10:00:00Z; dual_rate on bench 3");
  const std::string second = notesAfterBiasCapture(first, "2026-11-25T11:00:00Z");
  EXPECT_EQ(second, "D0 from a turn-on bias capture at 2026-11-25T11:00:00Z; dual_rate on bench 3");
  std::string many = second;
  for (int i = 0; i < 50; ++i) many = notesAfterBiasCapture(many, "2026-11-25T12:00:00Z");
  EXPECT_EQ(many, "D0 from a turn-on bias capture at 2026-11-25T12:00:00Z; dual_rate on bench 3");
  EXPECT_EQ(notesAfterBiasCapture("", "T"), "D0 from a turn-on bias capture at T");
  // Notes that merely mention a capture elsewhere are kept.
  EXPECT_EQ(notesAfterBiasCapture("a; see D0 from a turn-on bias capture at X", "T"),
            "D0 from a turn-on bias capture at T; a; see D0 from a turn-on bias capture at X");
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
