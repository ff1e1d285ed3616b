// The attitude hold: exact increments from an exact start keep the attitude (the Earth's rate removed
// in ENU) at rest and on a turning platform; the covariance grows as the noise model says (N^2 t for an
// angle random walk, the bias's image for a constant bias, the scale factor's for a turning body); a
// gap, a reset or a wave turned on command loses the attitude; one lost, glitched, jittered or
// mis-timed sample does not.
#include "hrg_gyro/core/alignment/attitude_hold.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/testing/angle_level_mount.h"
#include "core/testing/refusal.h"

namespace hrg_gyro {
namespace core {
namespace {

using testing::MountScenario;

AttitudeHoldSettings holdSettings(double latitude) {
  AttitudeHoldSettings s;
  s.latitude = latitude;
  s.noise.angle_white_noise = 1e-12;
  s.noise.angle_random_walk = s.noise.rate_random_walk = 0.0;
  s.noise.residual_bias = s.noise.residual_drift_harmonics = 0.0;
  s.scale_factor_sigma = 0.0;
  return s;
}

HoldStart exactStart(const MountScenario& s) {
  HoldStart start;
  start.stamp = toNanoseconds(s.start);
  start.body_to_enu = orientationFromEuler(s.mount);
  return start;
}

// Feeds the scenario's triad samples into the hold; returns the body's true orientation at the end.
Eigen::Quaterniond runHold(const MountScenario& s, AttitudeHold* hold) {
  testing::MountSinks sinks;
  sinks.triad = [&](const TriadBodySample& x) { hold->add(x); };
  testing::runMountScenario(s, sinks);
  double logged, truth, rate;
  testing::indexerAngle(s, s.length(), &logged, &truth, &rate);
  return orientationFromEuler(s.mount) * Eigen::AngleAxisd(s.indexed ? truth : 0.0, Eigen::Vector3d::UnitZ());
}

TEST(AttitudeHoldTest, ExactIncrementsKeepTheAttitude) {
  MountScenario s;
  s.white_noise = 1e-13;
  s.accelerometer = false;
  s.mount = EulerAngles{0.02, -0.01, 2.5};
  s.duration = 3600.0;
  AttitudeHold hold(holdSettings(s.latitude), exactStart(s));
  const Eigen::Quaterniond truth = runHold(s, &hold);
  ASSERT_TRUE(hold.holding()) << hold.lostReason();
  EXPECT_NEAR(hold.elapsed(), 3600.0, 1e-6);
  const double error = hold.orientation().angularDistance(truth);
  std::printf("[ measured ] one hour at rest, exact increments: attitude off by %.3e rad\n", error);
  EXPECT_LT(error, 1e-9);

  // On a platform turning at 0.05 rad/s about the vertical for 300 s.
  MountScenario turning = s;
  turning.indexed = true;
  turning.continuous = true;
  turning.duration = 300.0;
  AttitudeHold spun(holdSettings(s.latitude), exactStart(turning));
  const Eigen::Quaterniond turned = runHold(turning, &spun);
  ASSERT_TRUE(spun.holding());
  std::printf("[ measured ] 300 s turning at 0.05 rad/s: attitude off by %.3e rad\n",
              spun.orientation().angularDistance(turned));
  EXPECT_LT(spun.orientation().angularDistance(turned), 1e-8);
}

TEST(AttitudeHoldTest, TheCovarianceGrowsAsTheNoiseModelSays) {
  MountScenario s;
  s.accelerometer = false;
  s.duration = 1000.0;
  s.white_noise = 1e-13;
  // An angle random walk alone: each axis's variance grows as N^2 t.
  AttitudeHoldSettings settings = holdSettings(s.latitude);
  settings.noise.angle_random_walk = 1e-6;
  AttitudeHold hold(settings, exactStart(s));
  runHold(s, &hold);
  const Eigen::Matrix3d p = hold.covariance();
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(p(i, i) / (1e-12 * 1000.0), 1.0, 1e-3) << i;
  // A constant bias of 1e-8 rad/s per axis, uncorrelated at the start: the heading's sigma grows as the
  // up-axis bias times t (the tilts' coupling through the Earth's rate adds a little).
  HoldStart start = exactStart(s);
  start.bias_variance = 1e-16;
  AttitudeHold biased(holdSettings(s.latitude), start);
  runHold(s, &biased);
  const double sigma_yaw = std::sqrt(biased.covarianceRpy()(2, 2));
  std::printf("[ measured ] 1e-8 rad/s bias, 1000 s: heading sigma %.3e rad (b t = %.3e)\n", sigma_yaw, 1e-5);
  EXPECT_NEAR(sigma_yaw / 1e-5, 1.0, 0.05);
  EXPECT_NEAR(biased.headingSigma(), sigma_yaw * 180.0 / kPi, 1e-12);
}

TEST(AttitudeHoldTest, AGapOrACommandedWaveLosesTheAttitude) {
  HoldStart start;
  start.stamp = toNanoseconds(1.0);
  AttitudeHold hold(holdSettings(0.9), start);
  TriadBodySample x;
  x.stamp = toNanoseconds(1.005);
  x.dt = 0.005;
  EXPECT_TRUE(hold.add(x));
  TriadBodySample stale = x;
  EXPECT_TRUE(hold.add(stale));  // at the latest stamp: dropped
  EXPECT_EQ(hold.dropped(), 1u);
  x.stamp = toNanoseconds(1.010);
  x.flags = kTriadFlagPrecessing;
  EXPECT_FALSE(hold.add(x));
  EXPECT_FALSE(hold.holding());
  EXPECT_NE(hold.lostReason().find("FLAG_PRECESSING"), std::string::npos);

  AttitudeHold gapped(holdSettings(0.9), start);
  x.flags = kTriadFlagGap;
  EXPECT_FALSE(gapped.add(x));
  AttitudeHold skipped(holdSettings(0.9), start);
  x.flags = 0;
  x.stamp = toNanoseconds(1.200);  // samples missing in between, longer than max_bridge
  EXPECT_FALSE(skipped.add(x));
  EXPECT_NE(skipped.lostReason().find("missing"), std::string::npos);
  // A stream that jumps ahead for good (five samples in a row 100 s on) loses it too.
  AttitudeHold jumped(holdSettings(0.9), start);
  for (int k = 0; k < 5; ++k) {
    x.stamp = toNanoseconds(101.0 + 0.005 * k);
    jumped.add(x);
  }
  EXPECT_FALSE(jumped.holding());
  EXPECT_NE(jumped.lostReason().find("jumped ahead"), std::string::npos);
  // Settings: a scale-factor sigma not given is refused, naming the key.
  AttitudeHoldSettings unset = holdSettings(0.9);
  unset.scale_factor_sigma = NAN;
  EXPECT_EQ(refusedKey([&] { unset.validate(); }), "hold/scale_factor_sigma");
  AttitudeHoldSettings no_noise = holdSettings(0.9);
  no_noise.noise.residual_bias = NAN;
  EXPECT_EQ(refusedKey([&] { no_noise.validate(); }), "noise/residual_bias");
  // A refused alignment or one gyro's gives no start.
  AlignmentResult refused;
  EXPECT_THROW(holdStartFrom(refused), std::invalid_argument);
}

TEST(AttitudeHoldTest, OneLostGlitchedJitteredOrMistimedSampleCostsThatSampleOnly) {
  // At rest for 600 s: one sample lost, one stamped 1000 s ahead, one with dt = 1e6 s, every stamp
  // jittered by +-0.1 ms (hardware stamps): the hold goes on, the attitude within the bridges' noise.
  MountScenario s;
  s.white_noise = 1e-13;
  s.accelerometer = false;
  s.mount = EulerAngles{0.01, 0.02, -1.0};
  s.duration = 600.0;
  AttitudeHold hold(holdSettings(s.latitude), exactStart(s));
  GaussianNoise jitter(5);
  long k = 0;
  testing::MountSinks sinks;
  sinks.triad = [&](const TriadBodySample& sample) {
    ++k;
    TriadBodySample x = sample;
    x.stamp += static_cast<Nanoseconds>(1e5 * (2.0 * jitter.uniform() - 1.0));  // +-0.1 ms
    if (k == 20000) return;                                                     // lost
    if (k == 40000) x.stamp += toNanoseconds(1000.0);                           // glitched
    if (k == 60000) x.dt = 1e6;                                                 // mis-timed
    ASSERT_TRUE(hold.add(x)) << k << ": " << hold.lostReason();
  };
  testing::runMountScenario(s, sinks);
  ASSERT_TRUE(hold.holding()) << hold.lostReason();
  EXPECT_EQ(hold.dropped(), 2u);
  EXPECT_EQ(hold.bridged(), 3u);
  const double error = hold.orientation().angularDistance(orientationFromEuler(s.mount));
  std::printf(
      "[ measured ] 600 s, one lost, one glitched, one mis-timed sample, stamps jittered 0.1 ms: attitude "
      "off by %.3e rad\n",
      error);
  // Each bridge assumes the previous rate for 5 ms (the body at rest: exact but for the jitter's share).
  EXPECT_LT(error, 1e-8);
}

TEST(AttitudeHoldTest, ATurningBodysHeadingSigmaGrowsWithItsScaleFactorError) {
  // 300 s at 0.05 rad/s about the vertical: 15 rad turned, a 1 ppm scale error is 15 urad of heading.
  MountScenario s;
  s.white_noise = 1e-13;
  s.accelerometer = false;
  s.indexed = true;
  s.continuous = true;
  s.duration = 300.0;
  AttitudeHoldSettings settings = holdSettings(s.latitude);
  settings.scale_factor_sigma = 1e-6;
  AttitudeHold hold(settings, exactStart(s));
  runHold(s, &hold);
  ASSERT_TRUE(hold.holding());
  const double sigma_yaw = std::sqrt(hold.covarianceRpy()(2, 2));
  std::printf("[ measured ] 15 rad turned, scale sigma 1 ppm: heading sigma %.3e rad\n", sigma_yaw);
  EXPECT_NEAR(sigma_yaw / 15e-6, 1.0, 0.01);
}

}  // namespace
}  // namespace core
}  // namespace hrg_gyro
