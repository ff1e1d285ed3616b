// The simulator against its own ground truth, and its determinism.
#include "hrg_gyro/core/simulation/gyro_simulator.h"

#include <gtest/gtest.h>

#include "hrg_gyro/core/processing/gyro_processor.h"

namespace hrg_gyro {
namespace core {
namespace {

SimulationConfig idealConfig() {
  SimulationConfig c;
  c.resonator.scale_factor = HarmonicModel({2, 4}, -0.56, {-2e-4, 1e-4}, {1.5e-4, 0.0});
  c.resonator.drift = HarmonicModel({2}, 1e-5, {2e-5}, {-1e-5});
  c.latitude = 0.9;
  c.profile.append(2.0, 0.0, 0.0, "rest");
  c.profile.append(0.2, 0.0, 0.5, "ramp");
  c.profile.append(30.0, 0.1, 0.0, "turn");
  return c;
}

// Demodulating a pattern that turns during the period (rate thetadot) gives, to first order,
//   delta theta = thetadot sin(2 tau) / (2 w),   delta B = -thetadot cos(2 tau) / (2 w):
// a fixed time shift of sin(2 tau) / (2 w) (9 us here) and an apparent quadrature.
TEST(GyroSimulatorTest, IdealPickoffMeasuresTheTrueAngleUpToTheRotationTerm) {
  const SimulationConfig c = idealConfig();
  GyroSimulator sim(c);
  const double two_omega = 2.0 * kTwoPi * c.resonator.frequency, tau = c.resonator.phase;
  SimulationSample s;
  int n = 0;
  double previous_stamp = 0.0, previous_theta = 0.0, worst = 0.0, previous_rate = 0.0;
  while (sim.next(&s)) {
    WaveState w;
    ASSERT_EQ(estimateWave(s.z, WaveLimits{}, &w), WaveStatus::kOk);
    const double thetadot = n > 0 ? (s.truth.theta - previous_theta) / (toSeconds(s.stamp) - previous_stamp) : 0.0;
    const double dtheta = wrapToPi(2.0 * (w.theta - s.truth.theta)) / 2.0;
    // While the table accelerates, the sample is the window mean of a curved theta(t): it differs
    // from the centre value by thetaddot T^2 / 24 (1.2e-8 rad here); otherwise the first-order
    // rotation term is all there is.
    // First order in thetadot / w: holds to 1 % (N = 32 sampling adds ~0.7 %).
    const bool accelerating = *s.truth.segment == "ramp" || s.truth.table_rate != previous_rate;
    const double first_order = std::abs(thetadot) / two_omega;
    const double tolerance = accelerating ? 3e-8 : 0.01 * first_order + 1e-12;
    const double quadrature = 0.02 - thetadot * std::cos(2 * tau) / two_omega;
    if (n > 0) {
      EXPECT_NEAR(dtheta, thetadot * std::sin(2 * tau) / two_omega, tolerance) << n;
      EXPECT_NEAR(w.quadrature, quadrature, tolerance) << n;
    }
    // E = A^2 + B^2 is what the demodulation conserves: the apparent quadrature comes out of A^2.
    EXPECT_NEAR(w.amplitude, std::sqrt(1.0 + 0.02 * 0.02 - quadrature * quadrature), 0.05 * tolerance + 1e-12) << n;
    previous_rate = s.truth.table_rate;
    worst = std::max(worst, std::abs(dtheta));
    if (n > 0) {
      EXPECT_NEAR(toSeconds(s.stamp) - previous_stamp, 1e-3, 1e-9);
    }
    previous_stamp = toSeconds(s.stamp);
    previous_theta = s.truth.theta;
    ++n;
  }
  EXPECT_GT(worst, 4e-7);  // the effect is there, and the prediction accounts for it
  EXPECT_EQ(n, 32200);
  EXPECT_TRUE(sim.done());
}

TEST(GyroSimulatorTest, ProcessorWithTheTrueModelRecoversTheInertialAngle) {
  const SimulationConfig c = idealConfig();
  GyroSimulator sim(c);
  auto p = std::make_shared<GyroParameters>();
  p->scale_factor = c.resonator.scale_factor;
  p->drift = c.resonator.drift;
  p->earth_rate.latitude = c.latitude;
  GyroProcessor proc(ProcessorConfig{}, p);
  // The measurement leads the truth by sin(2 tau) / (2 w) (see above): alpha(t) = truth(t + lead).
  const double lead = std::sin(2 * c.resonator.phase) / (2.0 * kTwoPi * c.resonator.frequency);
  SimulationSample s;
  double truth0 = 0.0, fixed0 = 0.0, alpha_fixed = 0.0;
  bool first = true;
  while (sim.next(&s)) {
    const ProcessorResult r = proc.process({s.stamp, s.z, s.frequency, s.temperature});
    if (first) {
      truth0 = s.truth.inertial_angle;
      fixed0 = s.truth.table_angle;
      first = false;
      continue;
    }
    ASSERT_TRUE(r.has_output);
    alpha_fixed += r.increment.dalpha_earth_fixed;
    // Tolerances: the lead formula is first order (N = 32 adds 0.7 % of lead x rate ~ 6e-9 rad);
    // while accelerating the window mean of a curved theta(t) adds theta'' T^2 / 24 / K ~ 2e-8 rad.
    const double tolerance = *s.truth.segment == "ramp" ? 4e-8 : 1e-8;
    EXPECT_NEAR(r.alpha, s.truth.inertial_angle - truth0 + lead * (s.truth.inertial_rate - verticalEarthRate(0.9)),
                tolerance);
  }
  EXPECT_NEAR(alpha_fixed, s.truth.table_angle - fixed0 + lead * s.truth.table_rate, 1e-8);
  EXPECT_GT(s.truth.table_angle, 2.9);  // it really turned
}

TEST(GyroSimulatorTest, SameSeedSameRunDifferentSeedDifferentNoise) {
  SimulationConfig c = idealConfig();
  c.pickoff.noise = 2e-4;
  GyroSimulator a(c), b(c);
  c.seed = 99;
  GyroSimulator other(c);
  SimulationSample sa, sb, so;
  bool differs = false;
  for (int i = 0; i < 500; ++i) {
    ASSERT_TRUE(a.next(&sa) && b.next(&sb) && other.next(&so));
    EXPECT_EQ(sa.stamp, sb.stamp);
    EXPECT_EQ(sa.z, sb.z);
    differs = differs || sa.z != so.z;
  }
  EXPECT_TRUE(differs);
}

TEST(GyroSimulatorTest, GeneratorSweepsKnownWaves) {
  SimulationConfig c;
  c.generator.enabled = true;
  c.generator.angles = 4;
  c.generator.quadratures = {0.0, 0.05};
  c.generator.phases = {0.0};
  c.generator.dwell = 0.002;  // two outputs per state
  GyroSimulator sim(c);
  SimulationSample s;
  std::vector<double> thetas;
  while (sim.next(&s)) {
    EXPECT_TRUE(s.truth.generator);
    EXPECT_LT((s.z - idealChannels({s.truth.amplitude, s.truth.quadrature, s.truth.theta, s.truth.phase})).norm(),
              1e-12);
    thetas.push_back(s.truth.theta);
  }
  ASSERT_EQ(thetas.size(), 4u * 2u * 2u);
  EXPECT_NEAR(thetas.back(), 3 * kPi / 4, 1e-15);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
