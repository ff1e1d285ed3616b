// The closed-loop resonator stepped in time: exact for an ideal shell, its control periods, its
// refusals.
#include "hrg_gyro/core/resonator/resonator_dynamics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/testing/resonator_cases.h"
#include "hrg_gyro/core/common/units.h"

namespace hrg_gyro {
namespace core {
namespace {

// No anisotropy, no drive error, the loops still settling from a wave far from their setpoints,
// a body rate that ramps, holds and reverses: the wave angle is K0 times the body angle, to rounding.
TEST(ResonatorDynamics, IdealShellTurnsByExactlyK0TimesTheBodyAngle) {
  ShellParameters p;
  LoopSettings loops;
  ResonatorDynamics d(p, loops, DriveChainErrors(), {0.85, 0.12, 0.4, -0.5});
  const double k0 = p.scaleFactor(), dt = 1e-3;
  double body_angle = 0.0, rate = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double t = i * dt;
    // 0.5 rad/s^2 up to 1 rad/s, held, then down through zero to -0.7 rad/s.
    const double next = t < 2.0 ? 0.5 * (t + dt) : t < 8.0 ? 1.0 : std::max(-0.7, 1.0 - 0.5 * (t + dt - 8.0));
    ResonatorInputs in;
    in.body_rate_start = rate;
    in.body_rate_end = next;
    ASSERT_TRUE(d.step(dt, in));
    body_angle += 0.5 * (rate + next) * dt;
    rate = next;
  }
  EXPECT_NEAR(d.wave().theta - 0.4, k0 * body_angle, 1e-12 * std::abs(k0 * body_angle));
  EXPECT_NEAR(body_angle, 1.49, 1e-9);  // 1 + 6 + 0.51 - 6.02 rad
  // Meanwhile the loops have done their work.
  EXPECT_NEAR(d.wave().amplitude, 1.0, 1e-12);
  EXPECT_NEAR(d.wave().quadrature, 0.0, 1e-12);
  EXPECT_NEAR(d.wave().phase, loops.phase, 1e-12);
}

TEST(ResonatorDynamics, AStepRunsWholeControlPeriods) {
  LoopSettings loops;  // 5 kHz
  ResonatorDynamics d(ShellParameters(), loops, DriveChainErrors(), {1.0, 0.0, 0.0, 0.3});
  ASSERT_TRUE(d.step(1e-3, {}));
  EXPECT_EQ(d.controlPeriods(), 5u);
  ASSERT_TRUE(d.step(0.3e-3, {}));  // 1.5 periods: two shorter ones
  EXPECT_EQ(d.controlPeriods(), 7u);
  ASSERT_TRUE(d.step(0.05e-3, {}));
  EXPECT_EQ(d.controlPeriods(), 8u);
  EXPECT_NEAR(d.time(), 1.35e-3, 1e-15);
}

TEST(ResonatorDynamics, TheAngleRateInputAddsToTheDrift) {
  ResonatorDynamics d(ShellParameters(), LoopSettings(), DriveChainErrors(), {1.0, 0.0, 0.2, 0.3});
  ResonatorInputs in;
  in.angle_rate = 1e-5;
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(d.step(1e-3, in));
  EXPECT_NEAR(d.wave().theta, 0.2 + 1e-5, 1e-13);  // 5000 additions of rounding
}

TEST(ResonatorDynamics, RefusesAWaveThatDoesNotStand) {
  const ShellParameters p;
  const LoopSettings l;
  const DriveChainErrors e;
  EXPECT_THROW(ResonatorDynamics(p, l, e, {0.5, 0.5, 0.0, 0.0}), std::invalid_argument);
  EXPECT_THROW(ResonatorDynamics(p, l, e, {1.0, 0.0, NAN, 0.0}), std::invalid_argument);
  ShellParameters bad;
  bad.bryan_factor = 1.2;
  EXPECT_THROW(ResonatorDynamics(bad, l, e, {1.0, 0.0, 0.0, 0.0}), std::invalid_argument);
  ResonatorDynamics d(p, l, e, {1.0, 0.0, 0.0, 0.0});
  EXPECT_THROW(d.step(0.0, {}), std::invalid_argument);
  // A large split with the quadrature loop open and the wave half way between the split's axes: the
  // two modes beat and the wave travels within a quarter of the beat (pi / (2 Dw) = 79 ms); the step
  // says so and keeps the last standing wave.
  ShellParameters split;
  split.frequency_split = 20.0;
  split.frequency_axis = -0.25 * kPi;
  LoopSettings open;
  open.quadrature_bandwidth = 0.0;
  ResonatorDynamics free(split, open, e, {1.0, 0.0, 0.0, 0.3});
  bool stood = true;
  for (int i = 0; i < 2000 && stood; ++i) stood = free.step(1e-3, {});
  EXPECT_FALSE(stood);
  const WaveParameters& w = free.wave();
  EXPECT_GT(w.amplitude * w.amplitude, w.quadrature * w.quadrature);
  EXPECT_GT(std::abs(w.quadrature), 0.9 * std::abs(w.amplitude));
  EXPECT_LT(free.time(), 0.1);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
